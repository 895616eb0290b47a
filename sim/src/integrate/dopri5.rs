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
//! - starting step: HNW I §II.4, "Starting Step Size" (a–f), with the RMS norm above.
//! - dense output: the continuous extension of HNW I §II.6 as coded in `dopri5.f`'s `contd5`:
//!   `y(t_prev + s h) = r0 + s (r1 + (1-s) (r2 + s (r3 + (1-s) r4)))`, of order 4.
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

use super::{first_non_finite, IntegrateError, OdeSystem, SettingsError, Stats, Stepper};

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

/// Tolerances and step-size controller settings for [`DormandPrince45`].
///
/// The defaults are those of [`Default`] (the only place they are written down); the
/// controller constants match `dopri5.f`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dopri5Settings {
    /// Relative tolerance, >= 0.
    pub rtol: f64,
    /// Absolute tolerance (same unit as y), > 0.
    pub atol: f64,
    /// First step to try; `None` uses Hairer's starting-step algorithm (one extra evaluation).
    pub h_init: Option<f64>,
    /// Largest step, > 0 (may be infinite).
    pub h_max: f64,
    /// Smallest step before giving up with `StepSizeTooSmall`, >= 0 (a final step shortened
    /// to land on `t_stop` may be smaller).
    pub h_min: f64,
    /// Most step attempts (accepted + rejected) between `init` and `TooManySteps`, > 0.
    pub max_steps: usize,
    /// Safety factor on the predicted optimal step, in (0, 1].
    pub safety: f64,
    /// Lower bound on `h_new / h`, in (0, 1] (`dopri5.f` FAC1).
    pub fac_min: f64,
    /// Upper bound on `h_new / h`, >= 1 (`dopri5.f` FAC2).
    pub fac_max: f64,
    /// PI stabilisation exponent, in [0, 0.2]; 0 gives the plain controller (`dopri5.f` BETA).
    pub beta: f64,
}

impl Default for Dopri5Settings {
    fn default() -> Self {
        Self {
            rtol: 1e-6,
            atol: 1e-9,
            h_init: None,
            h_max: f64::INFINITY,
            h_min: 0.0,
            max_steps: 100_000,
            safety: 0.9,
            fac_min: 0.2,
            fac_max: 10.0,
            beta: 0.04,
        }
    }
}

impl Dopri5Settings {
    /// Checks every field's range (see the field docs); use on user-supplied settings.
    ///
    /// # Errors
    /// The first field out of range, with its value and the requirement.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let bad = |field, value, requirement| {
            Err(SettingsError {
                settings: "Dopri5Settings",
                field,
                value,
                requirement,
            })
        };
        if !(self.rtol.is_finite() && self.rtol >= 0.0) {
            return bad("rtol", self.rtol, "finite and >= 0");
        }
        if !(self.atol.is_finite() && self.atol > 0.0) {
            return bad("atol", self.atol, "finite and > 0");
        }
        if let Some(h) = self.h_init {
            if !(h.is_finite() && h > 0.0 && h >= self.h_min) {
                return bad("h_init", h, "finite, > 0 and >= h_min");
            }
        }
        if self.h_max.is_nan() || self.h_max <= 0.0 {
            return bad("h_max", self.h_max, "> 0 (may be infinite)");
        }
        if !(self.h_min.is_finite() && self.h_min >= 0.0 && self.h_min <= self.h_max) {
            return bad("h_min", self.h_min, "finite, >= 0 and <= h_max");
        }
        if self.max_steps == 0 {
            return bad("max_steps", 0.0, "> 0");
        }
        if !(self.safety > 0.0 && self.safety <= 1.0) {
            return bad("safety", self.safety, "in (0, 1]");
        }
        if !(self.fac_min > 0.0 && self.fac_min <= 1.0) {
            return bad("fac_min", self.fac_min, "in (0, 1]");
        }
        if !(self.fac_max.is_finite() && self.fac_max >= 1.0) {
            return bad("fac_max", self.fac_max, "finite and >= 1");
        }
        if !(self.beta >= 0.0 && self.beta <= 0.2) {
            return bad("beta", self.beta, "in [0, 0.2]");
        }
        Ok(())
    }
}

/// Adaptive Dormand–Prince 5(4) stepper (`dopri5.f`) with dense output.
#[derive(Clone, Debug)]
pub struct DormandPrince45 {
    /// State dimension.
    dim: usize,
    settings: Dopri5Settings,
    /// Exponent of err in the controller, `1/5 - 0.75 beta`.
    expo1: f64,
    /// Current time and state; `k1 = f(t, y)` (FSAL).
    t: f64,
    y: Vec<f64>,
    k1: Vec<f64>,
    /// Start and size of the last accepted step (`h_last = 0` before the first step).
    t_prev: f64,
    h_last: f64,
    /// Next step size to try; `None` until the first `step` computes or takes `h_init`.
    h_next: Option<f64>,
    /// Controller memory: max(err, 1e-4) of the last accepted step.
    err_old: f64,
    /// The last attempt was rejected (the next accepted step may not grow).
    rejected_last: bool,
    /// The last rejection was a non-finite stage: (time of the evaluation, component).
    non_finite: Option<(f64, usize)>,
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
    stats: Stats,
    initialized: bool,
}

/// Outcome of one step attempt.
enum Attempt {
    Accepted,
    Rejected,
}

impl DormandPrince45 {
    /// A stepper for systems of dimension `dim`; all buffers are allocated here.
    ///
    /// # Panics
    /// If `settings.validate()` fails; use [`DormandPrince45::try_new`] for user input.
    pub fn new(dim: usize, settings: Dopri5Settings) -> Self {
        match Self::try_new(dim, settings) {
            Ok(s) => s,
            Err(e) => panic!("DormandPrince45::new: {e}"),
        }
    }

    /// Like [`DormandPrince45::new`], returning the settings error instead of panicking.
    ///
    /// # Errors
    /// The first out-of-range field of `settings` (see [`Dopri5Settings::validate`]).
    pub fn try_new(dim: usize, settings: Dopri5Settings) -> Result<Self, SettingsError> {
        settings.validate()?;
        let z = || vec![0.0; dim];
        Ok(Self {
            dim,
            settings,
            expo1: 0.2 - 0.75 * settings.beta,
            t: 0.0,
            y: z(),
            k1: z(),
            t_prev: 0.0,
            h_last: 0.0,
            h_next: None,
            err_old: 1e-4,
            rejected_last: false,
            non_finite: None,
            k2: z(),
            k3: z(),
            k4: z(),
            k5: z(),
            k6: z(),
            k7: z(),
            y_stage: z(),
            y_new: z(),
            dense: [z(), z(), z(), z(), z()],
            stats: Stats::default(),
            initialized: false,
        })
    }

    /// The settings this stepper was built with.
    pub fn settings(&self) -> &Dopri5Settings {
        &self.settings
    }

    /// Start of the last accepted step (equals `t()` before the first step).
    pub fn t_prev(&self) -> f64 {
        self.t_prev
    }

    /// Current time (same as [`Stepper::t`], without naming the system type).
    pub fn t(&self) -> f64 {
        self.t
    }

    /// Current state (same as [`Stepper::y`]).
    pub fn y(&self) -> &[f64] {
        &self.y
    }

    /// 4th-order continuous extension on `[t_prev, t]` (`contd5`). Outside that interval it
    /// extrapolates the same quartic (accuracy degrades quickly).
    pub fn interpolate(&self, t_query: f64, out: &mut [f64]) {
        assert_eq!(
            out.len(),
            self.dim,
            "DormandPrince45::interpolate: out length vs dim"
        );
        if t_query == self.t || self.h_last == 0.0 {
            out.copy_from_slice(&self.y);
            return;
        }
        if t_query == self.t_prev {
            out.copy_from_slice(&self.dense[0]);
            return;
        }
        let s = (t_query - self.t_prev) / self.h_last;
        let s1 = 1.0 - s;
        let [r0, r1, r2, r3, r4] = &self.dense;
        for (i, o) in out.iter_mut().enumerate() {
            *o = r0[i] + s * (r1[i] + s1 * (r2[i] + s * (r3[i] + s1 * r4[i])));
        }
    }

    /// Work counters since `init` (same as [`Stepper::stats`]).
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// Step size the next attempt will use (before the `h_max` and `t_stop` limits);
    /// `None` before the first step.
    pub fn h_next(&self) -> Option<f64> {
        self.h_next
    }

    /// Hairer's starting step (HNW I §II.4, a–f; order p = 5). Uses one evaluation.
    fn initial_step<S: OdeSystem>(&mut self, sys: &mut S) -> Result<f64, IntegrateError<S::Error>> {
        let Dopri5Settings {
            atol, rtol, h_max, ..
        } = self.settings;
        let inv_n = 1.0 / self.dim.max(1) as f64;
        // a) d0 = ||y0||, d1 = ||f(t0, y0)|| in the tolerance-weighted RMS norm
        let (mut d0, mut d1) = (0.0, 0.0);
        for i in 0..self.dim {
            let sk = atol + rtol * self.y[i].abs();
            d0 += (self.y[i] / sk).powi(2);
            d1 += (self.k1[i] / sk).powi(2);
        }
        let (d0, d1) = ((d0 * inv_n).sqrt(), (d1 * inv_n).sqrt());
        // b) first guess
        let h0 = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        let h0 = h0.min(h_max);
        // c) explicit Euler step, d) estimate of the second derivative
        for i in 0..self.dim {
            self.y_stage[i] = self.y[i] + h0 * self.k1[i];
        }
        self.stats.rhs_evals += 1;
        sys.rhs(self.t + h0, &self.y_stage, &mut self.k2)
            .map_err(IntegrateError::Rhs)?;
        let mut d2 = 0.0;
        for i in 0..self.dim {
            let sk = atol + rtol * self.y[i].abs();
            d2 += ((self.k2[i] - self.k1[i]) / sk).powi(2);
        }
        let d2 = (d2 * inv_n).sqrt() / h0;
        // e) h1^5 max(d1, d2) = 0.01 (a NaN d2 from a probe outside the domain is ignored)
        let dmax = d1.max(d2);
        let h1 = if dmax <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / dmax).powf(0.2)
        };
        // f)
        let h = (100.0 * h0).min(h1).min(h_max);
        Ok(if h.is_finite() && h > 0.0 { h } else { h0 })
    }

    /// Evaluates one stage, counting it; returns the first non-finite component, if any.
    fn eval<S: OdeSystem>(
        stats: &mut Stats,
        sys: &mut S,
        t: f64,
        y: &[f64],
        out: &mut [f64],
    ) -> Result<Option<usize>, IntegrateError<S::Error>> {
        stats.rhs_evals += 1;
        sys.rhs(t, y, out).map_err(IntegrateError::Rhs)?;
        Ok(first_non_finite(out))
    }

    /// Records a rejection caused by a non-finite value produced at time `t_bad`.
    fn reject_non_finite(&mut self, h: f64, t_bad: f64, index: usize) -> Attempt {
        self.h_next = Some(h * self.settings.fac_min);
        self.rejected_last = true;
        self.non_finite = Some((t_bad, index));
        self.stats.rejected += 1;
        Attempt::Rejected
    }

    /// One attempt from `(t, y)` with step `h` ending at `t_new`; commits on acceptance.
    /// `h_proposed` is the controller's step before it was shortened to land on `t_stop`.
    fn attempt<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        h: f64,
        t_new: f64,
        h_proposed: f64,
    ) -> Result<Attempt, IntegrateError<S::Error>> {
        let (t, n) = (self.t, self.dim);
        let (y, k1) = (&self.y, &self.k1);

        // stages 2..6
        for i in 0..n {
            self.y_stage[i] = y[i] + h * A21 * k1[i];
        }
        let ts = t + C2 * h;
        if let Some(i) = Self::eval(&mut self.stats, sys, ts, &self.y_stage, &mut self.k2)? {
            return Ok(self.reject_non_finite(h, ts, i));
        }
        let (y, k1, k2) = (&self.y, &self.k1, &self.k2);
        for i in 0..n {
            self.y_stage[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i]);
        }
        let ts = t + C3 * h;
        if let Some(i) = Self::eval(&mut self.stats, sys, ts, &self.y_stage, &mut self.k3)? {
            return Ok(self.reject_non_finite(h, ts, i));
        }
        let (y, k1, k2, k3) = (&self.y, &self.k1, &self.k2, &self.k3);
        for i in 0..n {
            self.y_stage[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
        }
        let ts = t + C4 * h;
        if let Some(i) = Self::eval(&mut self.stats, sys, ts, &self.y_stage, &mut self.k4)? {
            return Ok(self.reject_non_finite(h, ts, i));
        }
        let (y, k1, k2, k3, k4) = (&self.y, &self.k1, &self.k2, &self.k3, &self.k4);
        for i in 0..n {
            self.y_stage[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
        }
        let ts = t + C5 * h;
        if let Some(i) = Self::eval(&mut self.stats, sys, ts, &self.y_stage, &mut self.k5)? {
            return Ok(self.reject_non_finite(h, ts, i));
        }
        let (y, k1, k2, k3, k4, k5) = (&self.y, &self.k1, &self.k2, &self.k3, &self.k4, &self.k5);
        for i in 0..n {
            self.y_stage[i] =
                y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
        }
        if let Some(i) = Self::eval(&mut self.stats, sys, t_new, &self.y_stage, &mut self.k6)? {
            return Ok(self.reject_non_finite(h, t_new, i));
        }

        // 5th-order solution, then stage 7 at it (FSAL)
        let (y, k1, k3, k4, k5, k6) = (&self.y, &self.k1, &self.k3, &self.k4, &self.k5, &self.k6);
        for i in 0..n {
            self.y_new[i] =
                y[i] + h * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i]);
        }
        if let Some(i) = first_non_finite(&self.y_new) {
            return Ok(self.reject_non_finite(h, t_new, i));
        }
        if let Some(i) = Self::eval(&mut self.stats, sys, t_new, &self.y_new, &mut self.k7)? {
            return Ok(self.reject_non_finite(h, t_new, i));
        }

        // error estimate in the tolerance-weighted RMS norm, HNW I §II.4
        let Dopri5Settings {
            atol,
            rtol,
            safety,
            fac_min,
            fac_max,
            beta,
            h_max,
            ..
        } = self.settings;
        let (y, k1, k3, k4, k5, k6, k7) = (
            &self.y, &self.k1, &self.k3, &self.k4, &self.k5, &self.k6, &self.k7,
        );
        let mut sum = 0.0;
        for i in 0..n {
            let e =
                h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
            let sk = atol + rtol * y[i].abs().max(self.y_new[i].abs());
            sum += (e / sk).powi(2);
        }
        let err = if n == 0 { 0.0 } else { (sum / n as f64).sqrt() };

        // step-size controller (dopri5.f): fac = h / h_new, bounded to [1/fac_max, 1/fac_min]
        let fac11 = err.powf(self.expo1);
        let accepted = err <= 1.0;
        if !accepted {
            // rejected (err > 1, or an overflowed inf)
            let fac = (fac11 / safety).min(1.0 / fac_min);
            self.h_next = Some(h / fac);
            self.rejected_last = true;
            self.non_finite = None;
            self.stats.rejected += 1;
            return Ok(Attempt::Rejected);
        }
        let fac = (fac11 / self.err_old.powf(beta) / safety)
            .min(1.0 / fac_min)
            .max(1.0 / fac_max);
        let mut h_new = h / fac;
        if self.rejected_last {
            h_new = h_new.min(h);
        }
        if h < h_proposed {
            // shortened to land on t_stop: keep the step the controller had planned
            h_new = h_new.max(h_proposed);
        }
        self.err_old = err.max(1e-4);

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
        self.t_prev = t;
        self.t = t_new;
        self.h_last = h;
        self.h_next = Some(h_new.min(h_max));
        self.rejected_last = false;
        self.non_finite = None;
        self.stats.steps += 1;
        Ok(Attempt::Accepted)
    }
}

impl<S: OdeSystem> Stepper<S> for DormandPrince45 {
    /// Evaluates `f(t0, y0)` once (the FSAL first stage).
    fn init(&mut self, sys: &mut S, t0: f64, y0: &[f64]) -> Result<(), IntegrateError<S::Error>> {
        assert_eq!(
            sys.dim(),
            self.dim,
            "DormandPrince45::init: system dim vs stepper dim"
        );
        assert_eq!(
            y0.len(),
            self.dim,
            "DormandPrince45::init: y0 length vs dim"
        );
        self.initialized = false;
        self.stats = Stats::default();
        if let Some(index) = first_non_finite(y0) {
            return Err(IntegrateError::NonFiniteState { t: t0, index });
        }
        self.t = t0;
        self.t_prev = t0;
        self.h_last = 0.0;
        self.h_next = None;
        self.err_old = 1e-4;
        self.rejected_last = false;
        self.non_finite = None;
        self.y.copy_from_slice(y0);
        self.dense[0].copy_from_slice(y0);
        if let Some(index) = Self::eval(&mut self.stats, sys, t0, y0, &mut self.k1)? {
            return Err(IntegrateError::NonFiniteState { t: t0, index });
        }
        self.initialized = true;
        Ok(())
    }

    fn step(&mut self, sys: &mut S, t_stop: f64) -> Result<f64, IntegrateError<S::Error>> {
        assert!(
            self.initialized,
            "DormandPrince45::step called before a successful init"
        );
        // nothing to do at or past the stop time (forward integration only)
        if t_stop.is_nan() || t_stop <= self.t {
            return Ok(self.t);
        }
        let h_first = match (self.h_next, self.settings.h_init) {
            (Some(h), _) | (None, Some(h)) => h,
            (None, None) => self.initial_step(sys)?,
        };
        self.h_next = Some(h_first);

        loop {
            if self.stats.steps + self.stats.rejected >= self.settings.max_steps as u64 {
                return Err(IntegrateError::TooManySteps {
                    t: self.t,
                    max_steps: self.settings.max_steps,
                });
            }
            let h = self.h_next.unwrap_or(h_first).min(self.settings.h_max);

            // step-size collapse (dopri5.f: 0.1 |h| <= |x| uround)
            if !(h >= self.settings.h_min && 0.1 * h > self.t.abs() * f64::EPSILON && h > 0.0) {
                return Err(match self.non_finite {
                    Some((t, index)) => IntegrateError::NonFiniteState { t, index },
                    None => IntegrateError::StepSizeTooSmall { t: self.t, h },
                });
            }

            // land on t_stop, stretching the step by up to 1% rather than leaving a sliver
            let (h_try, t_new) = if self.t + 1.01 * h >= t_stop {
                (t_stop - self.t, t_stop)
            } else {
                (h, self.t + h)
            };

            if let Attempt::Accepted = self.attempt(sys, h_try, t_new, h)? {
                // the per-step state check (the attempt already rejects non-finite trial states)
                if let Some(index) = first_non_finite(&self.y) {
                    return Err(IntegrateError::NonFiniteState { t: self.t, index });
                }
                return Ok(self.t);
            }
        }
    }

    fn t(&self) -> f64 {
        DormandPrince45::t(self)
    }

    fn y(&self) -> &[f64] {
        DormandPrince45::y(self)
    }

    fn interpolate(&self, t_query: f64, out: &mut [f64]) {
        DormandPrince45::interpolate(self, t_query, out)
    }

    fn stats(&self) -> Stats {
        DormandPrince45::stats(self)
    }

    fn set_state(&mut self, sys: &mut S, y: &[f64]) -> Result<(), IntegrateError<S::Error>> {
        self.y.copy_from_slice(y);
        self.stats.rhs_evals += 1;
        sys.rhs(self.t, y, &mut self.k1).map_err(IntegrateError::Rhs)?;
        match first_non_finite(&self.k1) {
            Some(index) => Err(IntegrateError::NonFiniteState { t: self.t, index }),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests;
