// Pinocchio's side of the kernel benchmark (bench/peers/peers.py builds and runs it against the
// `pin` wheel's headers and libraries): times RNEA, CRBA, ABA and the constrained forward dynamics
// with point contacts (constraintDynamics, CONTACT_3D at each contact joint's origin, frames
// LOCAL_WORLD_ALIGNED) at one state, in C++ (no Python in the loop).
//
// usage: pin_kernels INPUT N
//   INPUT (written by peers.py from the model Pinocchio's Python bindings parsed from the URDF;
//   the wheel ships no urdfdom headers, so the model is rebuilt here joint by joint): lines
//   "joint NAME PARENT_ID AX AY AZ R11 R12 .. R33 PX PY PZ MASS CX CY CZ IXX IXY IYY IXZ IYZ IZZ",
//   then "gravity gx gy gz", "armature a_1 .. a_nv", "q ..", "v ..", "tau ..", and one
//   "contact JOINT_NAME" per contact.
// stdout: one line per kernel, "name microseconds_per_call" (best of 5 batches of N calls), then
// "#ddq ..": the accelerations of the last call (constraintDynamics, or ABA without contacts).
#include <chrono>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "pinocchio/algorithm/aba.hpp"
#include "pinocchio/algorithm/constrained-dynamics.hpp"
#include "pinocchio/algorithm/crba.hpp"
#include "pinocchio/algorithm/rnea.hpp"
#include "pinocchio/multibody.hpp"

using namespace pinocchio;

template<class F> double best_us(int n, F f) {
  double best = 1e300;
  for (int r = 0; r < 5; r++) {
    auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < n; i++) f();
    double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    best = std::min(best, s / n * 1e6);
  }
  return best;
}

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: pin_kernels INPUT N\n";
    return 2;
  }
  Model model;
  std::ifstream in(argv[1]);
  if (!in) {
    std::cerr << "pin_kernels: cannot read " << argv[1] << "\n";
    return 2;
  }
  int n = std::atoi(argv[2]);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  for (auto& line : lines) {
    std::istringstream s(line);
    std::string key, name;
    s >> key;
    if (key != "joint") continue;
    JointIndex parent;
    Eigen::Vector3d axis, p, c;
    Eigen::Matrix3d r;
    double mass, ixx, ixy, iyy, ixz, iyz, izz;
    s >> name >> parent >> axis[0] >> axis[1] >> axis[2];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) s >> r(i, j);
    s >> p[0] >> p[1] >> p[2] >> mass >> c[0] >> c[1] >> c[2] >> ixx >> ixy >> iyy >> ixz >> iyz >> izz;
    SE3 placement(r, p);
    JointIndex id;
    // the specialised joints for unit axes, as Pinocchio's URDF parser chooses them
    if (axis == Eigen::Vector3d::UnitX()) id = model.addJoint(parent, JointModelRX(), placement, name);
    else if (axis == Eigen::Vector3d::UnitY()) id = model.addJoint(parent, JointModelRY(), placement, name);
    else if (axis == Eigen::Vector3d::UnitZ()) id = model.addJoint(parent, JointModelRZ(), placement, name);
    else id = model.addJoint(parent, JointModelRevoluteUnaligned(axis), placement, name);
    Symmetric3 inertia(ixx, ixy, iyy, ixz, iyz, izz);
    model.appendBodyToJoint(id, Inertia(mass, c, inertia), SE3::Identity());
  }
  Eigen::VectorXd q(model.nq), v(model.nv), tau(model.nv);
  std::vector<std::string> contacts;
  auto read_vec = [](std::istringstream& s, Eigen::VectorXd& x) {
    for (Eigen::Index i = 0; i < x.size(); i++) s >> x[i];
  };
  for (auto& line : lines) {
    std::istringstream s(line);
    std::string key;
    s >> key;
    if (key == "gravity") {
      Eigen::Vector3d g;
      s >> g[0] >> g[1] >> g[2];
      model.gravity.linear(g);
    } else if (key == "armature") {
      Eigen::VectorXd a(model.nv);
      read_vec(s, a);
      model.armature = a;
    } else if (key == "q") read_vec(s, q);
    else if (key == "v") read_vec(s, v);
    else if (key == "tau") read_vec(s, tau);
    else if (key == "contact") {
      std::string name;
      s >> name;
      contacts.push_back(name);
    }
  }
  Data data(model);
  typedef std::vector<RigidConstraintModel, Eigen::aligned_allocator<RigidConstraintModel>> Models;
  typedef std::vector<RigidConstraintData, Eigen::aligned_allocator<RigidConstraintData>> Datas;
  Models cms;
  Datas cds;
  for (auto& c : contacts) {
    if (!model.existJointName(c)) {
      std::cerr << "pin_kernels: no joint " << c << "\n";
      return 2;
    }
    cms.emplace_back(CONTACT_3D, model, model.getJointId(c), SE3::Identity(), LOCAL_WORLD_ALIGNED);
  }
  for (auto& cm : cms) cds.emplace_back(cm);
  std::cout << "rnea " << best_us(n, [&] { rnea(model, data, q, v, tau); }) << "\n";
  std::cout << "crba " << best_us(n, [&] { crba(model, data, q); }) << "\n";
  std::cout << "aba " << best_us(n, [&] { aba(model, data, q, v, tau); }) << "\n";
  if (!cms.empty()) {
    initConstraintDynamics(model, data, cms, cds);
    std::cout << "constraintDynamics_3d " << best_us(n, [&] { constraintDynamics(model, data, q, v, tau, cms, cds); }) << "\n";
  }
  // the result, for peers.py to check this model against the Python bindings' (not a timing)
  if (!cms.empty()) constraintDynamics(model, data, q, v, tau, cms, cds);
  else aba(model, data, q, v, tau);
  std::cout.precision(17);
  std::cout << "#ddq";
  for (Eigen::Index i = 0; i < model.nv; i++) std::cout << " " << data.ddq[i];
  std::cout << "\n";
  return 0;
}
