//! Dormand–Prince 5(4): adaptive explicit Runge–Kutta with FSAL and 4th-order dense output.
//!
//! References (HNW I = Hairer, Nørsett & Wanner, *Solving Ordinary Differential Equations I*,
//! 2nd ed., 1993), following Hairer's Fortran code `dopri5.f`:
//! - tableau: Dormand & Prince, "A family of embedded Runge–Kutta formulae", J. Comput. Appl.
//!   Math. 6 (1980) 19–26; HNW I §II.5. Seven stages, the 7th is `f(t + h, y_new)`
//!   and becomes the next step's 1st (FSAL), so an accepted step costs 6 evaluations.
//! - error estimate and norm: HNW I §II.4: `err = sqrt(1/n sum (e_i / sc_i)^2)`,
//!   `sc_i = atol + rtol max(|y_i|, |y_new_i|)`, `e_i` the difference of the 5th- and 4th-order
//!   solutions; the step is accepted when `err <= 1`.
//! - step-size control: HNW I §II.4 with `dopri5.f`'s bounds `0.2 <= h_new/h <= 10` and
//!   safety 0.9, plus the PI ("Lund") stabilisation of `dopri5.f` (Gustafsson, ACM TOMS 17
//!   (1991); HNW II §IV.2): `h_new = h safety err^-(1/5 - 0.75 beta) err_old^beta`,
//!   `beta = 0.04`. After a rejection the next accepted step may not grow.
//! - starting step: HNW I §II.4, "Starting Step Size" (a–f), with the RMS norm above; after an
//!   event's restart, the last accepted step (`adaptive.rs`, as RODAS).
//! - dense output: the continuous extension of HNW I §II.6 as coded in `dopri5.f`'s `contd5`:
//!   `y(t_prev + s h) = r0 + s (r1 + (1-s) (r2 + s (r3 + (1-s) r4)))`, of order 4.
//!
//! - stiffness detection: `dopri5.f`'s test (HNW I §II.10, "Automatic Stiffness Detection";
//!   Hairer & Wanner, HNW II §IV.2): on every [`NSTIFF`]-th accepted step, and on every step
//!   once a check was positive, `h λ ≈ h ||f(t+h, y_new) − f(t+h, Y6)|| / ||y_new − Y6||`
//!   (both at the step's end: the 7th stage and the 6th stage's argument `Y6`); beyond 3.25
//!   (DOPRI5's stability boundary on the negative real axis is ≈ 3.3) it counts as stiff, 15
//!   stiff checks in a row mean the problem is stiff, 6 non-stiff ones reset the count.
//!   `dopri5.f` then stops (IDID = −4); here [`IntegrateError::Stiff`] is returned only when
//!   more than [`STIFF_STEPS_LEFT`] steps of the current size remain before `t_stop`, so a
//!   mildly stiff problem still completes and one that would crawl for hours ends at once.
//!   The test only reads the stages: it never changes a step.
//!
//! Deviations from `dopri5.f`, all deliberate:
//! - a non-finite stage derivative or trial state counts as a failed error test and shrinks `h`
//!   by `fac_min` (a too-large trial step may leave the domain of `f`); only if the step size
//!   then collapses is [`IntegrateError::NonFiniteState`] returned, at the time of the last
//!   offending evaluation (which is then within a few rounding units of the onset);
//! - when a step is shortened to land on `t_stop` and accepted, the next step starts from the
//!   larger of the controller's new proposal and the one that was cut short, so frequent stop
//!   times (e.g. control updates) do not drag the step size down;
//! - `max_steps` counts attempts (accepted + rejected) since `init`; every rejection is counted in
//!   [`Stats::rejected`], including those before the first accepted step.

use super::adaptive::{self, initial_step, Adaptive, Attempt, Core, Failure};
use super::control::Controller;
use super::{
    dense_output, eval, eval_finite, first_non_finite, IntegrateError, OdeSystem, RestartStart,
    SettingsError, Stats, StepControl, Stepper,
};

// Dormand & Prince (1980) tableau, HNW I §II.5 (c6 = c7 = 1).
const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
// 5th-order weights b (= row 7 of A, FSAL); b2 = b7 = 0
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
// error coefficients e = b - b_hat (dopri5.f E1..E7); e2 = 0
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
// dense output coefficients (dopri5.f D1..D7, HNW I §II.6); d2 = 0
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// The step-size controller of `dopri5.f` (SAFE = 0.9, FAC1 = 0.2, FAC2 = 10): `h_new / h`
/// in `[0.2, 10]`.
const CONTROLLER: Controller = Controller {
    safety: 0.9,
    fac_min: 0.2,
    fac_max: 10.0,
};

/// PI stabilisation exponent of `dopri5.f` (BETA = 0.04; 0 would give the plain controller).
const BETA: f64 = 0.04;

/// Stiffness test every `NSTIFF` accepted steps (`dopri5.f`'s default NSTIFF = 1000).
pub const NSTIFF: u64 = 1000;
/// `h λ` beyond this counts as a stiff check (`dopri5.f`: 3.25).
const STIFF_H_LAMBDA: f64 = 3.25;
/// Stiff checks in a row that make the problem stiff (`dopri5.f`: 15).
const STIFF_CHECKS: u32 = 15;
/// Non-stiff checks in a row that reset the count (`dopri5.f`: 6).
const NON_STIFF_CHECKS: u32 = 6;
/// A stiff problem is given up ([`IntegrateError::Stiff`]) when more steps than this, of the
/// current size, remain before `t_stop` (at 6 evaluations a step, 6 10^6 evaluations: what an
/// implicit method does in a few hundred).
pub const STIFF_STEPS_LEFT: f64 = 1e6;

/// Adaptive Dormand–Prince 5(4) stepper (`dopri5.f`) with dense output.
#[derive(Clone, Debug)]
pub struct DormandPrince45 {
    /// State dimension.
    dim: usize,
    /// Time, last step, step-size control and statistics.
    core: Core,
    /// Exponent of err in the controller, `1/5 - 0.75 beta`.
    expo1: f64,
    /// Current state; `k1 = f(t, y)` (FSAL).
    y: Vec<f64>,
    k1: Vec<f64>,
    /// Controller memory: max(err, 1e-4) of the last accepted step.
    err_old: f64,
    /// Stage derivatives k2..k7 (k7 = f(t + h, y_new), swapped into k1 on acceptance).
    k2: Vec<f64>,
    k3: Vec<f64>,
    k4: Vec<f64>,
    k5: Vec<f64>,
    k6: Vec<f64>,
    k7: Vec<f64>,
    /// Stage argument and trial solution (scratch).
    y_stage: Vec<f64>,
    y_new: Vec<f64>,
    /// Dense-output coefficients r0..r4 of the last accepted step (`contd5`); `r0 = y(t_prev)`.
    dense: [Vec<f64>; 5],
    /// Stiffness detection (`dopri5.f`'s IASTI, NONSTI, HLAMB): stiff and non-stiff checks in
    /// a row, the last estimate of `h λ`.
    stiff_checks: u32,
    non_stiff_checks: u32,
    h_lambda: f64,
}

impl DormandPrince45 {
    /// A stepper for systems of dimension `dim`; all buffers are allocated here.
    ///
    /// # Panics
    /// If `control.validate()` fails; use [`DormandPrince45::try_new`] for user input.
    pub fn new(dim: usize, control: StepControl) -> Self {
        match Self::try_new(dim, control) {
            Ok(s) => s,
            Err(e) => panic!("DormandPrince45::new: {e}"),
        }
    }

    /// Like [`DormandPrince45::new`], returning the settings error instead of panicking.
    ///
    /// # Errors
    /// The first out-of-range field of `control` (see [`StepControl::validate`]).
    pub fn try_new(dim: usize, control: StepControl) -> Result<Self, SettingsError> {
        control.validate()?;
        let z = || vec![0.0; dim];
        Ok(Self {
            dim,
            core: Core::new(control, CONTROLLER),
            expo1: 0.2 - 0.75 * BETA,
            y: z(),
            k1: z(),
            err_old: 1e-4,
            k2: z(),
            k3: z(),
            k4: z(),
            k5: z(),
            k6: z(),
            k7: z(),
            y_stage: z(),
            y_new: z(),
            dense: [z(), z(), z(), z(), z()],
            stiff_checks: 0,
            non_stiff_checks: 0,
            h_lambda: 0.0,
        })
    }

    adaptive_accessors!();

    /// 4th-order continuous extension on `[t_prev, t]` (`contd5`). Outside that interval it
    /// extrapolates the same quartic (accuracy degrades quickly).
    pub fn interpolate(&self, t_query: f64, out: &mut [f64]) {
        let Core {
            t_prev,
            t,
            h_last: h,
            ..
        } = self.core;
        let [r0, r1, r2, r3, r4] = &self.dense;
        dense_output(
            "DormandPrince45",
            t_query,
            out,
            t_prev,
            t,
            h,
            r0,
            &self.y,
            |s, out| {
                let s1 = 1.0 - s;
                for (i, o) in out.iter_mut().enumerate() {
                    *o = r0[i] + s * (r1[i] + s1 * (r2[i] + s * (r3[i] + s1 * r4[i])));
                }
            },
        );
    }
}

impl<S: OdeSystem> Adaptive<S> for DormandPrince45 {
    const NAME: &'static str = "DormandPrince45";

    fn core(&mut self) -> &mut Core {
        &mut self.core
    }

    /// Hairer's starting step; `dopri5.f`'s IORD = 5 (`h1^5 max(d1, d2) = 0.01`).
    fn starting_step(&mut self, sys: &mut S) -> Result<f64, IntegrateError<S::Error>> {
        let core = &mut self.core;
        initial_step(
            sys,
            &mut core.stats,
            core.t,
            &self.y,
            &self.k1,
            &mut self.y_stage,
            &mut self.k2,
            &core.control,
            &core.measured,
            4,
        )
    }

    /// [`DormandPrince45::attempt`], then the per-step state check (the attempt already rejects
    /// non-finite trial states).
    fn attempt(
        &mut self,
        sys: &mut S,
        h: f64,
        t_new: f64,
        h_proposed: f64,
    ) -> Result<Attempt, IntegrateError<S::Error>> {
        let outcome = DormandPrince45::attempt(self, sys, h, t_new, h_proposed)?;
        if let Attempt::Accepted = outcome {
            if let Some(index) = first_non_finite(&self.y) {
                return Err(IntegrateError::NonFiniteState {
                    t: self.core.t,
                    index,
                });
            }
            let Core { t, t_stop, h_last, .. } = self.core;
            if self.stiff_checks >= STIFF_CHECKS && (t_stop - t) / h_last > STIFF_STEPS_LEFT {
                return Err(IntegrateError::Stiff {
                    t,
                    h: h_last,
                    h_lambda: self.h_lambda,
                });
            }
        }
        Ok(outcome)
    }
}

impl DormandPrince45 {
    /// One attempt from `(t, y)` with step `h` ending at `t_new`; commits on acceptance.
    /// `h_proposed` is the controller's step before it was shortened to land on `t_stop`.
    fn attempt<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        h: f64,
        t_new: f64,
        h_proposed: f64,
    ) -> Result<Attempt, IntegrateError<S::Error>> {
        let (t, n) = (self.core.t, self.dim);
        let (y, k1) = (&self.y, &self.k1);

        // stages 2..6
        for i in 0..n {
            self.y_stage[i] = y[i] + h * A21 * k1[i];
        }
        let ts = t + C2 * h;
        if let Some(i) = eval(&mut self.core.stats, sys, ts, &self.y_stage, &mut self.k2)? {
            return Ok(self.core.reject_non_finite(h, ts, i));
        }
        let (y, k1, k2) = (&self.y, &self.k1, &self.k2);
        for i in 0..n {
            self.y_stage[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i]);
        }
        let ts = t + C3 * h;
        if let Some(i) = eval(&mut self.core.stats, sys, ts, &self.y_stage, &mut self.k3)? {
            return Ok(self.core.reject_non_finite(h, ts, i));
        }
        let (y, k1, k2, k3) = (&self.y, &self.k1, &self.k2, &self.k3);
        for i in 0..n {
            self.y_stage[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
        }
        let ts = t + C4 * h;
        if let Some(i) = eval(&mut self.core.stats, sys, ts, &self.y_stage, &mut self.k4)? {
            return Ok(self.core.reject_non_finite(h, ts, i));
        }
        let (y, k1, k2, k3, k4) = (&self.y, &self.k1, &self.k2, &self.k3, &self.k4);
        for i in 0..n {
            self.y_stage[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
        }
        let ts = t + C5 * h;
        if let Some(i) = eval(&mut self.core.stats, sys, ts, &self.y_stage, &mut self.k5)? {
            return Ok(self.core.reject_non_finite(h, ts, i));
        }
        let (y, k1, k2, k3, k4, k5) = (&self.y, &self.k1, &self.k2, &self.k3, &self.k4, &self.k5);
        for i in 0..n {
            self.y_stage[i] =
                y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
        }
        if let Some(i) = eval(
            &mut self.core.stats,
            sys,
            t_new,
            &self.y_stage,
            &mut self.k6,
        )? {
            return Ok(self.core.reject_non_finite(h, t_new, i));
        }

        // 5th-order solution, then stage 7 at it (FSAL)
        let (y, k1, k3, k4, k5, k6) = (&self.y, &self.k1, &self.k3, &self.k4, &self.k5, &self.k6);
        for i in 0..n {
            self.y_new[i] =
                y[i] + h * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i]);
        }
        if let Some(i) = first_non_finite(&self.y_new) {
            return Ok(self.core.reject_non_finite(h, t_new, i));
        }
        if let Some(i) = eval(&mut self.core.stats, sys, t_new, &self.y_new, &mut self.k7)? {
            return Ok(self.core.reject_non_finite(h, t_new, i));
        }

        // stiffness test (dopri5.f), read before y_stage (= Y6) is overwritten; it counts only
        // if the step is accepted (then it is accepted step number steps + 1)
        let stiff_check = (self.core.stats.steps + 1).is_multiple_of(NSTIFF) || self.stiff_checks > 0;
        let (mut stnum, mut stden) = (0.0, 0.0);
        if stiff_check {
            for i in 0..n {
                stnum += (self.k7[i] - self.k6[i]).powi(2);
                stden += (self.y_new[i] - self.y_stage[i]).powi(2);
            }
        }

        // error estimate (into y_stage) in the tolerance-weighted RMS norm, HNW I §II.4
        let Controller {
            safety,
            fac_min,
            fac_max,
        } = CONTROLLER;
        let (y, k1, k3, k4, k5, k6, k7) = (
            &self.y, &self.k1, &self.k3, &self.k4, &self.k5, &self.k6, &self.k7,
        );
        for i in 0..n {
            self.y_stage[i] =
                h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
        }
        let err = self.core.error_norm(&self.y_stage, y, &self.y_new);

        // step-size controller (dopri5.f): fac = h / h_new, bounded to [1/fac_max, 1/fac_min]
        let fac11 = err.powf(self.expo1);
        let accepted = err <= 1.0;
        if !accepted {
            // rejected (err > 1, or an overflowed inf)
            let fac = (fac11 / safety).min(1.0 / fac_min);
            return Ok(self.core.reject(h / fac, Failure::None));
        }
        let fac = (fac11 / self.err_old.powf(BETA) / safety)
            .min(1.0 / fac_min)
            .max(1.0 / fac_max);
        let h_new = self.core.limit_growth(h / fac, h, h_proposed);
        self.err_old = err.max(1e-4);
        if stiff_check {
            if stden > 0.0 {
                self.h_lambda = h * (stnum / stden).sqrt();
            }
            if self.h_lambda > STIFF_H_LAMBDA {
                self.non_stiff_checks = 0;
                self.stiff_checks += 1;
            } else {
                self.non_stiff_checks += 1;
                if self.non_stiff_checks == NON_STIFF_CHECKS {
                    self.stiff_checks = 0;
                }
            }
        }

        // dense output coefficients (dopri5.f, contd5)
        for i in 0..n {
            let ydiff = self.y_new[i] - y[i];
            let bspl = h * k1[i] - ydiff;
            self.dense[0][i] = y[i];
            self.dense[1][i] = ydiff;
            self.dense[2][i] = bspl;
            self.dense[3][i] = ydiff - h * k7[i] - bspl;
            self.dense[4][i] =
                h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i]);
        }

        // commit
        std::mem::swap(&mut self.y, &mut self.y_new);
        std::mem::swap(&mut self.k1, &mut self.k7);
        self.core.accept(t_new, h, h_new);
        Ok(Attempt::Accepted)
    }
}

impl<S: OdeSystem> Stepper<S> for DormandPrince45 {
    /// Evaluates `f(t0, y0)` once (the FSAL first stage).
    fn init(&mut self, sys: &mut S, t0: f64, y0: &[f64]) -> Result<(), IntegrateError<S::Error>> {
        self.core
            .init("DormandPrince45", self.dim, &*sys, t0, y0)?;
        self.err_old = 1e-4;
        (self.stiff_checks, self.non_stiff_checks, self.h_lambda) = (0, 0, 0.0);
        self.y.copy_from_slice(y0);
        self.dense[0].copy_from_slice(y0);
        eval_finite(&mut self.core.stats, sys, t0, y0, &mut self.k1)?;
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

    forward_stepper_accessors!(DormandPrince45);

    fn set_state(&mut self, sys: &mut S, y: &[f64]) -> Result<(), IntegrateError<S::Error>> {
        self.y.copy_from_slice(y);
        eval_finite(&mut self.core.stats, sys, self.core.t, y, &mut self.k1)
    }
}
