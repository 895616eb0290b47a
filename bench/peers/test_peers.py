"""Tests of peers.py's own arithmetic (the model checks against MuJoCo and Pinocchio run inside
peers.py itself, on every run). Run: python -m unittest discover -s bench/peers"""
import math
import unittest

import numpy as np

import peers


def rx(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def ry(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


class Rotations(unittest.TestCase):
    def test_urdf_rpy_is_fixed_axis_xyz(self):
        """URDF: R = Rz(yaw) Ry(pitch) Rx(roll); the quaternion's matrix equals it to 1e-15."""
        rng = np.random.default_rng(1)
        for _ in range(50):
            r, p, y = rng.uniform(-math.pi, math.pi, 3)
            q = peers.rpy_quat([r, p, y])
            self.assertAlmostEqual(float(np.linalg.norm(q)), 1.0, delta=1e-15)
            self.assertLess(np.abs(peers.quat_matrix(q) - rz(y) @ ry(p) @ rx(r)).max(), 1e-15)


class Interpolation(unittest.TestCase):
    def test_exact_on_a_power_law(self):
        """On rungs of an exact power law (error ~ time^-4), the log-log interpolation at a level
        between two rungs returns the law's time to 1e-12 relative."""
        law = lambda w: 1e-3 * (w / 0.01) ** -4
        pts = [(w, law(w)) for w in (0.01, 0.02, 0.05, 0.1)]
        level = 2e-6
        expect = 0.01 * (level / 1e-3) ** (-1 / 4)
        self.assertLess(abs(peers.time_to_reach(pts, level) / expect - 1), 1e-12)

    def test_never_extrapolates(self):
        pts = [(0.01, 1e-3), (0.02, 1e-4)]
        self.assertIsNone(peers.time_to_reach(pts, 1e-5))
        # a rung already within the level: its own time, with no cheaper rung to interpolate from
        self.assertEqual(peers.time_to_reach(pts, 1e-2), 0.01)

    def test_cheapest_rung_within_wins_on_a_non_monotone_ladder(self):
        """A cheap rung that happens to be accurate beats the interpolation of dearer ones."""
        pts = [(0.01, 1e-7), (0.02, 1e-3), (0.04, 1e-9)]
        self.assertEqual(peers.time_to_reach(pts, 1e-6), 0.01)

    def test_a_floor_is_not_extrapolated(self):
        """Two most accurate rungs within a factor 2 of each other (a soft-contact floor): no
        estimate, where the line through them would promise any accuracy at some cost."""
        rows = [{"series": "a", "wall_s": w, "max_hand_error_m": e, "status": "ok"} for w, e in ((1.0, 4.6e-4), (2.0, 4.5e-4), (0.5, 2e-3))]
        self.assertEqual(peers.extrapolated(rows, 1e-4), (None, None))
        rows[1]["max_hand_error_m"] = 2.3e-4  # a factor 2: an order, followed for a decade
        self.assertIsNotNone(peers.extrapolated(rows, 1e-4)[0])

    def test_best_series_and_diverged_rows_skipped(self):
        rows = [
            {"series": "a", "wall_s": 0.01, "max_hand_error_m": 1e-7, "status": "diverged"},
            {"series": "a", "wall_s": 0.1, "max_hand_error_m": 1e-7, "status": "ok"},
            {"series": "b", "wall_s": 0.05, "max_hand_error_m": 1e-7, "status": "ok"},
        ]
        self.assertEqual(peers.best_at(rows, 1e-6), (0.05, "b"))


URDF_ONE_LINK = """<robot name="one">
  <link name="base"/>
  <link name="l1"><inertial><origin xyz="0.5 0 0"/><mass value="2"/>
    <inertia ixx="0.01" iyy="0.2" izz="0.2" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>"""


def one_link_dump(mu):
    return {
        "joint_names": ["j1"], "gravity": [0, 0, -9.81],
        "drives": {"km": [0.6], "r": [1.1], "l": [0.0017], "jm": [0.0015], "dm": [0.03], "d": [0.5]},
        "gains": {"kp": [500.0], "kd": [20.0]},
        "hand": {"joint": "j1", "point_in_body": [1.0, 0, 0]},
        "q0": [0.0], "qd0": [0.0], "q_des0": [0.0],
        "contacts": [{"name": "tip", "joint": "j1", "point_in_body": [1.0, 0, 0], "normal": [0.0, 0.0, 1.0], "offset": 0.0,
                      "law": {"model": "unilateral", "restitution": 0.0, "friction": mu}}],
    }


class ContactModel(unittest.TestCase):
    def test_sphere_over_the_lowered_table_touches_where_the_point_reaches_the_plane(self):
        """The MJCF of a contact scene: the point (the sphere's centre) 0.3 m up on a 1 m link
        pivoting about y. MuJoCo finds no contact while the point is above z = 0 and one contact,
        with the scene's μ, once it is below, its distance equal to the point's height (1e-12 m)."""
        try:
            import mujoco
        except ImportError:
            self.skipTest("mujoco is not installed (bench/peers/requirements.txt)")
        import tempfile
        from pathlib import Path

        with tempfile.TemporaryDirectory() as d:
            urdf = Path(d) / "one.urdf"
            urdf.write_text(URDF_ONE_LINK)
            for name, v in peers.MJ_CONTACT_VARIANTS.items():
                m = mujoco.MjModel.from_xml_string(peers.mjcf(urdf, one_link_dump(0.5), "inductive", v))
                data = mujoco.MjData(m)
                for z in (1e-4, 1e-6, -1e-6, -1e-4):
                    # the tip's height 0.3 - sin(q) (rotation about +y takes +x to -z)
                    data.qpos[0] = math.asin(0.3 - z)
                    mujoco.mj_forward(m, data)
                    if z > 0:
                        self.assertEqual(data.ncon, 0, (name, z))
                    else:
                        self.assertEqual(data.ncon, 1, (name, z))
                        self.assertAlmostEqual(float(data.contact[0].dist), z, delta=1e-12)
                        self.assertEqual(float(data.contact[0].friction[0]), 0.5)
                        self.assertEqual(int(data.contact[0].dim), 3)

    def test_tracking_input_reproduces_eq_27(self):
        """MuJoCo's position input u = q_d + (k_d / k_p) q̇_d with v = k_p (u − q) − k_d q̇ is the
        paper's v = k_p (q_d − q) + k_d (q̇_d − q̇) (eq 27) for any state, to roundoff."""
        rng = np.random.default_rng(3)
        kp, kd = rng.uniform(10, 1000, 10), rng.uniform(1, 50, 10)
        qd_, qdd_, q, qdot = (rng.uniform(-2, 2, 10) for _ in range(4))
        u = qd_ + (kd / kp) * qdd_
        self.assertLess(np.abs((kp * (u - q) - kd * qdot) - (kp * (qd_ - q) + kd * (qdd_ - qdot))).max(), 1e-12)


if __name__ == "__main__":
    unittest.main()
