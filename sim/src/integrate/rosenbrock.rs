//! ROS34PW2: adaptive Rosenbrock-W method of order 3(2) for stiff systems, with a reusable
//! Jacobian and cubic Hermite dense output.
//!
//! References (HNW II = Hairer & Wanner, *Solving Ordinary Differential Equations II*, 2nd ed.,
//! Springer 1996):
//! - method: J. Rang & L. Angermann, "New Rosenbrock W-methods of order 3 for partial
//!   differential algebraic equations of index 1", BIT 45 (2005) 761–787, method ROS34PW2:
//!   4 stages, order 3 with an embedded order-2 solution, L-stable (`R(∞) = 0`), stiffly
//!   accurate, and a *W-method*: the order conditions hold for any matrix `W` in place of the
//!   Jacobian `J`, so a lagged or approximate Jacobian costs stability margin, not order.
//!   Coefficients (`gamma`, `alpha_ij`, `gamma_ij`, `b`, `b_hat`) as printed in the paper to 17
//!   digits (the same values are in PETSc's `TSROSWRA34PW2` and MATLODE); the tests check the
//!   W-method order conditions to 1e-14 and the observed orders.
//! - formulation: one step from `(t, y)` with step `h` is (HNW II §IV.7, (7.4) with the
//!   autonomisation `t' = 1`, whose Jacobian row for `t` is zero):
//!   `(I - h gamma J) k_i = h f(t + alpha_i h, y + sum_j alpha_ij k_j) +
//!   h J sum_j gamma_ij k_j + gamma_i h^2 f_t`, `y_new = y + sum b_i k_i`, with `J ≈ ∂f/∂y`,
//!   `f_t ≈ ∂f/∂t`, `alpha_i = sum_j alpha_ij`, `gamma_i = sum_{j<=i} gamma_ij`. It is
//!   computed in the transformed variables `u_i = sum_{j<=i} gamma_ij k_j` of HNW II (7.25),
//!   which need no product with `J`: `(I/(h gamma) - J) u_i = f(t + alpha_i h, y +
//!   sum_j a_ij u_j) + sum_j (c_ij / h) u_j + gamma_i h f_t`, `y_new = y + sum_j m_j u_j`,
//!   with `(a_ij) = (alpha_ij) Gamma^-1`, `(c_ij) = diag(1/gamma) - Gamma^-1`,
//!   `m = b Gamma^-1` computed here from the paper's coefficients. One LU of
//!   `I/(h gamma) - J` per new step size or Jacobian (in-place, partial pivoting, `lu.rs`);
//!   4 solves and 3 new evaluations of `f` per attempt, 1 more (`f` at the new point, the
//!   next first stage) per accepted step.
//! - error estimate and step-size control: `err = ||y_new - y_hat||` in the RMS norm of
//!   HNW I §II.4 with `atol + rtol max(|y|, |y_new|)`; `h_new = h min(fac_max, max(fac_min,
//!   safety err^(-1/3)))` (the embedded solution has order 2), as in Hairer's `ros4.f`; after a
//!   rejection the next accepted step may not grow; optionally Gustafsson's predictive
//!   controller after accepted steps ([`Rosenbrock::with_step_size_control`]; HNW II §IV.8
//!   (8.21), `adaptive.rs`). After an event's restart the first step is the last accepted one
//!   (`adaptive.rs`, as RODAS).
//! - Jacobian reuse (the W property): `J` is evaluated at the start of a step and kept for
//!   `jacobian_reuse` accepted steps; a rejection with a stale `J` triggers a refresh. `f_t`
//!   (one column of the autonomised Jacobian, cheap) is evaluated at the start of every step:
//!   a stale `f_t` of a stiff forcing (`-k sin t` in Prothero–Robinson) is off by `O(k h)`
//!   (measured on the stiff Kepler test problem at reuse 5: 507 tol with `f_t` reused with
//!   `J`, 209 tol refreshed, 213 tol with a fresh `J` every step). It comes from
//!   [`OdeJacobian::time_derivative`] or, if the system does not give it, a forward
//!   difference in `t` with increment `sqrt(eps max(1e-5, |t|))` (Hairer's `rodas.f`; one
//!   evaluation of `rhs`), falling back to a backward difference, then to 0, if the probe is
//!   not finite.
//! - singular matrix: as in `rodas.f`, a singular `I/(h gamma) - J` halves the step (counted as
//!   a rejection) up to 5 times in a row, then [`IntegrateError::SingularMatrix`].
//! - dense output: the cubic Hermite interpolant through `(y, f)` at both ends of the step
//!   (HNW I §II.6), exact at the ends; `f(t_new, y_new)` is the next step's first stage, so it
//!   costs no extra evaluation. Its local error is `O(h^4)` whatever Jacobian was used. (A
//!   stage-based cubic `y_prev + sum b_i(theta) k_i` satisfying the order-2 W conditions was
//!   tried: same error on the non-stiff problems, 2x larger on Prothero–Robinson with
//!   `lambda = -1e4`; Hermite's slope error `lambda x (global error)` on stiff components stays
//!   small because that global error is `O(h^2 / |lambda|)` there.)
//!
//! Other behaviour as in [`super::DormandPrince45`]: a non-finite stage shrinks `h` by
//! `fac_min` and is reported only if the step size collapses; steps shortened to land on
//! `t_stop` do not reduce the next step; `max_steps` counts attempts.

use self::tableau::{Tableau, GAMMA};
use super::adaptive::{self, initial_step, Adaptive, Attempt, Core, Failure};
use super::control::{Controller, StepSizeControl};
use super::lu::{lu_factor_within, lu_solve, LuStop};
use super::{
    dense_output, eval, eval_finite, first_non_finite, hermite, IntegrateError, OdeJacobian,
    Phase, RestartStart, SettingsError, Stats, StepControl, Stepper, Watch,
};

mod tableau;

/// The step-size controller of Hairer's `ros4.f` (SAFE = 0.9, FAC1 = 0.2, FAC2 = 6):
/// `h_new / h` in `[0.2, 6]`.
const CONTROLLER: Controller = Controller {
    safety: 0.9,
    fac_min: 0.2,
    fac_max: 6.0,
};

/// Adaptive ROS34PW2 Rosenbrock-W stepper (see the module docs).
#[derive(Clone, Debug)]
pub struct Rosenbrock {
    dim: usize,
    /// Accepted steps between Jacobian evaluations, >= 1.
    jacobian_reuse: usize,
    /// Time, last step, step-size control and statistics.
    core: Core,
    tab: Tableau,
    /// Current state, `f0 = f(t, y)`.
    y: Vec<f64>,
    f0: Vec<f64>,
    /// `y`, `f` at the start of the last accepted step (the Hermite data at the left end).
    y_prev: Vec<f64>,
    f_prev: Vec<f64>,
    /// Jacobian (row-major) and `f_t`; `jac_valid`: evaluated since `init`; `jac_fresh`:
    /// evaluated at the current `(t, y)`; accepted steps since the evaluation; `max |J_ij|`.
    jac: Vec<f64>,
    dfdt: Vec<f64>,
    jac_valid: bool,
    jac_fresh: bool,
    /// `f_t` was evaluated at the current `(t, y)`.
    dfdt_fresh: bool,
    steps_since_jac: usize,
    jac_max: f64,
    /// LU of `I/(h gamma) - J` and the `h` it was formed for (NaN: none).
    lu: Vec<f64>,
    piv: Vec<usize>,
    lu_h: f64,
    /// Transformed stages, stage argument, stage right-hand side, trial solution, f at it.
    u: [Vec<f64>; 4],
    y_stage: Vec<f64>,
    f_stage: Vec<f64>,
    y_new: Vec<f64>,
    f_new: Vec<f64>,
    /// The deadline the factorisation looks at.
    watch: Watch,
}

impl Rosenbrock {
    /// A stepper for systems of dimension `dim`, with a fresh Jacobian every step (see
    /// [`Rosenbrock::with_jacobian_reuse`]); all buffers (two `dim x dim` matrices) are
    /// allocated here.
    ///
    /// # Panics
    /// If `control.validate()` fails; use [`Rosenbrock::try_new`] for user input.
    pub fn new(dim: usize, control: StepControl) -> Self {
        match Self::try_new(dim, control) {
            Ok(s) => s,
            Err(e) => panic!("Rosenbrock::new: {e}"),
        }
    }

    /// Like [`Rosenbrock::new`], returning the settings error instead of panicking.
    ///
    /// # Errors
    /// The first out-of-range field of `control` (see [`StepControl::validate`]).
    pub fn try_new(dim: usize, control: StepControl) -> Result<Self, SettingsError> {
        control.validate()?;
        let z = || vec![0.0; dim];
        Ok(Self {
            dim,
            jacobian_reuse: 1,
            core: Core::new(control, CONTROLLER),
            tab: Tableau::new(),
            y: z(),
            f0: z(),
            y_prev: z(),
            f_prev: z(),
            jac: vec![0.0; dim * dim],
            dfdt: z(),
            jac_valid: false,
            jac_fresh: false,
            dfdt_fresh: false,
            steps_since_jac: 0,
            jac_max: 0.0,
            lu: vec![0.0; dim * dim],
            piv: vec![0; dim],
            lu_h: f64::NAN,
            u: [z(), z(), z(), z()],
            y_stage: z(),
            f_stage: z(),
            y_new: z(),
            f_new: z(),
            watch: Watch::default(),
        })
    }

    /// The same stepper choosing the step after an accepted one by `control` (module docs;
    /// default [`StepSizeControl::Elementary`]).
    pub fn with_step_size_control(mut self, control: StepSizeControl) -> Self {
        self.core.step_size_control = control;
        self
    }

    /// Keeps each Jacobian for `k` accepted steps (`k >= 1`; the default, 1, evaluates a
    /// fresh `J` every step). The Jacobian is also refreshed after a rejection if it was not
    /// evaluated at the current point. Fewer Jacobians cost stability margin, not order (the
    /// W property, module docs).
    ///
    /// # Panics
    /// If `k == 0`; use [`Rosenbrock::try_with_jacobian_reuse`] for user input.
    pub fn with_jacobian_reuse(self, k: usize) -> Self {
        match self.try_with_jacobian_reuse(k) {
            Ok(s) => s,
            Err(e) => panic!("Rosenbrock::with_jacobian_reuse: {e}"),
        }
    }

    /// Like [`Rosenbrock::with_jacobian_reuse`], returning the settings error instead of
    /// panicking.
    ///
    /// # Errors
    /// `k == 0` (`settings = "Rosenbrock"`, `field = "jacobian_reuse"`).
    pub fn try_with_jacobian_reuse(mut self, k: usize) -> Result<Self, SettingsError> {
        if k == 0 {
            return Err(SettingsError {
                settings: "Rosenbrock",
                field: "jacobian_reuse",
                value: 0.0,
                requirement: ">= 1",
            });
        }
        self.jacobian_reuse = k;
        Ok(self)
    }

    /// Accepted steps between Jacobian evaluations (see [`Rosenbrock::with_jacobian_reuse`]).
    pub fn jacobian_reuse(&self) -> usize {
        self.jacobian_reuse
    }

    adaptive_accessors!();

    /// Cubic Hermite interpolation on `[t_prev, t]`. Outside that interval it extrapolates the
    /// same cubic.
    pub fn interpolate(&self, t_query: f64, out: &mut [f64]) {
        let Core {
            t_prev,
            t,
            h_last: h,
            ..
        } = self.core;
        let (y_prev, y) = (&self.y_prev, &self.y);
        dense_output(
            "Rosenbrock",
            t_query,
            out,
            t_prev,
            t,
            h,
            y_prev,
            y,
            |th, out| hermite(th, h, y_prev, &self.f_prev, y, |i| self.f0[i], out),
        );
    }

    /// Evaluates `J` at the current point. A non-finite entry is an error: shrinking the step
    /// cannot change a Jacobian taken at an accepted state.
    fn evaluate_jacobian<S: OdeJacobian>(
        &mut self,
        sys: &mut S,
    ) -> Result<(), IntegrateError<S::Error>> {
        let (t, n) = (self.core.t, self.dim);
        self.core.stats.jacobian_evals += 1;
        sys.jacobian(t, &self.y, &self.f0, &mut self.jac)
            .map_err(IntegrateError::Rhs)?;
        if let Some(k) = first_non_finite(&self.jac) {
            return Err(IntegrateError::NonFiniteState {
                t,
                index: k / n.max(1),
            });
        }
        self.jac_max = self.jac.iter().fold(0.0, |m, v| m.max(v.abs()));
        self.jac_valid = true;
        self.jac_fresh = true;
        self.steps_since_jac = 0;
        self.lu_h = f64::NAN;
        Ok(())
    }

    /// Evaluates `f_t` at the current point ([`time_derivative`]).
    fn evaluate_dfdt<S: OdeJacobian>(
        &mut self,
        sys: &mut S,
    ) -> Result<(), IntegrateError<S::Error>> {
        time_derivative(&mut self.core.stats, sys, self.core.t, &self.y, &self.f0, &mut self.dfdt, &mut self.f_stage)?;
        self.dfdt_fresh = true;
        Ok(())
    }

    /// LU of `I/(h gamma) - J`; `Ok(false)` if singular, [`IntegrateError::OutOfTime`] past
    /// the deadline.
    fn factor<E>(&mut self, h: f64) -> Result<bool, IntegrateError<E>> {
        let n = self.dim;
        let d = 1.0 / (h * GAMMA);
        for (w, j) in self.lu.iter_mut().zip(&self.jac) {
            *w = -j;
        }
        for i in 0..n {
            self.lu[i * n + i] += d;
        }
        self.core.stats.lu_decompositions += 1;
        let result = lu_factor_within(&mut self.lu, n, &mut self.piv, d + self.jac_max, || self.watch.out_of_time());
        self.lu_h = if result.is_ok() { h } else { f64::NAN };
        match result {
            Ok(()) => Ok(true),
            Err(LuStop::Singular(_)) => Ok(false),
            Err(LuStop::OutOfTime(k)) => {
                Err(IntegrateError::OutOfTime { t: self.core.t, during: Phase::Factoring { column: k + 1, columns: n } })
            }
        }
    }

}

impl<S: OdeJacobian> Adaptive<S> for Rosenbrock {
    const NAME: &'static str = "Rosenbrock";

    fn core(&mut self) -> &mut Core {
        &mut self.core
    }

    fn starting_step(&mut self, sys: &mut S) -> Result<f64, IntegrateError<S::Error>> {
        let core = &mut self.core;
        initial_step(
            sys,
            &mut core.stats,
            core.t,
            &self.y,
            &self.f0,
            &mut self.y_stage,
            &mut self.f_stage,
            &core.control,
            &core.measured,
            3,
        )
    }

    fn attempt(
        &mut self,
        sys: &mut S,
        h: f64,
        t_new: f64,
        h_proposed: f64,
    ) -> Result<Attempt, IntegrateError<S::Error>> {
        let need_jac = !self.jac_valid
            || self.steps_since_jac >= self.jacobian_reuse
            || (self.core.rejected_last && !self.jac_fresh);
        if need_jac {
            self.evaluate_jacobian(sys)?;
        }
        if !self.dfdt_fresh {
            self.evaluate_dfdt(sys)?;
        }
        if self.lu_h != h && !self.factor(h)? {
            return self.core.reject_singular(h);
        }
        self.core.singular_run = 0;
        let (t, n, tab) = (self.core.t, self.dim, self.tab);

        for s in 0..4 {
            // stage argument and f at it (stage 0: f0)
            let ts = if s == 3 { t_new } else { t + tab.alpha[s] * h };
            if s > 0 {
                stage_argument(&self.y, &self.u[..s], &tab.a[s], &mut self.y_stage);
                if let Some(i) = eval(
                    &mut self.core.stats,
                    sys,
                    ts,
                    &self.y_stage,
                    &mut self.f_stage,
                )? {
                    return Ok(self.core.reject_non_finite(h, ts, i));
                }
            } else {
                self.f_stage.copy_from_slice(&self.f0);
            }
            let (done, rest) = self.u.split_at_mut(s);
            let us = &mut rest[0];
            stage_rhs(&self.f_stage, &self.dfdt, h * tab.gamma[s], done, &tab.c[s], h, us);
            lu_solve(&self.lu, n, &self.piv, us);
            if let Some(i) = first_non_finite(us) {
                return Ok(self.core.reject_non_finite(h, ts, i));
            }
        }

        // solution and error estimate (the error vector goes to y_stage)
        for i in 0..n {
            let (mut yn, mut e) = (self.y[i], 0.0);
            for j in 0..4 {
                yn += tab.m[j] * self.u[j][i];
                e += tab.e[j] * self.u[j][i];
            }
            self.y_new[i] = yn;
            self.y_stage[i] = e;
        }
        let err = self.core.error_norm(&self.y_stage, &self.y, &self.y_new);
        let passed = err <= 1.0;
        if !passed {
            return Ok(self.core.reject(h * CONTROLLER.factor(err, 1.0 / 3.0).min(1.0), Failure::None));
        }
        if let Some(i) = first_non_finite(&self.y_new) {
            return Ok(self.core.reject_non_finite(h, t_new, i));
        }
        if let Some(i) = eval(
            &mut self.core.stats,
            sys,
            t_new,
            &self.y_new,
            &mut self.f_new,
        )? {
            return Ok(self.core.reject_non_finite(h, t_new, i));
        }

        let fac = self.core.accepted_factor(err, 1.0 / 3.0, h);
        let h_new = self.core.limit_growth(h * fac, h, h_proposed);
        // commit: (y, f0) become the left Hermite data, the new point the current one
        std::mem::swap(&mut self.y_prev, &mut self.y);
        std::mem::swap(&mut self.y, &mut self.y_new);
        std::mem::swap(&mut self.f_prev, &mut self.f0);
        std::mem::swap(&mut self.f0, &mut self.f_new);
        self.core.accept(t_new, h, h_new);
        self.jac_fresh = false;
        self.dfdt_fresh = false;
        self.steps_since_jac += 1;
        Ok(Attempt::Accepted)
    }
}

impl<S: OdeJacobian> Stepper<S> for Rosenbrock {
    /// Evaluates `f(t0, y0)` once; the Jacobian is evaluated by the first step.
    fn init(&mut self, sys: &mut S, t0: f64, y0: &[f64]) -> Result<(), IntegrateError<S::Error>> {
        self.core.init("Rosenbrock", self.dim, &*sys, t0, y0)?;
        self.jac_valid = false;
        self.jac_fresh = false;
        self.dfdt_fresh = false;
        self.lu_h = f64::NAN;
        self.y.copy_from_slice(y0);
        self.y_prev.copy_from_slice(y0);
        eval_finite(&mut self.core.stats, sys, t0, y0, &mut self.f0)?;
        self.f_prev.copy_from_slice(&self.f0);
        self.core.initialized = true;
        Ok(())
    }

    /// `init`, keeping the last accepted step's size for [`Stepper::first_step_after_restart`]
    /// (`adaptive.rs`).
    fn restart(&mut self, sys: &mut S, t0: f64, y0: &[f64]) -> Result<(), IntegrateError<S::Error>> {
        adaptive::restart(self, sys, t0, y0)
    }

    /// The first step after an event: the last accepted step where every event function is
    /// armed, else the smaller of it and Hairer's starting step (`adaptive.rs`).
    fn first_step_after_restart(&mut self, sys: &mut S, start: RestartStart) -> Result<(), IntegrateError<S::Error>> {
        adaptive::first_step_after_restart(self, sys, start)
    }

    fn step(&mut self, sys: &mut S, t_stop: f64) -> Result<f64, IntegrateError<S::Error>> {
        adaptive::step(self, sys, t_stop)
    }

    forward_stepper_accessors!(Rosenbrock);

    fn set_watch(&mut self, watch: Watch) {
        self.watch = watch;
    }

    fn set_state(&mut self, sys: &mut S, y: &[f64]) -> Result<(), IntegrateError<S::Error>> {
        self.y.copy_from_slice(y);
        eval_finite(&mut self.core.stats, sys, self.core.t, y, &mut self.f0)
    }
}


/// The argument of stage s of a Rosenbrock method in the form of HNW II §IV.7 (eq 7.25, with
/// `u_j = γ k_j`): `y_s = y + Σ_{j<s} a_sj u_j`, `u` holding the stages done. Shared by
/// [`Rosenbrock`] and [`super::Rodas`].
pub(super) fn stage_argument(y: &[f64], u: &[Vec<f64>], a_row: &[f64], y_stage: &mut [f64]) {
    for i in 0..y.len() {
        let mut v = y[i];
        for (j, uj) in u.iter().enumerate() {
            v += a_row[j] * uj[i];
        }
        y_stage[i] = v;
    }
}

/// The right-hand side of stage s's linear system in the same form: `f(y_s) + h d_s f_t +
/// Σ_{j<s} (c_sj / h) u_j` into `us`, with `hd = h d_s` (ROS34PW2: `h γ_s`). Shared by
/// [`Rosenbrock`] and [`super::Rodas`].
pub(super) fn stage_rhs(f_stage: &[f64], dfdt: &[f64], hd: f64, done: &[Vec<f64>], c_row: &[f64], h: f64, us: &mut [f64]) {
    for i in 0..us.len() {
        let mut v = f_stage[i] + hd * dfdt[i];
        for (j, uj) in done.iter().enumerate() {
            v += c_row[j] / h * uj[i];
        }
        us[i] = v;
    }
}

/// `f_t = ∂f/∂t` at `(t, y)` into `dfdt` (`f0 = f(t, y)`, `scratch` of length `dim`): the
/// system's own ([`OdeJacobian::time_derivative`]), else a forward difference in `t` with
/// increment `sqrt(eps max(1e-5, |t|))` (Hairer's `rodas.f`), else a backward one, else 0 (any
/// value keeps a Rosenbrock-W method's order; the classical RODAS methods need it exact to
/// O(increment)). Shared by [`Rosenbrock`] and [`super::Rodas`].
pub(super) fn time_derivative<S: OdeJacobian>(
    stats: &mut Stats,
    sys: &mut S,
    t: f64,
    y: &[f64],
    f0: &[f64],
    dfdt: &mut [f64],
    scratch: &mut [f64],
) -> Result<(), IntegrateError<S::Error>> {
    if !sys.time_derivative(t, y, f0, dfdt).map_err(IntegrateError::Rhs)? {
        let delta = (f64::EPSILON * t.abs().max(1e-5)).sqrt();
        dfdt.fill(0.0);
        for d in [delta, -delta] {
            if eval(stats, sys, t + d, y, scratch)?.is_none() {
                let dt = (t + d) - t;
                for ((g, f), f0) in dfdt.iter_mut().zip(scratch.iter()).zip(f0) {
                    *g = (f - f0) / dt;
                }
                break;
            }
        }
    }
    if let Some(i) = first_non_finite(dfdt) {
        return Err(IntegrateError::NonFiniteState { t, index: i });
    }
    Ok(())
}

#[cfg(test)]
mod tests;
