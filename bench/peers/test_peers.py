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

    def test_best_series_and_diverged_rows_skipped(self):
        rows = [
            {"series": "a", "wall_s": 0.01, "max_hand_error_m": 1e-7, "status": "diverged"},
            {"series": "a", "wall_s": 0.1, "max_hand_error_m": 1e-7, "status": "ok"},
            {"series": "b", "wall_s": 0.05, "max_hand_error_m": 1e-7, "status": "ok"},
        ]
        self.assertEqual(peers.best_at(rows, 1e-6), (0.05, "b"))


if __name__ == "__main__":
    unittest.main()
