//! A general inverse kinematics for any chain: damped least squares (Levenberg–Marquardt) on
//! the task Jacobian with a posture task in its null space (Wampler 1986; Nakamura & Hanafusa
//! 1986; Buss, "Introduction to inverse kinematics with Jacobian transpose, pseudoinverse and
//! damped least squares methods", 2004), and the joint-space trajectory that tracks a hand path.
//!
//! **Task.** Rows, world frame: the hand position error `e_p = r_d − p(q)` (3, m) with rows
//! `J_p` (columns `z_j × (p − o_j)`); optionally the orientation error `e_o = log(R_d R(q)ᵀ)`
//! (3, rad, a rotation vector) with rows `J_ω` (columns `z_j`); and for every kept contact
//! `e_c = d − n · p_c(q)` (1, m) with row `n · J_{p_c}`. Only the joints the IK moves (`active`)
//! have columns; the others stay at their posture angle.
//!
//! **Step.** With z the posture pull `q_post − q` on the free joints and
//! `A = J Jᵀ + λ² I`, `λ² = ½ |e|²` (the Levenberg–Marquardt damping of Sugihara, IEEE T-RO
//! 27(5), 2011, which vanishes at the solution so the last steps are Gauss–Newton),
//! `Δq = β z + Jᵀ A⁻¹ (e − β J z)`: at λ = 0, `J Δq = e` and the rest of Δq is the projection
//! of β z onto the null space of J. The posture gain β starts at 1 and is halved (down to
//! 1/64) whenever |e| grows (the null-space step ignores the task's curvature, and a far
//! posture can then undo the task's progress). A step is scaled to at most 0.3 rad per joint
//! (trust region). A
//! fixed point has e = 0 and `(I − J⁺J) z = 0`, the first-order conditions of
//! `min ½|q − q_post|²` subject to the task: the solution is a function of the target alone,
//! given the branch chosen by continuation.
//!
//! **Joint limits** (URDF `<limit>`, `model.bodies[j].limits.position`): a step that leaves
//! `[lo, hi]` is clamped there and that joint is frozen (its column dropped) for the rest of
//! that solve (an active-set method, Nocedal & Wright §16.5, in its simplest form).
//!
//! **Convergence.** `|e| ≤ 1e-12` (m, rad) and `|(I − J⁺J) z| ≤ 1e-10` rad, at most 200
//! iterations; a solve that ends with `|e| > 1e-10` fails with its residual.
//!
//! **Trajectory** ([`track`]). The path is solved on a uniform grid of step ≤ `grid_step`
//! (default 2 ms) over `[0, duration]` plus two knots beyond, by continuation (each solve starts
//! from the previous solution extrapolated linearly), and the knots are joined by a C² cubic
//! spline ([`CubicSpline::uniform_sampled`]) whose exact derivatives are q̇_d and q̈_d. The task
//! error of the spline at every interval's midpoint is measured and returned
//! ([`TrackStats::between_knots`]); an interpolation error of O(h⁴ q⁗) is ~1e-13 m at 2 ms on
//! the paper's circle.

use nalgebra::{DMatrix, DVector, UnitQuaternion, Vector3};

use super::path::CartesianPath;
use super::spline::CubicSpline;
use crate::dynamics::constraints::PointOnPlane;
use crate::dynamics::kinematics::{forward_kinematics, BodyPoint};
use crate::dynamics::{Data, Model};
use crate::dynamics::model::JointKind;

/// Converged task residual, m or rad.
pub const TASK_TOL: f64 = 1e-12;
/// Accepted task residual after the iteration limit, m or rad.
pub const TASK_FAIL: f64 = 1e-10;
/// Converged posture stationarity `|(I − J⁺J) z|`, rad.
pub const POSTURE_TOL: f64 = 1e-10;
/// Iteration limit per solve.
pub const MAX_ITERATIONS: usize = 200;
/// Largest joint change per iteration, rad.
pub const MAX_STEP: f64 = 0.3;
/// Default grid step of [`track`], s.
pub const DEFAULT_GRID_STEP: f64 = 2e-3;
/// Most knots of [`track`].
pub const MAX_KNOTS: usize = 1_000_000;

/// The IK's task and settings (read-only).
#[derive(Clone, Debug)]
pub struct GeneralIk {
    pub hand: BodyPoint,
    /// The hand frame's orientation in its body, and the desired world orientation.
    pub orientation: Option<(UnitQuaternion<f64>, UnitQuaternion<f64>)>,
    /// Contacts whose point must stay on their plane.
    pub contacts: Vec<PointOnPlane>,
    /// Joints the IK moves (nv).
    pub active: Vec<bool>,
    /// Posture q_post (nv), rad: the null-space target, and the angle of every inactive joint.
    pub posture: Vec<f64>,
}

/// What one solve did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveStats {
    pub iterations: usize,
    /// Final |e|, m or rad.
    pub residual: f64,
    /// Final |(I − J⁺J) z|, rad.
    pub stationarity: f64,
}

/// Scratch of [`GeneralIk::solve`] (sized once per IK).
pub struct IkScratch {
    data: Data,
    jac: DMatrix<f64>,
    e: DVector<f64>,
    frozen: Vec<bool>,
}

impl GeneralIk {
    /// Task rows.
    pub fn rows(&self) -> usize {
        3 + if self.orientation.is_some() { 3 } else { 0 } + self.contacts.len()
    }

    pub fn scratch(&self, model: &Model) -> IkScratch {
        IkScratch {
            data: Data::new(model),
            jac: DMatrix::zeros(self.rows(), model.nv),
            e: DVector::zeros(self.rows()),
            frozen: vec![false; model.nv],
        }
    }

    /// The task error e and Jacobian J at q (free columns only).
    fn task(&self, model: &Model, s: &mut IkScratch, q: &[f64], r_d: &Vector3<f64>) {
        forward_kinematics(model, &mut s.data, q);
        let data = &s.data;
        s.jac.fill(0.0);
        let p = self.hand.position(data);
        let ep = r_d - p;
        s.e.fixed_rows_mut::<3>(0).copy_from(&ep);
        let mut cur = self.hand.body;
        while let Some(j) = cur {
            let z = data.x_world_body[j].rotation * model.bodies[j].axis.into_inner();
            // a revolute joint turns the hand about z through its origin, a prismatic one
            // moves it along z without turning it (Siciliano et al., *Robotics*, eq 3.30)
            match model.bodies[j].kind {
                JointKind::Revolute => {
                    s.jac.fixed_view_mut::<3, 1>(0, j).copy_from(&z.cross(&(p - data.x_world_body[j].translation.vector)));
                    if self.orientation.is_some() {
                        s.jac.fixed_view_mut::<3, 1>(3, j).copy_from(&z);
                    }
                }
                JointKind::Prismatic => s.jac.fixed_view_mut::<3, 1>(0, j).copy_from(&z),
            }
            cur = model.bodies[j].parent;
        }
        let mut row = 3;
        if let Some((r_bf, r_d)) = &self.orientation {
            let r_w = match self.hand.body {
                Some(b) => data.x_world_body[b].rotation * r_bf,
                None => *r_bf,
            };
            s.e.fixed_rows_mut::<3>(3).copy_from(&(r_d * r_w.inverse()).scaled_axis());
            row = 6;
        }
        for c in &self.contacts {
            s.e[row] = -c.position(data);
            let mut r = s.jac.row_mut(row);
            c.point.jacobian_along(model, data, &c.normal_world, &mut r);
            row += 1;
        }
        for j in 0..model.nv {
            if !self.active[j] || s.frozen[j] {
                s.jac.column_mut(j).fill(0.0);
            }
        }
    }

    /// Solve for the hand at `r_d` (world, m) starting from `q` (nv), which is overwritten by
    /// the solution. `Err` carries the stats of a solve whose residual stayed above
    /// [`TASK_FAIL`].
    pub fn solve(&self, model: &Model, s: &mut IkScratch, r_d: &Vector3<f64>, q: &mut [f64]) -> Result<SolveStats, SolveStats> {
        let nv = model.nv;
        s.frozen.fill(false);
        for j in 0..nv {
            if !self.active[j] {
                q[j] = self.posture[j];
            } else if let Some((lo, hi)) = model.bodies[j].limits.position {
                q[j] = q[j].clamp(lo, hi);
            }
        }
        let m = self.rows();
        let mut stats = SolveStats { iterations: 0, residual: f64::INFINITY, stationarity: f64::INFINITY };
        let mut beta = 1.0;
        let mut last = f64::INFINITY;
        for it in 0..=MAX_ITERATIONS {
            // joints at a limit are free again each iteration and frozen only while the step
            // would push them out of their range (an active set, Nocedal & Wright §16.5), so a
            // joint clamped once by a long early step can come back
            s.frozen.fill(false);
            self.task(model, s, q, r_d);
            let enorm = s.e.norm();
            if enorm > last && enorm > TASK_TOL {
                beta = (beta * 0.5f64).max(1.0 / 64.0);
            }
            last = enorm;
            let mut dq;
            loop {
                let z = DVector::from_fn(nv, |j, _| if self.active[j] && !s.frozen[j] { beta * (self.posture[j] - q[j]) } else { 0.0 });
                let jt = s.jac.transpose();
                let mut a = &s.jac * &jt;
                for i in 0..m {
                    a[(i, i)] += 0.5 * enorm * enorm;
                }
                // A is singular only when J loses rank at the solution: regularise minimally
                let chol = match a.clone().cholesky() {
                    Some(c) => c,
                    None => {
                        for i in 0..m {
                            a[(i, i)] += 1e-12;
                        }
                        match a.cholesky() {
                            Some(c) => c,
                            None => return Err(SolveStats { iterations: it, residual: enorm, stationarity: f64::NAN }),
                        }
                    }
                };
                let jz = &s.jac * &z;
                let null_part = &z - &jt * chol.solve(&jz);
                stats = SolveStats { iterations: it, residual: enorm, stationarity: null_part.norm() / beta };
                dq = &z + &jt * chol.solve(&(&s.e - &jz));
                let mut again = false;
                for j in 0..nv {
                    if let (true, false, Some((lo, hi))) = (self.active[j], s.frozen[j], model.bodies[j].limits.position) {
                        if (q[j] >= hi && dq[j] > 0.0) || (q[j] <= lo && dq[j] < 0.0) {
                            s.frozen[j] = true;
                            s.jac.column_mut(j).fill(0.0);
                            again = true;
                        }
                    }
                }
                if !again {
                    break;
                }
            }
            if (enorm <= TASK_TOL && stats.stationarity <= POSTURE_TOL) || it == MAX_ITERATIONS {
                break;
            }
            let big = dq.amax();
            if big > MAX_STEP {
                dq *= MAX_STEP / big;
            }
            for j in 0..nv {
                q[j] += dq[j];
                if let (true, Some((lo, hi))) = (self.active[j], model.bodies[j].limits.position) {
                    q[j] = q[j].clamp(lo, hi);
                }
            }
        }
        if stats.residual > TASK_FAIL {
            Err(stats)
        } else {
            Ok(stats)
        }
    }

    /// The task error |e| at q, m or rad (no joint is frozen).
    pub fn residual(&self, model: &Model, s: &mut IkScratch, q: &[f64], r_d: &Vector3<f64>) -> f64 {
        s.frozen.fill(false);
        self.task(model, s, q, r_d);
        s.e.norm()
    }
}

/// How well a tracked trajectory does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrackStats {
    /// Knots and their spacing, s.
    pub knots: usize,
    pub step: f64,
    /// Largest task residual at a knot, m or rad.
    pub at_knots: f64,
    /// Largest task residual of the spline at the midpoints between knots, m or rad.
    pub between_knots: f64,
    /// Most iterations of one solve (the first solve, from the initial guess, included).
    pub max_iterations: usize,
}

/// Why a path cannot be tracked: the time and the solve's stats.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrackError {
    pub t: f64,
    pub stats: SolveStats,
}

/// Solve the IK along `path` on a grid over `[0, duration]` (step ≤ `grid_step`), starting
/// from `q_start`, and fit the C² spline q_d(t). See the module documentation.
pub fn track(
    ik: &GeneralIk,
    model: &Model,
    path: &CartesianPath,
    q_start: &[f64],
    duration: f64,
    grid_step: f64,
) -> Result<(CubicSpline, TrackStats), TrackError> {
    let nv = model.nv;
    let intervals = ((duration / grid_step).ceil() as usize).max(2);
    let h = duration / intervals as f64;
    let n = intervals + 3;
    let mut s = ik.scratch(model);
    let mut t_knots = Vec::with_capacity(n);
    let mut y = Vec::with_capacity(n * nv);
    let mut q = q_start.to_vec();
    let mut prev = q.clone();
    let mut stats = TrackStats { knots: n, step: h, at_knots: 0.0, between_knots: 0.0, max_iterations: 0 };
    for k in 0..n {
        let t = k as f64 * h;
        if k >= 2 {
            // predictor: linear extrapolation of the last two solutions
            for j in 0..nv {
                let next = 2.0 * q[j] - prev[j];
                prev[j] = q[j];
                q[j] = next;
            }
        } else {
            prev.copy_from_slice(&q);
        }
        let st = ik.solve(model, &mut s, &path.position(t), &mut q).map_err(|stats| TrackError { t, stats })?;
        stats.at_knots = stats.at_knots.max(st.residual);
        stats.max_iterations = stats.max_iterations.max(st.iterations);
        t_knots.push(t);
        y.extend_from_slice(&q);
    }
    let spline = CubicSpline::uniform_sampled(t_knots, y, nv).expect("a uniform grid of at least 5 knots");
    let (mut qm, mut qdm, mut qddm) = (vec![0.0; nv], vec![0.0; nv], vec![0.0; nv]);
    for k in 0..n - 1 {
        let t = (k as f64 + 0.5) * h;
        spline.eval(t, &mut qm, &mut qdm, &mut qddm);
        stats.between_knots = stats.between_knots.max(ik.residual(model, &mut s, &qm, &path.position(t)));
    }
    Ok((spline, stats))
}
