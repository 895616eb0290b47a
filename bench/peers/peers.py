#!/usr/bin/env python3
"""Peer benchmark (issue 14, item 7): the project's work-precision ladder and MuJoCo's, on the same
arm and the same reference, in one invocation; and Pinocchio's constrained forward dynamics
against the project's right-hand side.

For each scene (default: sim/scenes/peers/mechanical-hold.json and dcmotor-hold.json, run
"no-elbow"):
  1. `peers_dump SCENE RUN --reference` (sim/examples/peers_dump.rs) prints the drive and PD
     parameters, the initial state and joint targets, M(q) and the hand at a few q, and the
     reference hand path (`sim::precision::reference`: Dormand-Prince, rtol 1e-12, the run
     `sim precision` measures against), one sample per output interval.
  2. The MJCF is generated from the scene's URDF and those parameters (see `mjcf()` for the
     equivalence) and checked: hand position and M(q) (mj_fullM minus the armature) at the dumped
     q must agree with the project's to 1e-12 (relative to the largest entry); else the script
     stops.
  3. MuJoCo's ladder: every integrator (euler, implicitfast, implicit, rk4) over a ladder of
     timesteps, each run by `mj_ladder` (C, linked to the wheel's libmujoco; no Python in the
     timed loop: mj_step, and at every output sample mj_kinematics and a copy of the hand), best
     of --repeats. Max hand error over the run against the reference.
  4. The project's ladder: `SIM precision SCENE --run RUN -f json` (its own timing: the
     simulation with every 1 kHz output evaluated, no file; best of --repeats). Same reference.
  5. Per accuracy level (1e-3 ... 1e-8 m): each series' time to reach it, interpolated linearly
     in log-log between the cheapest rung within the level and the next cheaper rung (never
     extrapolated); the best series of each tool; the ratio project / MuJoCo.
A contact scene (issue 24 item 3: `--scene sim/scenes/paper_unilateral.json --run
two-elbow-unilateral`, the paper arm tracking its circle with elbows 4 and 7 over a rigid
table, μ = 0.5, restitution 0): MuJoCo gets the table as a plane and each contact point as a
1e-5 m sphere on its link (the table lowered by the radius, so that it touches where the point
reaches the plane); its ctrl follows the circle's joint targets (`peers_dump --targets`, eq 27
as MuJoCo's position input, see main()); the ladder runs implicitfast and rk4 for each of the
contact settings in MJ_CONTACT_VARIANTS (the pyramidal default, and the elliptic cone with the
stiffest contact the timestep allows, with and without noslip), and the table adds a row at
MuJoCo's best reachable error (its floor). The reference is ours, rodas5p at rtol 1e-12
(`sim::precision::reference` for a frictional run).

Then Pinocchio (the `pin` wheel, Python bindings): on the paper scene's two-elbow run, its
constrained accelerations (KKT with the same two normal rows) against ours at a few states,
and its timing against `rhs_profile` (ours). Pinocchio's timing through Python is an upper bound
(each call crosses the Python/C++ boundary: ~0.3-1 us), so the ratio is a lower bound of ours
relative to its C++.

Usage (from the repository root; see BENCHMARKS.md):
  python bench/peers/peers.py [--sim target/release/sim] [--dump target/release/examples/peers_dump]
                              [--rhs target/release/examples/rhs_profile] [--repeats 3] [--quick]
The venv: ~/.cache/elbow-sim/venv-peers with mujoco==4.0.0, pin==4.1.0 (bench/peers/requirements.txt).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent
LEVELS = [1e-3, 1e-4, 1e-5, 1e-6, 1e-8]
MJ_INTEGRATORS = ["euler", "implicitfast", "implicit", "rk4"]
# timesteps: the output interval over these (every one divides it), dense enough near the
# explicit integrators' stability limit (h ~ 3e-4 s here) not to overstate MuJoCo's cost
MJ_DIVISORS = [1, 2, 3, 4, 5, 7, 10, 14, 20, 30, 50, 70, 100, 150, 200, 300, 500, 700, 1000]
# the ladder of an integrator stops when its last rung, scaled by the step ratio, predicts more
# than this; rungs predicted above MJ_ONCE_S are timed once (their noise is relatively small)
MJ_MAX_PREDICTED_S = 6.0
MJ_ONCE_S = 1.0


class PeerError(Exception):
    pass


def run(cmd: list[str], **kw) -> str:
    p = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if p.returncode != 0:
        raise PeerError(f"{' '.join(map(str, cmd))} failed ({p.returncode}):\n{p.stderr.strip()}")
    return p.stdout


# ---------------------------------------------------------------------------------------------
# the model: URDF + the scene's drives -> MJCF


def rpy_quat(rpy: list[float]) -> np.ndarray:
    """URDF's fixed-axis roll-pitch-yaw, R = Rz(y) Ry(p) Rx(r), as a quaternion (w, x, y, z)."""
    r, p, y = (0.5 * a for a in rpy)
    qx = np.array([math.cos(r), math.sin(r), 0.0, 0.0])
    qy = np.array([math.cos(p), 0.0, math.sin(p), 0.0])
    qz = np.array([math.cos(y), 0.0, 0.0, math.sin(y)])
    return qmul(qz, qmul(qy, qx))


def qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array([
        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
    ])


def quat_matrix(q: np.ndarray) -> np.ndarray:
    """The rotation matrix of a unit quaternion (w, x, y, z)."""
    w, x, y, z = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def fmt(v) -> str:
    return " ".join(repr(float(x)) for x in v)


def origin(el) -> tuple[list[float], list[float]]:
    o = el.find("origin") if el is not None else None
    if o is None:
        return [0.0] * 3, [0.0] * 3
    return [float(x) for x in o.get("xyz", "0 0 0").split()], [float(x) for x in o.get("rpy", "0 0 0").split()]


# MuJoCo's contact settings tried on a contact scene (the best per accuracy level is reported).
# Chosen from MuJoCo's documentation (Computation > Contact; XML reference, option and geom):
#  - "default": what a user gets, pyramidal cone, solref (0.02, 1), solimp (0.9, 0.95, 0.001).
#  - "elliptic": elliptic cone (closer to the exact Coulomb cone), impratio 10 (the docs'
#    advice against slip in elliptic cones), a contact as stiff as the timestep allows: solref
#    timeconst 1e-9 s is clamped by `refsafe` to 2 h at every rung; solimp (0.99, 0.999, 0.001)
#    (near-rigid at any penetration).
#  - "elliptic-noslip": as "elliptic", plus 10 noslip iterations (the post-processor that
#    removes the slip the soft model allows while sticking).
MJ_CONTACT_VARIANTS = {
    "default": {"cone": "pyramidal", "impratio": 1.0, "solref": "0.02 1", "solimp": "0.9 0.95 0.001", "noslip": 0},
    "elliptic": {"cone": "elliptic", "impratio": 10.0, "solref": "1e-9 1", "solimp": "0.99 0.999 0.001", "noslip": 0},
    "elliptic-noslip": {"cone": "elliptic", "impratio": 10.0, "solref": "1e-9 1", "solimp": "0.99 0.999 0.001", "noslip": 10},
}
MJ_CONTACT_INTEGRATORS = ["implicitfast", "rk4"]
# the contact point as a sphere of this radius on the link, its centre at the point, over a table
# lowered by the radius: it touches where the point reaches the plane (the lever arm of the
# friction force about the point, 1e-5 m, is the only difference from a point contact)
MJ_CONTACT_RADIUS = 1e-5


def mjcf(urdf_path: Path, dump: dict, electrical: str, contact: dict | None = None) -> str:
    """MJCF of the arm: one body per moving URDF link (pos/quat from the joint origin, the URDF
    inertial as `fullinertia`), hinge joints with armature J_m = I_m k^2 and damping D + D_m
    (RBDA-style reflected drive: eqs 9-10 of the paper, sim/src/dynamics/motor.rs), the hand as a
    site, the initial state and targets as keyframe 0; without `contact`, no geoms and contacts off
    (no-elbow runs); with it (a contact scene), the table as a plane and each contact point as a
    small sphere on its link (MJ_CONTACT_RADIUS), Coulomb friction μ of the scene, condim 3, and
    the cone, impratio, solref, solimp and noslip of the variant (MJ_CONTACT_VARIANTS).

    Drives (per joint j; K_m = K k, all link side), from motor.rs (eqs 11-12) and pd.rs (eq 27)
    with a constant target (q̇_d = 0):
      quasi-static (L = 0): i = (v - K_m q̇)/R, v = k_p (q_d - q) - k_d q̇, so the drive torque is
        τ = K_m i = (K_m k_p/R)(q_d - q) - (K_m (k_d + K_m)/R) q̇: a `general` actuator with
        gain K_m k_p/R on ctrl = q_d and affine bias (0, -K_m k_p/R, -K_m (k_d + K_m)/R).
      inductive: a `dcmotor` with gear 1, motorconst K_m (torque = back-EMF constant, link side),
        resistance R, inductance L, input "pos" (ctrl = q_d) and controller gains in torque
        space (k_p' = K_m k_p/R, k_d' = K_m (k_d + K_m)/R): MuJoCo's controller drives
        v = (R/K)(k_p'(u - q) - k_d' q̇) + K q̇ = k_p (q_d - q) - k_d q̇, the paper's eq 27
        (XMLreference, dcmotor/controller; changelog 4.0: "add K^2/R to the converted kd").
    """
    tree = ET.parse(urdf_path)
    robot = tree.getroot()
    links = {l.get("name"): l for l in robot.findall("link")}
    joints = robot.findall("joint")
    children: dict[str, list] = {}
    for j in joints:
        children.setdefault(j.find("parent").get("link"), []).append(j)
    child_links = {j.find("child").get("link") for j in joints}
    roots = [n for n in links if n not in child_links]
    if len(roots) != 1:
        raise PeerError(f"{urdf_path}: expected one root link, found {roots}")
    names = dump["joint_names"]
    dr = dump["drives"]
    g = dump["gains"]
    hand_joint = dump["hand"]["joint"]
    out = []

    def emit_body(joint, depth: int):
        ind = "  " * depth
        jtype = joint.get("type")
        child = joint.find("child").get("link")
        xyz, rpy = origin(joint)
        if jtype in ("revolute", "continuous"):
            k = names.index(joint.get("name"))
            out.append(f'{ind}<body name="{child}" pos="{fmt(xyz)}" quat="{fmt(rpy_quat(rpy))}">')
            inertial = links[child].find("inertial")
            if inertial is None:
                raise PeerError(f"{urdf_path}: moving link {child} has no inertial")
            ixyz, irpy = origin(inertial)
            mass = float(inertial.find("mass").get("value"))
            it = inertial.find("inertia")
            ixx, iyy, izz, ixy, ixz, iyz = (float(it.get(a)) for a in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz"))
            # the URDF inertia is about the inertial frame's axes: in the body frame, R I R^T
            rot = quat_matrix(rpy_quat(irpy))
            ib = rot @ np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]) @ rot.T
            full = [ib[0, 0], ib[1, 1], ib[2, 2], ib[0, 1], ib[0, 2], ib[1, 2]]
            out.append(f'{ind}  <inertial pos="{fmt(ixyz)}" mass="{mass!r}" fullinertia="{fmt(full)}"/>')
            axis = [float(x) for x in joint.find("axis").get("xyz").split()] if joint.find("axis") is not None else [1.0, 0.0, 0.0]
            out.append(f'{ind}  <joint name="{joint.get("name")}" type="hinge" axis="{fmt(axis)}" '
                       f'armature="{dr["jm"][k]!r}" damping="{dr["d"][k] + dr["dm"][k]!r}"/>')
            if joint.get("name") == hand_joint:
                out.append(f'{ind}  <site name="hand" pos="{fmt(dump["hand"]["point_in_body"])}"/>')
            for c in dump.get("contacts", []) if contact is not None else []:
                if c["joint"] == joint.get("name"):
                    mu = c["law"]["friction"]
                    out.append(f'{ind}  <geom name="{c["name"]}" type="sphere" size="{MJ_CONTACT_RADIUS!r}" pos="{fmt(c["point_in_body"])}" '
                               f'contype="1" conaffinity="0" condim="3" friction="{mu!r} 0 0" density="0" '
                               f'solref="{contact["solref"]}" solimp="{contact["solimp"]}"/>')
            for cj in children.get(child, []):
                emit_body(cj, depth + 1)
            out.append(f"{ind}</body>")
        elif jtype == "fixed":
            if links[child].find("inertial") is not None or children.get(child):
                raise PeerError(f"{urdf_path}: fixed link {child} with mass or children is not supported")
        else:
            raise PeerError(f"{urdf_path}: joint type {jtype} is not supported")

    for j in children.get(roots[0], []):
        emit_body(j, 2)
    acts = []
    for k, name in enumerate(names):
        km, r, kp, kd = dr["km"][k], dr["r"][k], g["kp"][k], g["kd"][k]
        if electrical == "quasi-static":
            acts.append(f'    <general joint="{name}" gainprm="{km * kp / r!r}" biastype="affine" '
                        f'biasprm="0 {-km * kp / r!r} {-km * (kd + km) / r!r}"/>')
        else:
            acts.append(f'    <dcmotor joint="{name}" gear="1" motorconst="{km!r} {km!r}" resistance="{r!r}" '
                        f'inductance="{dr["l"][k]!r} 0" input="pos" controller="{km * kp / r!r} 0 {km * (kd + km) / r!r} 0 0 0"/>')
    gx = dump["gravity"]
    if contact is None:
        option = [f'  <option timestep="0.001" gravity="{fmt(gx)}">', '    <flag contact="disable"/>', "  </option>"]
        table = []
    else:
        option = [f'  <option timestep="0.001" gravity="{fmt(gx)}" cone="{contact["cone"]}" impratio="{contact["impratio"]!r}" '
                  f'noslip_iterations="{contact["noslip"]}"/>']
        c0 = dump["contacts"][0]
        mu = max(c["law"]["friction"] for c in dump["contacts"])
        table = [f'    <geom name="table" type="plane" size="0 0 1" pos="0 0 {c0["offset"] - MJ_CONTACT_RADIUS!r}" contype="0" conaffinity="1" '
                 f'condim="3" friction="{mu!r} 0 0" solref="{contact["solref"]}" solimp="{contact["solimp"]}"/>']
    return "\n".join([
        '<mujoco model="peers">',
        '  <compiler angle="radian" balanceinertia="false" boundmass="0" boundinertia="0"/>',
        *option,
        "  <worldbody>",
        *table,
        *out,
        "  </worldbody>",
        "  <actuator>",
        *acts,
        "  </actuator>",
        "  <keyframe>",
        f'    <key qpos="{fmt(dump["q0"])}" qvel="{fmt(dump["qd0"])}" ctrl="{fmt(dump["q_des0"])}"/>',
        "  </keyframe>",
        "</mujoco>",
        "",
    ])


def check_mujoco_model(xml: str, dump: dict) -> dict:
    """Hand position and M(q) of the MJCF against the project's at the dumped q."""
    import mujoco

    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    site = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "hand")
    armature = np.array(dump["drives"]["jm"])
    worst_hand, worst_m = 0.0, 0.0
    for s in dump["kinematics"]:
        d.qpos[:] = s["q"]
        mujoco.mj_forward(m, d)
        worst_hand = max(worst_hand, float(np.abs(d.site_xpos[site] - s["hand"]).max()))
        full = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, full)
        ours = np.array(s["mass_matrix"])
        worst_m = max(worst_m, float(np.abs(full - np.diag(armature) - ours).max() / np.abs(ours).max()))
    if worst_hand > 1e-12 or worst_m > 1e-12:
        raise PeerError(f"the MJCF does not match the project's model: hand {worst_hand:.2e} m, M(q) {worst_m:.2e} relative")
    early = [int(x) for x in m.actuator_actearly]
    return {"hand_max_abs_m": worst_hand, "mass_matrix_max_rel": worst_m, "na": int(m.na), "actearly": early}


# ---------------------------------------------------------------------------------------------
# ladders


def mujoco_ladder(exe: Path, xml_path: Path, dump: dict, reference: np.ndarray, repeats: int, quick: bool,
                  previous: list[dict] | None = None, ctrl: Path | None = None, integrators: list[str] = MJ_INTEGRATORS,
                  variant: str = "") -> list[dict]:
    """Every integrator over the timesteps; a later pass runs exactly the rungs of `previous`.
    `ctrl`: a time-varying control table (mj_ladder's --ctrl); `variant` names the contact
    settings in the series."""
    rows = []
    duration, sample = dump["duration"], 1.0 / dump["output_rate"]
    steps = [sample / k for k in (MJ_DIVISORS[:8] if quick else MJ_DIVISORS)]
    extra = [] if ctrl is None else [f"--ctrl={ctrl}"]
    for integ in integrators:
        series = f"mujoco {integ}" + (f" {variant}" if variant else "")
        last = None
        for dt in steps:
            predicted = 0.0 if last is None else last["wall_s"] * last["dt"] / dt
            if previous is not None:
                if not any(r["series"] == series and r["dt"] == dt for r in previous):
                    break
            elif predicted > MJ_MAX_PREDICTED_S:
                break
            reps = repeats if predicted < MJ_ONCE_S else 1
            with tempfile.NamedTemporaryFile(suffix=".bin") as f:
                line = run([str(exe), str(xml_path), integ, repr(duration), repr(sample), str(reps), "hand", f.name, *extra, repr(dt)], cwd=xml_path.parent)
                hand = np.fromfile(f.name, dtype=np.float64).reshape(-1, 3)
            dt_, wall, n, _, finite = line.split()
            if len(hand) != len(reference):
                raise PeerError(f"mj_ladder gave {len(hand)} samples, the reference has {len(reference)}")
            err = float(np.linalg.norm(hand - reference, axis=1).max()) if finite == "1" else float("inf")
            ok = finite == "1" and err < 1.0
            row = {"tool": "mujoco", "series": series, "setting": f"h {dt:.3g} s", "dt": dt, "repeats": reps,
                   "wall_s": float(wall), "max_hand_error_m": err, "status": "ok" if ok else "diverged"}
            rows.append(row)
            last = row
    return rows


def merge_best(old: list[dict] | None, new: list[dict]) -> list[dict]:
    """Rows of two passes of one ladder: each row with the better of its two times."""
    if old is None:
        return new
    by_key = {(r["series"], r["setting"]): r for r in old}
    out = []
    for r in new:
        o = by_key.get((r["series"], r["setting"]))
        # a run that failed in a pass has no time (None): the other pass's time, if any, wins
        if o is not None and o["wall_s"] is not None and (r["wall_s"] is None or o["wall_s"] < r["wall_s"]):
            r = o | {"status": r["status"] if r["status"] != "ok" else o["status"]}
        out.append(r)
    return out


def project_ladder(sim: Path, scene: Path, run_name: str, repeats: int) -> list[dict]:
    with tempfile.TemporaryDirectory() as out:
        run([str(sim), "precision", str(scene), "--run", run_name, "--repeats", str(repeats), "-o", out, "-f", "json"])
        rows = json.loads((Path(out) / "precision.json").read_text())
    if isinstance(rows, dict):  # tolerate a wrapped table
        rows = rows.get("rows", rows)
    res = []
    for r in rows:
        ok = r["status"] == "ok" and math.isfinite(r["max_hand_error_m"]) and r["max_hand_error_m"] < 1.0
        res.append({"tool": "project", "series": r["series"], "setting": r["setting"], "wall_s": r["wall_s"],
                    "max_hand_error_m": r["max_hand_error_m"], "rhs_evals": r.get("rhs_evals"),
                    "status": "ok" if ok else (r["status"] if r["status"] != "ok" else "diverged")})
    return res


def time_to_reach(points: list[tuple[float, float]], level: float) -> float | None:
    """The wall time at which a series reaches `level`: the cheapest rung within it, or the
    log-log line between it and the next cheaper rung (which misses the level) where that line
    crosses it. None if no rung reaches it (never extrapolated)."""
    pts = sorted(points)
    best = None
    for i, (w, e) in enumerate(pts):
        if e > level:
            continue
        cand = w
        if i > 0 and pts[i - 1][1] > level and pts[i - 1][0] < w:
            (w0, e0), (w1, e1) = pts[i - 1], (w, e)
            s = (math.log(level) - math.log(e0)) / (math.log(e1) - math.log(e0))
            cand = math.exp(math.log(w0) + s * (math.log(w1) - math.log(w0)))
        best = cand if best is None else min(best, cand)
    return best


def extrapolated(rows: list[dict], level: float) -> tuple[float | None, str | None]:
    """For a level no rung reached: per series, the log-log line through its two most accurate ok
    rungs, followed to the level (only if that line's error falls with time, by at least a factor
    2 between the two rungs: closer errors are a floor, not an order, as MuJoCo's soft contacts
    give; and for at most one decade of error); the cheapest. An estimate, printed as such, never
    used as a measurement."""
    series: dict[str, list] = {}
    for r in rows:
        if r["status"] == "ok" and r["max_hand_error_m"] > 0:
            series.setdefault(r["series"], []).append((r["max_hand_error_m"], r["wall_s"]))
    best, who = None, None
    for name, pts in series.items():
        if len(pts) < 2:
            continue
        (e1, w1), (e0, w0) = sorted(pts)[:2]
        if not (2 * e1 <= e0 and w1 > w0) or level < e1 / 10:
            continue
        slope = (math.log(w1) - math.log(w0)) / (math.log(e1) - math.log(e0))
        t = math.exp(math.log(w1) + slope * (math.log(level) - math.log(e1)))
        if best is None or t < best:
            best, who = t, name
    return best, who


def best_at(rows: list[dict], level: float) -> tuple[float | None, str | None]:
    series: dict[str, list] = {}
    for r in rows:
        if r["status"] == "ok" and r["max_hand_error_m"] > 0:
            series.setdefault(r["series"], []).append((r["wall_s"], r["max_hand_error_m"]))
    best, who = None, None
    for name, pts in series.items():
        t = time_to_reach(pts, level)
        if t is not None and (best is None or t < best):
            best, who = t, name
    return best, who


# ---------------------------------------------------------------------------------------------
# Pinocchio


def pinocchio_check(urdf: Path, dump: dict, rhs_exe: Path | None, pin_exe: Path | None, pin_input: Path | None, quick: bool) -> dict:
    import pinocchio as pin

    model = pin.buildModelFromUrdf(str(urdf))
    model.gravity.linear = np.array(dump["gravity"])
    names = dump["joint_names"]
    idx = [model.getJointId(n) for n in names]
    if any(model.joints[i].idx_v != k for k, i in enumerate(idx)):
        raise PeerError("Pinocchio orders the joints differently from the project")
    model.armature = np.array(dump["drives"]["jm"])
    frames = []
    for c in dump["contacts"]:
        jid = model.getJointId(c["joint"])
        pl = pin.SE3(np.eye(3), np.array(c["point_in_body"]))
        frames.append(model.addFrame(pin.Frame(c["name"], jid, pl, pin.FrameType.OP_FRAME)))
    data = model.createData()
    hand_fid = model.addFrame(pin.Frame("hand_point", model.getJointId(dump["hand"]["joint"]), pin.SE3(np.eye(3), np.array(dump["hand"]["point_in_body"])), pin.FrameType.OP_FRAME))
    data = model.createData()
    worst = {"hand_m": 0.0, "mass_matrix_rel": 0.0, "qdd_rel": 0.0, "normal_force_rel": 0.0}
    for s in dump["kinematics"]:
        q = np.array(s["q"])
        pin.framesForwardKinematics(model, data, q)
        worst["hand_m"] = max(worst["hand_m"], float(np.abs(data.oMf[hand_fid].translation - s["hand"]).max()))
        mm = pin.crba(model, data, q)
        mm = np.triu(mm) + np.triu(mm, 1).T
        ours = np.array(s["mass_matrix"]) + np.diag(model.armature)
        worst["mass_matrix_rel"] = max(worst["mass_matrix_rel"], float(np.abs(mm - ours).max() / np.abs(ours).max()))

    normals = [np.array(c["normal"]) for c in dump["contacts"]]

    def constraint_rows(q, v):
        pin.forwardKinematics(model, data, q, v, np.zeros(model.nv))
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        jac = np.zeros((len(frames), model.nv))
        gamma = np.zeros(len(frames))
        for k, (fid, n) in enumerate(zip(frames, normals)):
            jf = pin.getFrameJacobian(model, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
            jac[k] = n @ jf[:3]
            gamma[k] = n @ pin.getFrameClassicalAcceleration(model, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED).linear
        return jac, gamma

    for s in dump["dynamics"]:
        q, v, tau = (np.array(s[k]) for k in ("q", "qd", "tau_drive"))
        jac, gamma = constraint_rows(q, v)
        # KKT: [M + J_m, J^T; J, 0] [q̈; -λ] = [τ - h - G; -J̇q̇]  (Pinocchio's forwardDynamics with J, γ)
        qdd = pin.forwardDynamics(model, data, q, v, tau, jac, gamma, 0.0)
        ours = np.array(s["qdd"])
        worst["qdd_rel"] = max(worst["qdd_rel"], float(np.abs(qdd - ours).max() / max(1.0, np.abs(ours).max())))
        if len(frames):
            f_ours = np.array(s["normal_force"])
            f_pin = np.array(data.lambda_c)
            # the project's f_n pushes along +n (J^T f_n on the right-hand side)
            worst["normal_force_rel"] = max(worst["normal_force_rel"], float(np.abs(f_pin - f_ours).max() / max(1.0, np.abs(f_ours).max())))

    # timing: the two-contact constrained forward dynamics, through Python (an upper bound of its C++)
    s = dump["dynamics"][0]
    q, v, tau = (np.array(s[k]) for k in ("q", "qd", "tau_drive"))
    n = 2000 if quick else 20000
    timings = {}
    jac, gamma = constraint_rows(q, v)

    def best_of(f, rounds=7):
        b = float("inf")
        for _ in range(rounds):
            t0 = time.perf_counter()
            for _ in range(n):
                f()
            b = min(b, (time.perf_counter() - t0) / n)
        return b

    timings["python_noop_call_s"] = best_of(lambda: pin.SE3.Identity)  # a trivial bound call, for scale
    timings["forwardDynamics_J_gamma_s"] = best_of(lambda: pin.forwardDynamics(model, data, q, v, tau, jac, gamma, 0.0))
    # the 3D point contacts of Pinocchio's constraintDynamics (3 rows per elbow: not our model,
    # which holds only the normal; timed for scale against the numbers)
    cms = pin.StdVec_RigidConstraintModel()
    for c in dump["contacts"]:
        jid = model.getJointId(c["joint"])
        cms.append(pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model, jid, pin.SE3(np.eye(3), np.array(c["point_in_body"])), pin.ReferenceFrame.LOCAL_WORLD_ALIGNED))
    cds = pin.StdVec_RigidConstraintData()
    for cm in cms:
        cds.append(cm.createData())
    if len(cms):
        pin.initConstraintDynamics(model, data, cms, cds)
        timings["constraintDynamics_3d_s"] = best_of(lambda: pin.constraintDynamics(model, data, q, v, tau, cms, cds))
    timings["aba_s"] = best_of(lambda: pin.aba(model, data, q, v, tau))
    result = {"check": worst, "python_timing": timings}
    if rhs_exe is None:
        return result
    calls = 20000 if quick else 100000
    # C++ Pinocchio (pin_kernels.cpp) and our RHS (rhs_profile) in interleaved rounds; the
    # median of the per-round ratios (the machine is shared: rounds see different loads)
    rounds = []
    for _ in range(3 if quick else 7):
        ours = float(run([str(rhs_exe), str(calls)]).split()[0])
        row = {"project_rhs_two_elbow_us": ours, "python_constraintDynamics_3d_us": None}
        if pin_exe is not None:
            for line in run([str(pin_exe), str(pin_input), str(calls)]).splitlines():
                if line.startswith("#ddq"):
                    cpp_ddq = np.array([float(x) for x in line.split()[1:]])
                    continue
                k, v_ = line.split()
                row[f"pin_{k}_us"] = float(v_)
            # the C++ model is the Python one rebuilt joint by joint: same accelerations
            py_ddq = pin.constraintDynamics(model, data, q, v, tau, cms, cds) if len(cms) else pin.aba(model, data, q, v, tau)
            worst["cpp_vs_python_ddq_rel"] = max(worst.get("cpp_vs_python_ddq_rel", 0.0), float(np.abs(cpp_ddq - py_ddq).max() / max(1.0, np.abs(py_ddq).max())))
        rounds.append(row)
    result["rounds"] = rounds
    med = lambda xs: float(np.median(xs))
    result["project_rhs_two_elbow_us"] = med([r["project_rhs_two_elbow_us"] for r in rounds])
    result["ratio_rhs_vs_python_forwardDynamics_J"] = result["project_rhs_two_elbow_us"] * 1e-6 / timings["forwardDynamics_J_gamma_s"]
    if pin_exe is not None:
        for k in [k for k in rounds[0] if k.startswith("pin_")]:
            result[k] = med([r[k] for r in rounds])
        if "pin_constraintDynamics_3d_us" in rounds[0]:
            result["ratio_rhs_vs_cpp_constraintDynamics_3d"] = med([r["project_rhs_two_elbow_us"] / r["pin_constraintDynamics_3d_us"] for r in rounds])
    return result


def pin_kernels_input(urdf: Path, dump: dict, path: Path) -> None:
    """The model Pinocchio's Python bindings parse from the URDF, joint by joint, for pin_kernels."""
    import pinocchio as pin

    model = pin.buildModelFromUrdf(str(urdf))
    lines = []
    units = {"JointModelRX": (1, 0, 0), "JointModelRY": (0, 1, 0), "JointModelRZ": (0, 0, 1)}
    for i in range(1, model.njoints):
        jm = model.joints[i]
        short = jm.shortname()
        if short in units:
            axis = units[short]
        elif short == "JointModelRevoluteUnaligned":
            axis = tuple(jm.extract().axis)
        else:
            raise PeerError(f"pin_kernels: joint type {short} is not supported")
        pl, it = model.jointPlacements[i], model.inertias[i]
        ii = it.inertia
        vals = [model.parents[i], *axis, *pl.rotation.reshape(-1), *pl.translation, it.mass, *it.lever,
                ii[0, 0], ii[0, 1], ii[1, 1], ii[0, 2], ii[1, 2], ii[2, 2]]
        lines.append(f"joint {model.names[i]} " + " ".join(repr(float(x)) if not isinstance(x, int) else str(x) for x in vals))
    s = dump["dynamics"][0]
    lines += [f"gravity {fmt(dump['gravity'])}", f"armature {fmt(dump['drives']['jm'])}",
              f"q {fmt(s['q'])}", f"v {fmt(s['qd'])}", f"tau {fmt(s['tau_drive'])}"]
    lines += [f"contact {c['joint']}" for c in dump["contacts"]]
    path.write_text("\n".join(lines) + "\n")


CACHE = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "elbow-sim" / "peers-build"


def cached_exe(name: str, sources: list[Path], flags: list[str]) -> Path:
    """Where a helper built from `sources` with `flags` is kept between runs (Pinocchio's C++
    takes minutes to compile): the name carries a hash of both."""
    import hashlib

    h = hashlib.sha256("\0".join(flags).encode())
    for src in sources:
        h.update(src.read_bytes())
    CACHE.mkdir(parents=True, exist_ok=True)
    return CACHE / f"{name}-{h.hexdigest()[:16]}"


def build_pin_kernels(cxx: str, work: Path) -> Path | None:
    """pin_kernels.cpp against the `pin` wheel's headers and libpinocchio_default (Eigen's headers
    from cmeel-eigen); None, with a note, when they are not there."""
    import cmeel  # noqa: F401  (the wheels' prefix)

    prefix = Path(sys.prefix) / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}" / "site-packages" / "cmeel.prefix"
    if not (prefix / "include/eigen3").exists() or not (prefix / "include/pinocchio").exists():
        print(f"(no Pinocchio C++ timing: {prefix}/include needs pinocchio and eigen3: pip install cmeel-eigen)")
        return None
    exe = cached_exe("pin_kernels", [HERE / "pin_kernels.cpp"], [cxx, str(prefix)])
    if exe.exists():
        return exe
    t0 = time.time()
    # the compile definitions of Pinocchio's exported CMake targets (lib/cmake/pinocchio)
    defs = ["-DBOOST_MPL_LIMIT_LIST_SIZE=30", "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30", "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS",
            "-DBOOST_FUSION_INVOKE_MAX_ARITY=12", "-DPINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION"]
    run([cxx, "-O3", "-DNDEBUG", "-std=c++17", *defs, "-o", str(exe), str(HERE / "pin_kernels.cpp"), f"-I{prefix / 'include'}",
         f"-I{prefix / 'include/eigen3'}", f"-L{prefix / 'lib'}", "-lpinocchio_default", f"-Wl,-rpath,{prefix / 'lib'}"])
    print(f"(built pin_kernels in {time.time() - t0:.0f} s)")
    return exe


# ---------------------------------------------------------------------------------------------


def figure(stem: Path, title: str, rows: list[dict]) -> None:
    """The work-precision diagram: max hand error against wall time, log-log, one line per series
    through its rungs in ladder order (the project's solid, MuJoCo's dashed); failed or diverged
    rungs left out."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 5.5), dpi=110)
    series = {}
    for r in rows:
        if r["status"] == "ok" and r["wall_s"] and r["max_hand_error_m"] and math.isfinite(r["max_hand_error_m"]):
            series.setdefault((r["tool"], r["series"]), []).append((r["wall_s"], r["max_hand_error_m"]))
    for (tool, name), pts in sorted(series.items()):
        x, y = zip(*pts)  # in ladder order (tolerance or step), as a work-precision line is read
        ax.plot(x, y, "-o" if tool == "project" else "--s", ms=3, lw=1.2, label=name if tool == "project" else name)
    for lv in LEVELS:
        ax.axhline(lv, color="0.85", lw=0.6, zorder=0)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time of the 5-s run [s] (best of the passes)")
    ax.set_ylabel("max hand error against the reference [m]")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    fig.tight_layout()
    stem.parent.mkdir(parents=True, exist_ok=True)
    for ext in ("svg", "png"):
        fig.savefig(f"{stem}.{ext}")
    plt.close(fig)


def fmt_t(t):
    return "—" if t is None else (f"{t * 1e3:.1f} ms" if t >= 1e-3 else f"{t * 1e6:.0f} µs")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sim", type=Path, default=ROOT / "target/release/sim", help="the project's `sim` binary")
    ap.add_argument("--dump", type=Path, default=ROOT / "target/release/examples/peers_dump", help="sim/examples/peers_dump")
    ap.add_argument("--rhs", type=Path, default=ROOT / "target/release/examples/rhs_profile", help="sim/examples/rhs_profile (ours, for Pinocchio)")
    ap.add_argument("--scene", action="append", type=Path, help="scene JSON (repeatable) [default: the two peers scenes]")
    ap.add_argument("--run", default="no-elbow", help="the run of each scene")
    ap.add_argument("--repeats", type=int, default=3, help="timed repetitions, best kept (both tools)")
    ap.add_argument("--quick", action="store_true", help="shorter MuJoCo ladder, fewer Pinocchio calls")
    ap.add_argument("--passes", type=int, default=2, help="alternating passes of the two ladders; each row keeps its best time")
    ap.add_argument("--no-pinocchio", action="store_true")
    ap.add_argument("--json", type=Path, help="write every row and ratio here")
    ap.add_argument("--figure", type=Path, help="write the work-precision diagram of each scene here: PATH-<scene>.svg and .png (needs matplotlib)")
    ap.add_argument("--cc", default=os.environ.get("CC", "cc"), help="C compiler for mj_ladder.c")
    ap.add_argument("--cxx", default=os.environ.get("CXX", "c++"), help="C++ compiler for pin_kernels.cpp (Pinocchio's C++ timing)")
    a = ap.parse_args()
    if a.passes < 1 or a.repeats < 1:
        raise PeerError("--passes and --repeats must be at least 1")
    scenes = a.scene or [ROOT / "sim/scenes/peers/mechanical-hold.json", ROOT / "sim/scenes/peers/dcmotor-hold.json"]
    for p, what in [(a.sim, "--sim"), (a.dump, "--dump")]:
        if not p.exists():
            raise PeerError(f"{what} {p} does not exist: cargo build --release --bin sim && cargo build --release -p sim --example peers_dump --example rhs_profile")
    import mujoco

    mjdir = Path(mujoco.__file__).parent
    libs = sorted(mjdir.glob("libmujoco.so*"))
    if not libs:
        raise PeerError(f"no libmujoco.so in {mjdir}")
    work = Path(tempfile.mkdtemp(prefix="peers-"))
    exe = cached_exe("mj_ladder", [HERE / "mj_ladder.c"], [a.cc, str(libs[0])])
    run([a.cc, "-O2", "-o", str(exe), str(HERE / "mj_ladder.c"), f"-I{mjdir / 'include'}", f"-L{mjdir}", f"-l:{libs[0].name}", f"-Wl,-rpath,{mjdir}", "-lm"])

    load = os.getloadavg()
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), platform.processor())
    report = {"date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()), "cpu": cpu, "cores": os.cpu_count(),
              "load_at_start": load, "mujoco": mujoco.__version__, "sim": str(a.sim), "scenes": []}
    print(f"# peers: {report['date_utc']} UTC, {cpu}, {os.cpu_count()} cores, load {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}, MuJoCo {mujoco.__version__}")

    for scene in scenes:
        # peers_dump validates the scene (a clear error for a bad file or run name) before it is read here
        dump = json.loads(run([str(a.dump), str(scene), a.run, "--reference", "--targets"]))
        urdf = (scene.parent / json.loads(scene.read_text())["urdf"]).resolve()
        reference = np.array(dump["reference_hand"])
        electrical = "quasi-static" if all(x == 0.0 for x in dump["drives"]["l"]) else "inductive"
        ctrl = None
        tq = np.array(dump["targets"]["q_des"])
        # (q_d(0) = q_d(T) says nothing: a full circle ends where it starts)
        if np.abs(tq - tq[0]).max() > 1e-12:
            # a tracking run: MuJoCo's position input u with v = k_p (u − q) − k_d q̇ equals eq 27's
            # v = k_p (q_d − q) + k_d (q̇_d − q̇) for u = q_d + (k_d / k_p) q̇_d (per joint)
            tg = dump["targets"]
            kp, kd = np.array(dump["gains"]["kp"]), np.array(dump["gains"]["kd"])
            u = np.array(tg["q_des"]) + (kd / kp) * np.array(tg["qd_des"])
            ctrl = work / f"{scene.stem}-{a.run}-ctrl.bin"
            with open(ctrl, "wb") as f:
                np.array(u.shape, dtype=np.int64).tofile(f)
                np.array([tg["dt"]], dtype=np.float64).tofile(f)
                np.ascontiguousarray(u, dtype=np.float64).tofile(f)
        contacts = dump.get("contacts", [])
        for c in contacts:
            law = c["law"]
            if law["model"] != "unilateral" or law["restitution"] != 0.0 or c["normal"] != [0.0, 0.0, 1.0] or c["offset"] != contacts[0]["offset"] or c["joint"] is None:
                raise PeerError(f"{scene}: contact {c['name']}: the peers compare rigid unilateral contacts with restitution 0 "
                                f"on links against one horizontal table (law {law}, normal {c['normal']}, offset {c['offset']})")
        variants = [(name, v) for name, v in MJ_CONTACT_VARIANTS.items()] if contacts else [("", None)]
        xmls = []
        for name, v in variants:
            xml = mjcf(urdf, dump, electrical, v)
            xml_path = work / f"{scene.stem}{'-' + name if name else ''}.xml"
            xml_path.write_text(xml)
            xmls.append((name, xml_path))
        check = check_mujoco_model(xml, dump)
        print(f"\n## {scene.relative_to(ROOT) if scene.is_relative_to(ROOT) else scene} (run {a.run}, {electrical})")
        print(f"MJCF check at {len(dump['kinematics'])} q: hand {check['hand_max_abs_m']:.1e} m, M(q) {check['mass_matrix_max_rel']:.1e} rel; "
              f"MuJoCo activations {check['na']}, actearly {sorted(set(check['actearly']))}")
        # the ladders alternate (project, MuJoCo, project, ...) for --passes passes; each row keeps
        # its best time over the passes (its error is the same every time: both are deterministic),
        # so a load change on the shared machine during one ladder does not skew the ratios alone
        mj_rows, pr_rows, loads = None, None, []
        for p in range(a.passes):
            t0 = time.time()
            pr = project_ladder(a.sim, scene, a.run, a.repeats)
            t_pr = time.time() - t0
            t0 = time.time()
            mj = []
            for name, xml_path in xmls:
                integrators = MJ_CONTACT_INTEGRATORS if contacts else MJ_INTEGRATORS
                prev = None if mj_rows is None else [r for r in mj_rows if r["series"].endswith(name)]
                mj += mujoco_ladder(exe, xml_path, dump, reference, a.repeats, a.quick, prev, ctrl, integrators, name)
            t_mj = time.time() - t0
            mj_rows, pr_rows = merge_best(mj_rows, mj), merge_best(pr_rows, pr)
            loads.append(os.getloadavg())
            print(f"(pass {p + 1}: project ladder {t_pr:.0f} s, MuJoCo ladder {t_mj:.0f} s of wall; load {loads[-1][0]:.2f})")
        load_now = loads[-1]
        ratios = []
        print("\n| max hand error | MuJoCo best | (integrator) | project best | (series) | project / MuJoCo |")
        print("|---|---|---|---|---|---|")
        # MuJoCo's best reachable hand error (its floor, plus 2 %, so that the rung that reaches it
        # is within the level): a level of its own, beside the fixed ones
        mj_ok = [r["max_hand_error_m"] for r in mj_rows if r["status"] == "ok" and math.isfinite(r["max_hand_error_m"])]
        floor = 1.02 * min(mj_ok) if mj_ok else None
        levels = sorted(LEVELS + ([floor] if floor is not None and all(abs(floor / lv - 1) > 0.05 for lv in LEVELS) else []), reverse=True)
        for lv in levels:
            tm, wm = best_at(mj_rows, lv)
            tp, wp = best_at(pr_rows, lv)
            ratio = tp / tm if tm and tp else None
            entry = {"level_m": lv, "mujoco_s": tm, "mujoco_series": wm, "project_s": tp, "project_series": wp, "ratio": ratio}
            rs = "—" if ratio is None else (f"{ratio:.3f} ({1 / ratio:.1f}x faster)" if ratio < 1 else f"{ratio:.2f} ({ratio:.1f}x slower)")
            mj_text = f"{fmt_t(tm)} | {wm}"
            if tm is None:
                te, we = extrapolated(mj_rows, lv)
                entry |= {"mujoco_extrapolated_s": te, "mujoco_extrapolated_series": we}
                mj_text = "not reached | " if te is None else f"not reached (~{fmt_t(te)} extrapolated) | {we}"
                if te is not None and tp is not None:
                    rs = f"~{tp / te:.4f} (~{te / tp:.0f}x faster, against the extrapolation)"
            entry["mujoco_floor"] = lv == floor
            ratios.append(entry)
            print(f"| {lv:.1e} m (MuJoCo's floor)" if lv == floor else f"| {lv:.0e} m", end="")
            print(f" | {mj_text} | {fmt_t(tp)} | {wp or 'not reached'} | {rs} |")
        print("\nLadders (wall = best of %d per pass, best of %d passes; error = max |r_hand - r_ref| over the 1 ms samples):" % (a.repeats, a.passes))
        print("| tool | series | setting | wall | max hand error [m] | status |")
        print("|---|---|---|---|---|---|")
        for r in mj_rows + pr_rows:
            err = r['max_hand_error_m']
            err = "-" if err is None else f"{err:.2e}"  # a failed run has no error
            print(f"| {r['tool']} | {r['series']} | {r['setting']} | {fmt_t(r['wall_s'])} | {err} | {r['status']} |")
        if a.figure:
            figure(a.figure.parent / f"{a.figure.name}-{scene.stem}", f"{scene.stem}, run {a.run}", mj_rows + pr_rows)
        report["scenes"].append({"scene": str(scene), "run": a.run, "electrical": electrical, "mjcf_check": check,
                                 "mujoco_contact_variants": MJ_CONTACT_VARIANTS if contacts else None,
                                 "ratios": ratios, "mujoco": mj_rows, "project": pr_rows, "loads_after_each_pass": loads})

    if not a.no_pinocchio:
        paper = ROOT / "sim/scenes/paper.json"
        dump = json.loads(run([str(a.dump), str(paper), "two-elbow", "--states", "6"]))
        urdf = (paper.parent / json.loads(paper.read_text())["urdf"]).resolve()
        pin_exe, pin_input = build_pin_kernels(a.cxx, work), work / "pin_input.txt"
        if pin_exe is not None:
            pin_kernels_input(urdf, dump, pin_input)
        pc = pinocchio_check(urdf, dump, a.rhs if a.rhs.exists() else None, pin_exe, pin_input, a.quick)
        import pinocchio as pin

        report["pinocchio"] = pc | {"version": pin.__version__}
        c, t = pc["check"], pc["python_timing"]
        print(f"\n## Pinocchio {pin.__version__}: the paper scene, two-elbow run")
        print(f"cross-check at {len(dump['dynamics'])} states: hand {c['hand_m']:.1e} m, M + J_m {c['mass_matrix_rel']:.1e} rel, "
              f"constrained q̈ {c['qdd_rel']:.1e} rel, normal forces {c['normal_force_rel']:.1e} rel")
        print("\n| kernel | time per call | ours / it |")
        print("|---|---|---|")
        ours = pc.get("project_rhs_two_elbow_us")
        if ours is not None:
            print(f"| ours: the two-elbow right-hand side (rhs_profile: motors, IK, PD, eq 21) | {ours:.2f} µs | 1 |")
        for k, v in pc.items():
            if k.startswith("pin_"):
                r = "" if ours is None else f"{ours / v:.2f}"
                if k == "pin_constraintDynamics_3d_us" and "ratio_rhs_vs_cpp_constraintDynamics_3d" in pc:
                    r = f"{pc['ratio_rhs_vs_cpp_constraintDynamics_3d']:.2f} (median of per-round ratios)"
                print(f"| Pinocchio C++ {k[4:-3]} | {v:.2f} µs | {r} |")
        for k, v in t.items():
            if k == "python_noop_call_s":
                print(f"| (a trivial call through the bindings, for scale) | {v * 1e6:.2f} µs | |")
                continue
            print(f"| Pinocchio via Python {k[:-2]} (an upper bound of its C++) | {v * 1e6:.2f} µs | {'' if ours is None else f'{ours * 1e-6 / v:.2f}'} |")
        tol = 1e-9
        if max(c.values()) > tol:
            raise PeerError(f"Pinocchio disagrees with the project beyond {tol:g}: {c}")
    if a.json:
        a.json.write_text(json.dumps(report, indent=1) + "\n")
    shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except PeerError as e:
        print(f"peers: {e}", file=sys.stderr)
        sys.exit(2)
