#!/usr/bin/env python3
"""Independent check of the arm scenes in this directory (numpy only; not run by CI).

For each scene: reads its URDF (forward kinematics written here from the URDF joint origins and
axes, not the simulator's), checks every link's inertia (positive, triangle inequality), then
solves the scene's Cartesian task along its whole path by damped least squares with the scene's
posture in the null space and the contacts named in `keep_contacts` held on their planes, and
reports: the residuals (hand and contacts, m), the joint ranges used against the URDF limits,
the joint speeds (finite differences of the solutions, rad/s) against the URDF velocity limits,
q(0) (the `from-target` initial posture), the lowest hand point against the table, and the
statics of the free run: the gravity torque of each joint along the path against its effort
limit, and the motor current and R i it takes against the scene's current and voltage limits.

Usage: python3 check_arms.py [scene.json ...]   (default: every *.json here)
"""
import json
import math
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np


def rpy_matrix(r, p, y):
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def axis_angle(axis, q):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(q) * k + (1 - math.cos(q)) * k @ k


def floats(s, n=3, default=0.0):
    return [float(x) for x in s.split()] if s else [default] * n


class Urdf:
    def __init__(self, path):
        root = ET.parse(path).getroot()
        self.joints = {}
        self.child_joint = {}
        self.links = {l.get("name"): l for l in root.findall("link")}
        self.movable = []
        self.inertials = {}
        for name, l in self.links.items():
            i = l.find("inertial")
            if i is not None:
                o = i.find("origin")
                self.inertials[name] = (float(i.find("mass").get("value")), np.array(floats(o.get("xyz") if o is not None else None)))
        for j in root.findall("joint"):
            o = j.find("origin")
            xyz = floats(o.get("xyz") if o is not None else None)
            rpy = floats(o.get("rpy") if o is not None else None)
            ax = j.find("axis")
            lim = j.find("limit")
            d = dict(name=j.get("name"), type=j.get("type"), parent=j.find("parent").get("link"),
                     child=j.find("child").get("link"), xyz=np.array(xyz), R=rpy_matrix(*rpy),
                     axis=floats(ax.get("xyz")) if ax is not None else [1, 0, 0])
            if lim is not None:
                d["lo"], d["hi"] = float(lim.get("lower", "-inf")), float(lim.get("upper", "inf"))
                d["vel"], d["effort"] = float(lim.get("velocity", "inf")), float(lim.get("effort", "inf"))
            self.joints[d["name"]] = d
            self.child_joint[d["child"]] = d
            if d["type"] in ("revolute", "continuous"):
                self.movable.append(d["name"])
        # depth-first order from the root, as a URDF tree walk (the simulator's dof order)
        roots = [l for l in self.links if l not in self.child_joint]
        assert len(roots) == 1, roots
        order, stack = [], [roots[0]]
        while stack:
            link = stack.pop()
            kids = [j for j in self.joints.values() if j["parent"] == link]
            for j in kids:
                if j["type"] in ("revolute", "continuous"):
                    order.append(j["name"])
            stack.extend(reversed([j["child"] for j in kids]))
        self.dofs = order
        self.index = {n: i for i, n in enumerate(order)}

    def frame(self, link, q):
        """World pose (R, p) of `link`'s frame."""
        chain = []
        while link in self.child_joint:
            j = self.child_joint[link]
            chain.append(j)
            link = j["parent"]
        R, p = np.eye(3), np.zeros(3)
        for j in reversed(chain):
            p = p + R @ j["xyz"]
            R = R @ j["R"]
            if j["name"] in self.index:
                R = R @ axis_angle(j["axis"], q[self.index[j["name"]]])
        return R, p

    def point(self, spec, q):
        if spec.get("joint"):
            link = self.joints[spec["joint"]]["child"]
        else:
            link = spec["link"]
        R, p = self.frame(link, q)
        return p + R @ np.array(spec.get("offset", [0, 0, 0]), float)

    def check_inertias(self):
        bad = []
        for name, l in self.links.items():
            i = l.find("inertial")
            if i is None:
                continue
            m = float(i.find("mass").get("value"))
            t = i.find("inertia")
            g = lambda k: float(t.get(k, "0"))
            I = np.array([[g("ixx"), g("ixy"), g("ixz")], [g("ixy"), g("iyy"), g("iyz")], [g("ixz"), g("iyz"), g("izz")]])
            ev = np.sort(np.linalg.eigvalsh(I))
            if m <= 0 or ev[0] <= 0 or ev[0] + ev[1] < ev[2] * (1 - 1e-12):
                bad.append((name, m, ev))
        return bad


def holding_torques(u, q, g=9.81, h=1e-6):
    """The joint torques that hold the arm still against gravity, N m: dV/dq, V = sum m g z_c."""
    def V(qq):
        v = 0.0
        for link, (m, c) in u.inertials.items():
            if link not in u.child_joint:
                continue  # the root: welded to the world
            R, p = u.frame(link, qq)
            v += m * g * (p + R @ c)[2]
        return v
    out = np.zeros(len(q))
    for k in range(len(q)):
        dq = np.zeros(len(q)); dq[k] = h
        out[k] = (V(q + dq) - V(q - dq)) / (2 * h)
    return out


def drive_check(s, u, qs):
    """Statics of the free run along the path: the holding torque against the URDF effort limit,
    its motor current tau / (K_t N) against the scene's current limit, and R i against the supply."""
    m = s["motor"]
    n = len(u.dofs)
    per = lambda key, default=None: np.broadcast_to(np.array(m.get(key, default), float), (n,))
    kt, r, N = per("torque_constant"), per("resistance"), per("gear_ratio")
    ilim, vlim = per("current_limit", np.inf), per("voltage_limit", np.inf)
    tau = np.max(np.abs(np.array([holding_torques(u, q) for q in qs[::5]])), axis=0)
    ok = True
    for k, name in enumerate(u.dofs):
        eff = u.joints[name]["effort"]
        i = tau[k] / (kt[k] * N[k])
        ok &= tau[k] <= eff and i <= ilim[k] and r[k] * i <= vlim[k]
        print(f"   {name:22s} gravity {tau[k]:8.4f} N m (effort {eff:g}), current {i:6.3f} A (limit {ilim[k]:g}), R i = {r[k] * i:6.3f} V (supply {vlim[k]:g})")
    print("   the drives hold the arm without its contact along the path" if ok else "   A DRIVE CANNOT HOLD THE ARM")
    return ok


def circle(path, t):
    c, n = np.array(path["center"], float), np.array(path.get("normal", [0, 0, 1]), float)
    assert np.allclose(n, [0, 0, 1]), "this checker knows horizontal circles only"
    s = 1.0 if path.get("direction", "counter-clockwise") == "counter-clockwise" else -1.0
    a = path.get("phase", 0.0) + s * 2 * math.pi * t / path["period"]
    return c + path["radius"] * np.array([math.cos(a), math.sin(a), 0.0])


def solve(u, tasks, q, posture, w_post=1.0, tol=1e-12, iters=200):
    """Damped least squares on the stacked tasks (hand position, contact heights), the posture in the null space."""
    n = len(q)
    for it in range(iters):
        e, J = residual_and_jacobian(u, tasks, q)
        if np.max(np.abs(e)) < tol:
            return q, np.max(np.abs(e)), it
        lam = min(1e-2, 10 * np.linalg.norm(e))
        JJt = J @ J.T
        Jp = J.T @ np.linalg.inv(JJt + lam * lam * np.eye(len(e)))
        dq = Jp @ (-e)
        null = np.eye(n) - np.linalg.pinv(J) @ J
        dq = dq + null @ (w_post * 0.5 * (posture - q))
        step = np.linalg.norm(dq)
        if step > 0.2:  # a trust region: continuation along the path, never a jump
            dq *= 0.2 / step
        q = q + dq
    e, _ = residual_and_jacobian(u, tasks, q)
    return q, np.max(np.abs(e)), iters


def residual_and_jacobian(u, tasks, q, h=1e-7):
    def res(qq):
        out = []
        for kind, spec, target in tasks:
            p = u.point(spec, qq)
            if kind == "pos":
                out.extend(p - target)
            else:
                nrm, off = target
                out.append(float(np.dot(nrm, p) - off))
        return np.array(out)
    e = res(q)
    J = np.zeros((len(e), len(q)))
    for k in range(len(q)):
        dq = np.zeros(len(q)); dq[k] = h
        J[:, k] = (res(q + dq) - res(q - dq)) / (2 * h)
    return e, J


def check_scene(path):
    s = json.loads(Path(path).read_text())
    u = Urdf(Path(path).parent / s["urdf"])
    print(f"== {s['name']} ({path}): {len(u.dofs)} joints {u.dofs}")
    bad = u.check_inertias()
    print("   inertias:", "all physical (positive, triangle inequality)" if not bad else f"NOT physical: {bad}")
    tgt = s["target"]
    ik = tgt["ik"]
    posture = np.array(ik["posture"], float)
    contacts = {c["name"]: c for c in s.get("contacts", [])}
    keep = [contacts[k] for k in ik.get("keep_contacts", [])]
    path_spec = tgt["path"]
    T = s["duration"]
    N = 100
    q = posture.copy()
    qs, worst, worst_t = [], 0.0, 0.0
    for k in range(N + 1):
        t = T * k / N
        tasks = [("pos", s["hand"], circle(path_spec, t))]
        for c in keep:
            tasks.append(("plane", c["point"], (np.array(c["plane"]["normal"], float), c["plane"]["offset"])))
        q, r, it = solve(u, tasks, q, posture)
        if r > worst:
            worst, worst_t = r, t
        qs.append(q.copy())
    qs = np.array(qs)
    print(f"   IK along the path ({N + 1} samples over {T} s): worst residual {worst:.2e} m at t = {worst_t:.3f} s")
    q0 = qs[0]
    print("   q(0) =", "[" + ", ".join(f"{x:.9f}" for x in q0) + "]")
    for c in keep:
        z = np.dot(c["plane"]["normal"], u.point(c["point"], q0)) - c["plane"]["offset"]
        print(f"   contact {c['name']}: distance to its plane at q(0) {z:.2e} m")
    print(f"   hand at q(0): {u.point(s['hand'], q0)}")
    ok = True
    qd = np.gradient(qs, T / N, axis=0)
    for name in u.dofs:
        j = u.joints[name]
        i = u.index[name]
        lo, hi = qs[:, i].min(), qs[:, i].max()
        inside = j["lo"] <= lo and hi <= j["hi"]
        vmax = np.abs(qd[:, i]).max()
        ok &= inside and vmax <= j["vel"]
        print(f"   {name:22s} q in [{lo:+.4f}, {hi:+.4f}] (limit [{j['lo']:+.4f}, {j['hi']:+.4f}]) {'ok' if inside else 'OUTSIDE'};"
              f" |qd| <= {vmax:.3f} rad/s (limit {j['vel']:.3f})")
    # every joint origin but the contact points' stays on the table's side of its plane
    for c in keep:
        nrm, off = np.array(c["plane"]["normal"], float), c["plane"]["offset"]
        cj = c["point"].get("joint")
        others = [n for n in u.dofs if n != cj]
        low = min(float(np.dot(nrm, u.frame(u.joints[n]["child"], qq)[1]) - off) for qq in qs[::10] for n in others)
        hand_low = min(float(np.dot(nrm, u.point(s["hand"], qq)) - off) for qq in qs)
        print(f"   plane of {c['name']}: lowest other joint origin {low:+.4f} m, lowest hand point {hand_low:+.4f} m (>= 0: above the table)")
        ok &= hand_low >= -1e-9
    print("   joint limits hold along the path" if ok else "   A LIMIT IS CROSSED")
    ok &= drive_check(s, u, qs)
    return ok and worst < 1e-9


if __name__ == "__main__":
    here = Path(__file__).parent
    files = sys.argv[1:] or sorted(str(p) for p in here.glob("*.json"))
    results = [check_scene(f) for f in files]
    sys.exit(0 if all(results) else 1)
