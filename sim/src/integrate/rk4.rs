//! Classical 4th-order Runge–Kutta method with a fixed step and cubic Hermite dense output.
//!
//! Tableau: Kutta (1901), HNW I §II.1 ("the" Runge–Kutta method):
//! `c = (0, 1/2, 1/2, 1)`, `b = (1/6, 1/3, 1/3, 1/6)`, `a21 = a32 = 1/2`, `a43 = 1`.
//!
//! Step times lie on the grid `t0 + k h`, each computed by multiplication (no accumulated
//! round-off). A step that would pass `t_stop` is shortened to land on `t_stop` exactly; the
//! following step then returns to the grid.
//!
//! Dense output is the cubic Hermite interpolant through `(y, f)` at both ends of the step
//! (HNW I §II.6); `f` at the end of a step is the first stage of the next one, so the
//! interpolant costs no extra evaluation: 4 evaluations per step, plus 1 in `init`.
//! Its error is O(h^4), matching the method's global error.

use super::{
    dense_output, eval_finite, first_non_finite, hermite, IntegrateError, OdeSystem, Stats, Stepper,
};

/// Fixed-step classical Runge–Kutta method (4 stages, order 4).
#[derive(Clone, Debug)]
pub struct Rk4 {
    /// State dimension.
    dim: usize,
    /// Grid spacing (the nominal step), > 0.
    h: f64,
    /// Grid origin, set by `init`.
    t0: f64,
    /// Index `k` of the last grid point `t0 + k h` reached.
    k_grid: u64,
    /// Current time and state `y(t)`, with `f = f(t, y)`.
    t: f64,
    y: Vec<f64>,
    f: Vec<f64>,
    /// Start of the last accepted step and its `y`, `f` (the Hermite data at the left end).
    t_prev: f64,
    y_prev: Vec<f64>,
    f_prev: Vec<f64>,
    /// Stage derivatives k2..k4 and the stage argument (scratch).
    k2: Vec<f64>,
    k3: Vec<f64>,
    k4: Vec<f64>,
    y_stage: Vec<f64>,
    stats: Stats,
    initialized: bool,
}

impl Rk4 {
    /// A stepper for systems of dimension `dim` with fixed step `h` (> 0, finite).
    ///
    /// All buffers are allocated here; `init`, `step` and `interpolate` never allocate.
    ///
    /// # Panics
    /// If `h` is not finite and positive (validate user input before constructing).
    pub fn new(dim: usize, h: f64) -> Self {
        assert!(
            h.is_finite() && h > 0.0,
            "Rk4::new: step h must be finite and > 0, got {h}"
        );
        let z = || vec![0.0; dim];
        Self {
            dim,
            h,
            t0: 0.0,
            k_grid: 0,
            t: 0.0,
            y: z(),
            f: z(),
            t_prev: 0.0,
            y_prev: z(),
            f_prev: z(),
            k2: z(),
            k3: z(),
            k4: z(),
            y_stage: z(),
            stats: Stats::default(),
            initialized: false,
        }
    }

    /// The fixed (grid) step.
    pub fn h(&self) -> f64 {
        self.h
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

    /// Cubic Hermite interpolation on `[t_prev, t]`. Outside that interval it extrapolates the
    /// same cubic (accuracy degrades quickly).
    pub fn interpolate(&self, t_query: f64, out: &mut [f64]) {
        let (t_prev, h) = (self.t_prev, self.t - self.t_prev);
        dense_output(
            "Rk4",
            t_query,
            out,
            t_prev,
            self.t,
            h,
            &self.y_prev,
            &self.y,
            |th, out| {
                hermite(
                    th,
                    h,
                    &self.y_prev,
                    &self.f_prev,
                    &self.y,
                    |i| self.f[i],
                    out,
                )
            },
        );
    }

    /// Work counters since `init` (same as [`Stepper::stats`]).
    pub fn stats(&self) -> Stats {
        self.stats
    }
}

impl<S: OdeSystem> Stepper<S> for Rk4 {
    fn init(&mut self, sys: &mut S, t0: f64, y0: &[f64]) -> Result<(), IntegrateError<S::Error>> {
        assert_eq!(sys.dim(), self.dim, "Rk4::init: system dim vs stepper dim");
        assert_eq!(y0.len(), self.dim, "Rk4::init: y0 length vs dim");
        self.initialized = false;
        self.stats = Stats::default();
        if let Some(index) = first_non_finite(y0) {
            return Err(IntegrateError::NonFiniteState { t: t0, index });
        }
        self.t0 = t0;
        self.k_grid = 0;
        self.t = t0;
        self.t_prev = t0;
        self.y.copy_from_slice(y0);
        self.y_prev.copy_from_slice(y0);
        eval_finite(&mut self.stats, sys, t0, y0, &mut self.f)?;
        self.f_prev.copy_from_slice(&self.f);
        self.initialized = true;
        Ok(())
    }

    fn step(&mut self, sys: &mut S, t_stop: f64) -> Result<f64, IntegrateError<S::Error>> {
        assert!(
            self.initialized,
            "Rk4::step called before a successful init"
        );
        // nothing to do at or past the stop time (forward integration only)
        if t_stop.is_nan() || t_stop <= self.t {
            return Ok(self.t);
        }

        // next grid point; land on t_stop instead when the grid point reaches it, or misses it
        // by no more than rounding (no sliver steps)
        let t_grid = self.t0 + (self.k_grid + 1) as f64 * self.h;
        let snap = 1e-9 * self.h + 4.0 * f64::EPSILON * t_stop.abs();
        let (t_new, on_grid) = if t_grid >= t_stop - snap {
            (t_stop, t_grid <= t_stop + snap)
        } else {
            (t_grid, true)
        };
        let (t, h) = (self.t, t_new - self.t);
        let n = self.dim;

        // stages k2, k3, k4 (k1 = f(t, y) from the previous step)
        for i in 0..n {
            self.y_stage[i] = self.y[i] + 0.5 * h * self.f[i];
        }
        eval_finite(
            &mut self.stats,
            sys,
            t + 0.5 * h,
            &self.y_stage,
            &mut self.k2,
        )?;
        for i in 0..n {
            self.y_stage[i] = self.y[i] + 0.5 * h * self.k2[i];
        }
        eval_finite(
            &mut self.stats,
            sys,
            t + 0.5 * h,
            &self.y_stage,
            &mut self.k3,
        )?;
        for i in 0..n {
            self.y_stage[i] = self.y[i] + h * self.k3[i];
        }
        eval_finite(&mut self.stats, sys, t_new, &self.y_stage, &mut self.k4)?;

        // new state into y_stage
        let h6 = h / 6.0;
        for i in 0..n {
            self.y_stage[i] =
                self.y[i] + h6 * (self.f[i] + 2.0 * (self.k2[i] + self.k3[i]) + self.k4[i]);
        }
        if let Some(index) = first_non_finite(&self.y_stage) {
            return Err(IntegrateError::NonFiniteState { t: t_new, index });
        }

        // f at the new state (k2 is free now): the next step's k1 and the Hermite slope
        eval_finite(&mut self.stats, sys, t_new, &self.y_stage, &mut self.k2)?;

        // commit: (y, f) -> previous, new -> current; nothing changed before this point
        std::mem::swap(&mut self.y_prev, &mut self.y);
        std::mem::swap(&mut self.y, &mut self.y_stage);
        std::mem::swap(&mut self.f_prev, &mut self.f);
        std::mem::swap(&mut self.f, &mut self.k2);
        self.t_prev = t;
        self.t = t_new;
        if on_grid {
            self.k_grid += 1;
        }
        self.stats.steps += 1;
        Ok(t_new)
    }

    forward_stepper_accessors!(Rk4);

    fn set_state(&mut self, sys: &mut S, y: &[f64]) -> Result<(), IntegrateError<S::Error>> {
        self.y.copy_from_slice(y);
        eval_finite(&mut self.stats, sys, self.t, y, &mut self.f)
    }
}

#[cfg(test)]
mod tests {
    //! Rk4-specific: the grid, landing on stop times, the step count, the stage at which a
    //! failure is met. The stepper contract (orders, dense output, counts, errors) is
    //! `contract.rs`.

    use super::super::test_problems::{
        FailingRhs, HarmonicOscillator, NanAfter, RationalDecay, RhsFailure,
    };
    use super::super::testutil::run_to_failure;
    use super::*;

    #[test]
    fn rk4_step_times_are_multiples_of_h() {
        let mut p = RationalDecay;
        let (t0, h) = (0.1, 0.1);
        let mut st = Rk4::new(1, h);
        st.init(&mut p, t0, &[1.0]).expect("init");
        for k in 1..=1000u32 {
            let t = st.step(&mut p, 1e9).expect("step");
            assert_eq!(t, t0 + f64::from(k) * h, "step {k}");
        }
    }

    #[test]
    fn rk4_final_step_lands_on_t_stop_and_grid_resumes() {
        let mut p = HarmonicOscillator::default();
        let mut st = Rk4::new(2, 0.1);
        st.init(&mut p, 0.0, &[1.0, 0.0]).expect("init");
        let mut last = 0.0;
        while st.t() < 0.25 {
            last = st.step(&mut p, 0.25).expect("step");
        }
        assert_eq!(last, 0.25);
        assert_eq!(st.stats().steps, 3); // 0.1, 0.2, 0.25 (shortened)
                                         // the grid resumes at 0.3 = 3 * 0.1, not 0.35
        assert_eq!(st.step(&mut p, 1.0).expect("step"), 3.0 * 0.1);
        // a stop time within rounding of a grid point is hit without a sliver step
        let mut st = Rk4::new(2, 0.1);
        st.init(&mut p, 0.0, &[1.0, 0.0]).expect("init");
        let t_stop = 0.30000000000000004; // 0.1 + 0.2
        while st.t() < t_stop {
            st.step(&mut p, t_stop).expect("step");
        }
        assert_eq!(st.stats().steps, 3);
        assert_eq!(st.t(), t_stop);
        // 123 full steps + 1 shortened to reach 1.234 with h = 0.01
        let mut st = Rk4::new(2, 0.01);
        st.init(&mut p, 0.0, &[1.0, 0.0]).expect("init");
        while st.t() < 1.234 {
            st.step(&mut p, 1.234).expect("step");
        }
        assert_eq!(st.stats().steps, 124);
    }

    // A failure is met by the first stage evaluated at or after its onset: with h = 0.1, a
    // failing rhs from 0.33 and a NaN from 0.43 at k2 of the steps from 0.3 and 0.4 (0.35,
    // 0.45); the state stays at the step's start (t = 0.3 after 3 steps; t = 0.4).
    #[test]
    fn rk4_failures_are_met_at_the_stage_time() {
        let mut p = FailingRhs { t_fail: 0.33 };
        let mut st = Rk4::new(1, 0.1);
        st.init(&mut p, 0.0, &[1.0]).expect("init");
        match run_to_failure(&mut st, &mut p, 1.0) {
            IntegrateError::Rhs(RhsFailure { t }) => assert!((t - 0.35).abs() < 1e-15, "{t}"),
            other => panic!("expected Rhs error, got {other:?}"),
        }
        assert!((st.t() - 0.3).abs() < 1e-15 && st.stats().steps == 3);
        let mut p = NanAfter {
            t_nan: 0.43,
            index: 1,
        };
        let mut st = Rk4::new(2, 0.1);
        st.init(&mut p, 0.0, &[1.0, 1.0]).expect("init");
        match run_to_failure(&mut st, &mut p, 1.0) {
            IntegrateError::NonFiniteState { t, index } => {
                assert!(
                    (t - 0.45).abs() < 1e-12 && index == 1,
                    "t = {t}, index {index}"
                );
            }
            other => panic!("expected NonFiniteState, got {other:?}"),
        }
        assert!((st.t() - 0.4).abs() < 1e-15);
    }
}
