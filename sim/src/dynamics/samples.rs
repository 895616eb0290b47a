//! Models built in code for tests and benchmarks (pinocchio's `buildModels`): random chains
//! and trees with random axes, placements and physically valid inertias, reproducible from a
//! seed with a small SplitMix64 generator (Steele, Lea and Flood 2014) so that `sim` needs no
//! RNG dependency.

use nalgebra::{Isometry3, Matrix3, Translation3, Unit, UnitQuaternion, Vector3};

use super::model::{Body, Frame, JointKind, Model, UrdfJoint};
use super::spatial::Inertia;

/// SplitMix64: a tiny, well-mixed, reproducible generator.
#[derive(Clone, Debug)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }
    pub fn unit_vector(&mut self) -> Vector3<f64> {
        loop {
            let v = Vector3::new(self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0));
            let n = v.norm();
            if n > 0.1 && n <= 1.0 {
                return v / n;
            }
        }
    }
    pub fn vector(&mut self, n: usize, lo: f64, hi: f64) -> Vec<f64> {
        (0..n).map(|_| self.range(lo, hi)).collect()
    }
}

fn random_inertia(rng: &mut SplitMix64) -> Inertia {
    // a solid box of random sides, rotated and offset: always physically valid
    let mass = rng.range(0.05, 2.0);
    let (a, b, c) = (rng.range(0.01, 0.3), rng.range(0.01, 0.3), rng.range(0.01, 0.3));
    let diag = Matrix3::from_diagonal(&Vector3::new(b * b + c * c, a * a + c * c, a * a + b * b)) * (mass / 12.0);
    let r = UnitQuaternion::from_scaled_axis(rng.unit_vector() * rng.range(0.0, 3.0)).to_rotation_matrix();
    let com = Vector3::new(rng.range(-0.1, 0.1), rng.range(-0.1, 0.1), rng.range(0.0, 0.3));
    Inertia::from_com(mass, com, r * diag * r.transpose())
}

/// A random kinematic tree of `n` joints: body i hangs from a random earlier body (or the
/// root) when `branching`, else from body i − 1 (a chain). With `prismatic`, each joint is
/// prismatic with probability 1/3 (drawn after everything else, so that the revolute models
/// of a seed stay the same), else revolute.
fn random_tree(n: usize, seed: u64, branching: bool, prismatic: bool) -> Model {
    let mut rng = SplitMix64(seed);
    let mut bodies = Vec::with_capacity(n);
    let mut frames = vec![Frame { name: "base".into(), body: None, x_body_frame: Isometry3::identity() }];
    let mut urdf_joints = Vec::with_capacity(n);
    for i in 0..n {
        let parent = if i == 0 {
            None
        } else if branching {
            // 0 = the root, k = body k - 1
            let k = (rng.next_u64() % (i as u64 + 1)) as usize;
            k.checked_sub(1)
        } else {
            Some(i - 1)
        };
        let x = Isometry3::from_parts(
            Translation3::new(rng.range(-0.2, 0.2), rng.range(-0.2, 0.2), rng.range(0.05, 0.4)),
            UnitQuaternion::from_scaled_axis(rng.unit_vector() * rng.range(0.0, 3.0)),
        );
        let link = format!("link{}", i + 1);
        let joint = format!("joint{}", i + 1);
        urdf_joints.push(UrdfJoint {
            name: joint.clone(),
            parent_link: parent.map_or("base".to_string(), |p| format!("link{}", p + 1)),
            child_link: link.clone(),
            origin: x,
            dof: Some(i),
        });
        frames.push(Frame { name: link.clone(), body: Some(i), x_body_frame: Isometry3::identity() });
        bodies.push(Body {
            link,
            joint,
            kind: JointKind::Revolute,
            parent,
            x_parent_joint: x,
            axis: Unit::new_normalize(rng.unit_vector()),
            inertia: random_inertia(&mut rng),
            limits: Default::default(),
        });
    }
    if prismatic {
        let mut kinds = SplitMix64(seed ^ 0x5052_4953_4D41_5449);
        for b in &mut bodies {
            if kinds.next_u64() % 3 == 0 {
                b.kind = JointKind::Prismatic;
            }
        }
    }
    Model {
        name: format!("random_{}{}_{}", if prismatic { "mixed_" } else { "" }, if branching { "tree" } else { "chain" }, n),
        root_link: "base".into(),
        nv: n,
        bodies,
        frames,
        urdf_joints,
        gravity: Vector3::new(0.0, 0.0, -9.81),
        locked: Vec::new(),
        mimics: Vec::new(),
        repaired_inertias: Vec::new(),
    }
}

/// A random serial chain of `n` revolute joints.
pub fn random_chain(n: usize, seed: u64) -> Model {
    random_tree(n, seed, false, false)
}

/// A random serial chain of `n` joints, about a third of them prismatic.
pub fn random_mixed_chain(n: usize, seed: u64) -> Model {
    random_tree(n, seed, false, true)
}

/// A random branching tree of `n` joints, about a third of them prismatic.
pub fn random_mixed_tree(n: usize, seed: u64) -> Model {
    random_tree(n, seed, true, true)
}

/// A random branching tree of `n` revolute joints.
pub fn random_branching_tree(n: usize, seed: u64) -> Model {
    random_tree(n, seed, true, false)
}
