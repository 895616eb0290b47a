//! Rigid transforms for placing geometry: a translation and a unit quaternion `[x, y, z, w]`
//! (Hamilton convention, the order of `foxglove.Quaternion` and of Rerun's `RotationQuat`).
//!
//! `a.compose(b)` is `a ∘ b` (apply `b`, then `a`): with `x_world_parent` and `x_parent_child`
//! from `/tf`, `x_world_parent.compose(x_parent_child)` is `x_world_child`. URDF `rpy` is fixed-axis
//! roll-pitch-yaw, `R = Rz(yaw) Ry(pitch) Rx(roll)` (<http://wiki.ros.org/urdf/XML/joint>).

/// A rigid transform: rotate by `rotation`, then translate by `translation` (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    pub translation: [f64; 3],
    pub rotation: [f64; 4],
}

impl Pose {
    pub const IDENTITY: Pose = Pose { translation: [0.0; 3], rotation: [0.0, 0.0, 0.0, 1.0] };

    /// `self ∘ other`.
    pub fn compose(&self, other: &Pose) -> Pose {
        let t = self.apply(other.translation);
        Pose { translation: t, rotation: quat_mul(self.rotation, other.rotation) }
    }

    /// The point `p` (in this pose's child frame) in its parent frame.
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let r = rotate(self.rotation, p);
        [r[0] + self.translation[0], r[1] + self.translation[1], r[2] + self.translation[2]]
    }
}

/// Hamilton product `a b`.
pub fn quat_mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    let [ax, ay, az, aw] = a;
    let [bx, by, bz, bw] = b;
    [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]
}

/// `q p q*` for a unit quaternion `q`.
pub fn rotate(q: [f64; 4], p: [f64; 3]) -> [f64; 3] {
    let [x, y, z, w] = q;
    // t = 2 (q_v × p); p' = p + w t + q_v × t
    let t = [2.0 * (y * p[2] - z * p[1]), 2.0 * (z * p[0] - x * p[2]), 2.0 * (x * p[1] - y * p[0])];
    [
        p[0] + w * t[0] + (y * t[2] - z * t[1]),
        p[1] + w * t[1] + (z * t[0] - x * t[2]),
        p[2] + w * t[2] + (x * t[1] - y * t[0]),
    ]
}

/// The quaternion of URDF `rpy` (fixed axes: `Rz(yaw) Ry(pitch) Rx(roll)`).
pub fn quat_from_rpy([roll, pitch, yaw]: [f64; 3]) -> [f64; 4] {
    let axis = |i: usize, a: f64| {
        let mut q = [0.0, 0.0, 0.0, (a / 2.0).cos()];
        q[i] = (a / 2.0).sin();
        q
    };
    quat_mul(axis(2, yaw), quat_mul(axis(1, pitch), axis(0, roll)))
}

/// The shortest rotation taking +z to the unit vector `n`.
pub fn quat_z_to(n: [f64; 3]) -> [f64; 4] {
    let (x, y, z) = (n[0], n[1], n[2]);
    if z < -1.0 + 1e-12 {
        return [1.0, 0.0, 0.0, 0.0];
    }
    // q = (z × n, 1 + z · n), normalised; z × n = (-y, x, 0)
    let q = [-y, x, 0.0, 1.0 + z];
    let norm = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    q.map(|c| c / norm)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12)
    }

    #[test]
    fn composition_rotates_then_translates() {
        // 90° about z, then 1 m along x
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let a = Pose { translation: [1.0, 0.0, 0.0], rotation: [0.0, 0.0, s, s] };
        assert!(close(a.apply([1.0, 0.0, 0.0]), [1.0, 1.0, 0.0]));
        let b = Pose { translation: [0.0, 2.0, 0.0], rotation: [0.0, 0.0, 0.0, 1.0] };
        assert!(close(a.compose(&b).translation, [-1.0, 0.0, 0.0]));
        // rpy: yaw 90° is the same rotation
        let q = quat_from_rpy([0.0, 0.0, std::f64::consts::FRAC_PI_2]);
        assert!(close(rotate(q, [1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]));
        // roll then yaw (fixed axes): y -> z (roll 90°) -> stays z (yaw)
        let q = quat_from_rpy([std::f64::consts::FRAC_PI_2, 0.0, std::f64::consts::FRAC_PI_2]);
        assert!(close(rotate(q, [0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]));
        assert!(close(rotate(quat_z_to([1.0, 0.0, 0.0]), [0.0, 0.0, 1.0]), [1.0, 0.0, 0.0]));
        assert!(close(rotate(quat_z_to([0.0, 0.0, -1.0]), [0.0, 0.0, 1.0]), [0.0, 0.0, -1.0]));
    }
}
