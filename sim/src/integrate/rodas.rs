//! RODAS5P (default) and RODAS4: adaptive Rosenbrock methods of order 5(4) and 4(3) for stiff
//! systems with the exact Jacobian, a dense output of order 4 (3), and linear algebra that
//! factors only the block of the state that feeds back.
//!
//! References (HNW II = Hairer & Wanner, *Solving Ordinary Differential Equations II*, 2nd ed.,
//! Springer 1996):
//! - RODAS5P: G. Steinebach, "Construction of Rosenbrock–Wanner method Rodas5P and numerical
//!   benchmarks within the Julia Differential Equations package", BIT Numer. Math. 63 (2023)
//!   27: 8 stages, order 5 with an embedded order-4 solution, L-stable, stiffly accurate, a
//!   dense output of order 4 (coefficients: `rodas/tableau.rs`).
//! - RODAS4: HNW II §VI.4 and Hairer's `rodas.f`: 6 stages, order 4(3), L-stable, stiffly
//!   accurate, dense output of order 3.
//! - formulation: a *classical* Rosenbrock method (HNW II §IV.7, (7.4)), not a W-method: its
//!   order needs `J = ∂f/∂y` and `f_t = ∂f/∂t` exact (up to the accuracy of a finite
//!   difference). In the transformed variables of HNW II (7.25), as in `rodas.f`:
//!   `(I/(h gamma) - J) u_i = f(t + c_i h, y + sum_j a_ij u_j) + sum_j (C_ij / h) u_j +
//!   d_i h f_t`, `y_new = y + sum_j m_j u_j` (stiffly accurate: `m` is the last stage's
//!   argument plus the last stage); the error estimate is the last stage `u_s`
//!   (`y_new - y_hat`, with `y_hat` the last stage's argument).
//! - dense output (as in OrdinaryDiffEq.jl's Rodas interpolants, Steinebach 2023 §4):
//!   `y(t + theta h) = (1 - theta) y + theta (y_new + (1 - theta) (w_1 + theta (w_2 +
//!   theta w_3)))` with `w_k = sum_j H_kj u_j` (RODAS4: `w_1`, `w_2` only).
//! - error norm and step-size control: the RMS norm of HNW I §II.4 with `atol + rtol max(|y|,
//!   |y_new|)` over the components the system measures ([`super::OdeSystem::error_measured`]); `h_new = h min(6, max(0.2, 0.9 err^(-1/(q+1))))` with `q` the embedded order
//!   (Hairer's `rodas.f`: SAFE = 0.9, FAC1 = 5, FAC2 = 1/6); after a rejection the next
//!   accepted step may not grow. Optionally ([`Rodas::with_step_size_control`], a scene's
//!   `step_size_control: "predictive"`), Gustafsson's predictive controller after accepted
//!   steps (HNW II §IV.8 (8.21), as `radau5.f`'s `IWORK(8) = 1`; [`super::adaptive::Core::accepted_factor`]).
//!   It is not the default: as the default it broke RODAS5P's tolerance proportionality with
//!   gear friction (error ∝ rtol^0.85, `convergence.rs`) and the restitution run's balance
//!   bound (1e-9 E) when measured in issue 24's first pass; the paper-unilateral scene opts in
//!   (BENCHMARKS.md, "Issue 24, sixth pass").
//!   Gustafsson's PI controller, HNW II §IV.2, β = 0.04 as `dopri5.f`, brought the
//!   paper-unilateral runs' rejected steps from 6–7 % to 4.1–4.5 % for 6–9 % more steps, but
//!   put RODAS5P's dense output on Prothero–Robinson at 114 tol (tol 1e-6; bound 100,
//!   `contract.rs`); not kept either, BENCHMARKS.md.)
//! - restart after an event ([`Stepper::restart`], then
//!   [`Stepper::first_step_after_restart`], shared with dopri45 and rosenbrock in
//!   `adaptive.rs`): the state, Jacobian and statistics
//!   restart as in `init`, but the first step is the last accepted step's size (at most
//!   `h_max`) when every event function is armed at the restart ([`RestartStart::Armed`]: a
//!   stick ↔ slip change, a lift-off, a touch-down whose functions the driver watches from
//!   their start values), and the smaller of that and Hairer's starting step (or `h_init`)
//!   when one is disarmed ([`RestartStart::Disarmed`]: a function left at 0, or on its firing side, and not
//!   watched, e.g. a ball leaving the table, is not tested in the first step, `events.rs`, so
//!   that step must be short enough not to jump over the function's next root: a bounce shorter
//!   than the step before it). Hairer's step alone ignores what the steps before the event
//!   learned about the solution's scale: on the elbow runs it was often far too large (56 of
//!   two-elbow-unilateral's rejections at its 16 restarts). Only for systems that allow it
//!   ([`super::HybridSystem::restart_keeps_step_size`]): over the arm's gear events either rule
//!   broke RODAS5P's error ∝ rtol, so there the driver calls `init`.
//! - Jacobian: [`OdeJacobian::exact_jacobian`]; if the system has none, forward differences
//!   (HNW II §IV.8, [`super::fd_jacobian_columns`], increment `sqrt(eps) max(|y_j|, floor)`
//!   with `floor = atol / rtol` within `[1e-5, 1]`, the scale below which the error norm
//!   treats a component as absolute, unless the system states its noise and scale,
//!   [`OdeJacobian::difference_increment`]) over the *coupled* columns only (`j < coupled_dim`), counted in `Stats::rhs_evals`;
//!   the trailing columns from [`OdeJacobian::exact_columns_start`] on exact where the system
//!   writes them ([`OdeJacobian::exact_columns`], right after the difference sweep over the
//!   leading ones; the arm's current columns, issue 24; the system's own evaluations for them,
//!   [`OdeJacobian::exact_columns_rhs_evals`], counted in `Stats::rhs_evals` too), else
//!   differenced too. `f_t`:
//!   [`OdeJacobian::exact_time_derivative`], else [`OdeJacobian::time_derivative`], else a forward difference in `t` as in
//!   [`super::Rosenbrock`]. Both are evaluated at the start of every step by default;
//!   `with_jacobian_reuse(k)` keeps `J` for `k` accepted steps (this loses the order, which
//!   the error control then pays for in step size; `f_t` stays fresh).
//! - structure: with `nc = ` [`OdeJacobian::coupled_dim`], the components `nc..n`
//!   (quadratures) do not enter `f`, so `J = [[J_cc, 0], [J_qc, 0]]` and `I/(h gamma) - J` is
//!   block lower triangular: only `I/(h gamma) - J_cc` (`nc x nc`) is factored (LU with
//!   partial pivoting, `lu.rs`, once per step and reused by every stage), and the quadrature
//!   part of each stage is the substitution `u_q = h gamma (r_q + J_qc u_c)`, the product only
//!   over the rows of `J_qc` that are not 0 (a separated candidate contact's losses are;
//!   whole-table has 21 such rows of 50). The columns `nc..n` of `J` are zeroed once and not
//!   scanned (the difference sweep writes the columns `0..nc` only).
//! - singular matrix, non-finite stages, `t_stop`, `max_steps`: as in [`super::Rosenbrock`].

use self::tableau::{Tableau, MAX_STAGES, RODAS4, RODAS5P};
use super::adaptive::{self, initial_step, Adaptive, Attempt, Core, Failure};
use super::control::{Controller, StepSizeControl};
use super::lu::{lu_factor_within, lu_solve, LuStop};
use super::rosenbrock::{stage_argument, stage_rhs};
use super::{
    dense_output, eval, eval_finite, first_non_finite, IntegrateError, OdeJacobian, Phase, SettingsError,
    RestartStart, Stats, StepControl, Stepper, Watch,
};

mod jacobian;
pub(crate) mod tableau;

/// The step-size controller of Hairer's `rodas.f` (SAFE = 0.9, FAC1 = 5, FAC2 = 1/6).
const CONTROLLER: Controller = Controller {
    safety: 0.9,
    fac_min: 0.2,
    fac_max: 6.0,
};

/// The increment floor of the finite-difference Jacobian: `atol / rtol` (the size below which
/// the error norm treats a component as absolute), within `[1e-5, 1]`.
fn fd_floor(c: &StepControl) -> f64 {
    (c.atol / c.rtol).clamp(1e-5, 1.0)
}

/// Which Rosenbrock tableau a [`Rodas`] stepper runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RodasMethod {
    /// Steinebach 2023: order 5(4), 8 stages, dense output of order 4.
    Rodas5P,
    /// Hairer & Wanner: order 4(3), 6 stages, dense output of order 3.
    Rodas4,
}

impl RodasMethod {
    fn tableau(self) -> &'static Tableau {
        match self {
            RodasMethod::Rodas5P => &RODAS5P,
            RodasMethod::Rodas4 => &RODAS4,
        }
    }

    /// The tableau's name (`"RODAS5P"`, `"RODAS4"`).
    pub fn name(self) -> &'static str {
        self.tableau().name
    }
}

/// Adaptive RODAS5P / RODAS4 stepper (see the module docs).
#[derive(Clone, Debug)]
pub struct Rodas {
    dim: usize,
    /// Components `0..nc` feed back (set from the system in `init`).
    nc: usize,
    jacobian_reuse: usize,
    core: Core,
    tab: &'static Tableau,
    /// Current state, `f0 = f(t, y)`; the state at the start of the last accepted step; the
    /// dense-output vectors `w_k` of that step.
    y: Vec<f64>,
    f0: Vec<f64>,
    y_prev: Vec<f64>,
    w: [Vec<f64>; 3],
    /// Jacobian (row-major `dim x dim`, columns `nc..` zero) and `f_t`; see `Rosenbrock`.
    jac: Vec<f64>,
    dfdt: Vec<f64>,
    jac_valid: bool,
    jac_fresh: bool,
    dfdt_fresh: bool,
    steps_since_jac: usize,
    jac_max: f64,
    /// Whether the columns `nc..dim` of `jac` are 0 (the difference path writes only the
    /// columns `0..nc`, every row, so they stay 0 from one Jacobian to the next).
    jac_tail_zero: bool,
    /// The quadrature rows `nc..dim` of `jac` with a non-zero entry (the others, e.g. a
    /// separated contact's losses, need no product in [`Rodas::solve`]), ascending.
    quad_rows: Vec<usize>,
    /// LU of `I/(h gamma) - J_cc` (`nc x nc`, row-major) and the `h` it was formed for.
    lu: Vec<f64>,
    piv: Vec<usize>,
    lu_h: f64,
    /// Stages, stage argument, stage right-hand side, trial solution, f at it.
    u: [Vec<f64>; MAX_STAGES],
    y_stage: Vec<f64>,
    f_stage: Vec<f64>,
    y_new: Vec<f64>,
    f_new: Vec<f64>,
    /// The deadline the difference Jacobian and the factorisation look at.
    watch: Watch,
}

impl Rodas {
    /// A RODAS5P stepper for systems of dimension `dim`, a fresh Jacobian every step; all
    /// buffers are allocated here.
    ///
    /// # Panics
    /// If `control.validate()` fails; use [`Rodas::try_new`] for user input.
    pub fn new(dim: usize, control: StepControl) -> Self {
        match Self::try_new(dim, control) {
            Ok(s) => s,
            Err(e) => panic!("Rodas::new: {e}"),
        }
    }

    /// Like [`Rodas::new`], returning the settings error instead of panicking.
    ///
    /// # Errors
    /// The first out-of-range field of `control` (see [`StepControl::validate`]).
    pub fn try_new(dim: usize, control: StepControl) -> Result<Self, SettingsError> {
        control.validate()?;
        let z = || vec![0.0; dim];
        Ok(Self {
            dim,
            nc: dim,
            jacobian_reuse: 1,
            core: Core::new(control, CONTROLLER),
            tab: &RODAS5P,
            y: z(),
            f0: z(),
            y_prev: z(),
            w: [z(), z(), z()],
            jac: vec![0.0; dim * dim],
            dfdt: z(),
            jac_valid: false,
            jac_fresh: false,
            dfdt_fresh: false,
            steps_since_jac: 0,
            jac_max: 0.0,
            jac_tail_zero: false,
            quad_rows: Vec::with_capacity(dim),
            lu: vec![0.0; dim * dim],
            piv: vec![0; dim],
            lu_h: f64::NAN,
            u: std::array::from_fn(|_| z()),
            y_stage: z(),
            f_stage: z(),
            y_new: z(),
            f_new: z(),
            watch: Watch::default(),
        })
    }

    /// The same stepper running `method`'s tableau.
    pub fn with_method(mut self, method: RodasMethod) -> Self {
        self.tab = method.tableau();
        self
    }

    /// The same stepper choosing the step after an accepted one by `control` (module docs;
    /// default [`StepSizeControl::Elementary`]).
    pub fn with_step_size_control(mut self, control: StepSizeControl) -> Self {
        self.core.step_size_control = control;
        self
    }

    /// Keeps each Jacobian for `k` accepted steps (see [`Rodas::try_with_jacobian_reuse`]).
    ///
    /// # Panics
    /// If `k == 0`; use [`Rodas::try_with_jacobian_reuse`] for user input.
    pub fn with_jacobian_reuse(self, k: usize) -> Self {
        match self.try_with_jacobian_reuse(k) {
            Ok(s) => s,
            Err(e) => panic!("Rodas::with_jacobian_reuse: {e}"),
        }
    }

    /// Keeps each Jacobian for `k` accepted steps (`k >= 1`; default 1). Unlike
    /// [`super::Rosenbrock`] (a W-method) this costs order: the method is then only of order 2
    /// or so in the terms `J` enters, and the error control shortens the steps.
    ///
    /// # Errors
    /// `k == 0` (`settings = "Rodas"`, `field = "jacobian_reuse"`).
    pub fn try_with_jacobian_reuse(mut self, k: usize) -> Result<Self, SettingsError> {
        if k == 0 {
            return Err(SettingsError {
                settings: "Rodas",
                field: "jacobian_reuse",
                value: 0.0,
                requirement: ">= 1",
            });
        }
        self.jacobian_reuse = k;
        Ok(self)
    }

    /// The tableau's name.
    pub fn method_name(&self) -> &'static str {
        self.tab.name
    }

    adaptive_accessors!();

    /// The dense output on `[t_prev, t]` (module docs); outside, the same polynomial.
    pub fn interpolate(&self, t_query: f64, out: &mut [f64]) {
        let Core {
            t_prev,
            t,
            h_last: h,
            ..
        } = self.core;
        let (y_prev, y, w, dense) = (&self.y_prev, &self.y, &self.w, self.tab.dense);
        dense_output("Rodas", t_query, out, t_prev, t, h, y_prev, y, |th, out| {
            let th1 = 1.0 - th;
            for (i, o) in out.iter_mut().enumerate() {
                let mut p = 0.0;
                for k in (0..dense).rev() {
                    p = w[k][i] + th * p;
                }
                // p = w_1 + theta (w_2 + theta w_3)
                *o = th1 * y_prev[i] + th * (y[i] + th1 * p);
            }
        });
    }

    /// LU of `I/(h gamma) - J_cc`; `Ok(false)` if singular, [`IntegrateError::OutOfTime`]
    /// past the deadline.
    fn factor<E>(&mut self, h: f64) -> Result<bool, IntegrateError<E>> {
        let (n, nc) = (self.dim, self.nc);
        let d = 1.0 / (h * self.tab.gamma);
        for i in 0..nc {
            for j in 0..nc {
                self.lu[i * nc + j] = -self.jac[i * n + j];
            }
            self.lu[i * nc + i] += d;
        }
        self.core.stats.lu_decompositions += 1;
        let result = lu_factor_within(&mut self.lu[..nc * nc], nc, &mut self.piv[..nc], d + self.jac_max, || self.watch.out_of_time());
        self.lu_h = if result.is_ok() { h } else { f64::NAN };
        match result {
            Ok(()) => Ok(true),
            Err(LuStop::Singular(_)) => Ok(false),
            Err(LuStop::OutOfTime(k)) => Err(IntegrateError::OutOfTime {
                t: self.core.t,
                during: Phase::Factoring { column: k + 1, columns: nc },
            }),
        }
    }

    /// Solves `(I/(h gamma) - J) x = r` in place: the coupled block by the LU, the rest by
    /// substitution.
    fn solve(&self, h: f64, x: &mut [f64]) {
        let (n, nc) = (self.dim, self.nc);
        let (xc, xq) = x.split_at_mut(nc);
        lu_solve(&self.lu[..nc * nc], nc, &self.piv[..nc], xc);
        let hg = h * self.tab.gamma;
        // a zero row of J_qc (not in quad_rows) contributes nothing
        let mut rows = self.quad_rows.iter().copied().peekable();
        for (k, v) in xq.iter_mut().enumerate() {
            if rows.next_if_eq(&(nc + k)).is_some() {
                let row = &self.jac[(nc + k) * n..(nc + k) * n + nc];
                let s: f64 = row.iter().zip(xc.iter()).map(|(j, u)| j * u).sum();
                *v = hg * (*v + s);
            } else {
                *v *= hg;
            }
        }
    }

}

impl<S: OdeJacobian> Adaptive<S> for Rodas {
    const NAME: &'static str = "Rodas";

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
            self.tab.order as i32,
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
        let s_last = tab.stages - 1;

        for s in 0..tab.stages {
            let ts = if tab.c[s] == 1.0 { t_new } else { t + tab.c[s] * h };
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
            stage_rhs(&self.f_stage, &self.dfdt, h * tab.d[s], done, &tab.c_ij[s], h, &mut rest[0]);
            let mut x = std::mem::take(&mut self.u[s]);
            self.solve(h, &mut x);
            self.u[s] = x;
            if let Some(i) = first_non_finite(&self.u[s]) {
                return Ok(self.core.reject_non_finite(h, ts, i));
            }
        }

        // solution; the error estimate is the last stage
        for i in 0..n {
            let mut yn = self.y[i];
            for j in 0..tab.stages {
                yn += tab.m[j] * self.u[j][i];
            }
            self.y_new[i] = yn;
        }
        let err = self.core.error_norm(&self.u[s_last], &self.y, &self.y_new);
        let expo = 1.0 / f64::from(tab.embedded_order + 1);
        if err > 1.0 {
            return Ok(self.core.reject(h * CONTROLLER.factor(err, expo).min(1.0), Failure::None));
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

        // dense output of this step
        for (w, hk) in self.w.iter_mut().zip(&tab.h).take(tab.dense) {
            for (i, wi) in w.iter_mut().enumerate() {
                *wi = hk[..tab.stages].iter().zip(&self.u).map(|(c, u)| c * u[i]).sum();
            }
        }
        let fac = self.core.accepted_factor(err, expo, h);
        let h_new = self.core.limit_growth(h * fac, h, h_proposed);
        std::mem::swap(&mut self.y_prev, &mut self.y);
        std::mem::swap(&mut self.y, &mut self.y_new);
        std::mem::swap(&mut self.f0, &mut self.f_new);
        self.core.accept(t_new, h, h_new);
        self.jac_fresh = false;
        self.dfdt_fresh = false;
        self.steps_since_jac += 1;
        Ok(Attempt::Accepted)
    }
}

impl<S: OdeJacobian> Stepper<S> for Rodas {
    /// Evaluates `f(t0, y0)` once and reads the system's coupled dimension; the Jacobian is
    /// evaluated by the first step.
    ///
    /// # Panics
    /// Also if `sys.coupled_dim() > dim`.
    fn init(&mut self, sys: &mut S, t0: f64, y0: &[f64]) -> Result<(), IntegrateError<S::Error>> {
        self.core.init("Rodas", self.dim, &*sys, t0, y0)?;
        self.nc = sys.coupled_dim();
        self.jac_tail_zero = false;
        assert!(self.nc <= self.dim, "Rodas::init: coupled_dim {} > dim {}", self.nc, self.dim);
        self.jac_valid = false;
        self.jac_fresh = false;
        self.dfdt_fresh = false;
        self.lu_h = f64::NAN;
        self.y.copy_from_slice(y0);
        self.y_prev.copy_from_slice(y0);
        for w in &mut self.w {
            w.fill(0.0);
        }
        eval_finite(&mut self.core.stats, sys, t0, y0, &mut self.f0)?;
        self.core.initialized = true;
        Ok(())
    }

    /// `init`, keeping the last accepted step's size for [`Stepper::first_step_after_restart`]
    /// (module docs).
    fn restart(&mut self, sys: &mut S, t0: f64, y0: &[f64]) -> Result<(), IntegrateError<S::Error>> {
        adaptive::restart(self, sys, t0, y0)
    }

    /// The first step after an event (module docs): the last accepted step's size where every
    /// event function is armed, the smaller of it and the fresh starting step where one is
    /// disarmed; at most `h_max`. As `init` before any accepted step.
    fn first_step_after_restart(&mut self, sys: &mut S, start: RestartStart) -> Result<(), IntegrateError<S::Error>> {
        adaptive::first_step_after_restart(self, sys, start)
    }

    fn step(&mut self, sys: &mut S, t_stop: f64) -> Result<f64, IntegrateError<S::Error>> {
        adaptive::step(self, sys, t_stop)
    }

    forward_stepper_accessors!(Rodas);

    fn set_watch(&mut self, watch: Watch) {
        self.watch = watch;
    }

    fn set_state(&mut self, sys: &mut S, y: &[f64]) -> Result<(), IntegrateError<S::Error>> {
        self.y.copy_from_slice(y);
        eval_finite(&mut self.core.stats, sys, self.core.t, y, &mut self.f0)
    }
}

#[cfg(test)]
mod tests;
