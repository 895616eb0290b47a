//! Pieces shared by the steppers' tests: every test problem as one system type ([`Problem`]),
//! so that the contract (`contract.rs`) runs every method over every problem; runs against an
//! exact solution; and [`Checks`], which collects the failures of a sweep over methods and
//! problems and reports them all at once.

use std::convert::Infallible;

use super::test_problems::{
    ExactSolution, ExponentialDecay, FailingRhs, HarmonicOscillator, Kepler, NanAfter,
    RationalDecay, RhsFailure, RiccatiBlowup, StiffKepler, StiffLinear, StiffOscillator,
};
use super::{fd_jacobian, FdJacobian, OdeJacobian, OdeSystem, SplitSystem, Stats, Stepper};

/// A test problem of `test_problems`, as one type that is an [`OdeSystem`], [`OdeJacobian`],
/// [`SplitSystem`] and [`ExactSolution`], so every method can be built for it.
///
/// - Jacobian: the problem's analytic `J` and `f_t` where it has them, else forward
///   differences ([`fd_jacobian`], `f_t` left to the stepper's own difference).
/// - Split: the problem's own where it has one; [`FailingRhs`] all implicit (`f_E = 0`, its
///   solve fails from `t_fail` on like its `rhs`); the others all explicit (`f_I = 0`, the
///   solve is `z = r`: [`super::ArkImex`] is then its explicit part).
#[derive(Clone, Copy, Debug)]
pub(super) enum Problem {
    Decay(ExponentialDecay),
    Oscillator(HarmonicOscillator),
    Rational(RationalDecay),
    Kepler(Kepler),
    Pr(StiffLinear),
    Motor(StiffOscillator),
    StiffKepler(StiffKepler),
    Blowup(RiccatiBlowup),
    Failing(FailingRhs),
    Nan(NanAfter),
}

/// The system errors of the test problems, as the one error type of [`Problem`].
trait IntoFailure {
    fn into_failure(self) -> RhsFailure;
}

impl IntoFailure for Infallible {
    fn into_failure(self) -> RhsFailure {
        match self {}
    }
}

impl IntoFailure for RhsFailure {
    fn into_failure(self) -> RhsFailure {
        self
    }
}

/// `$e` with `$p` bound to the problem inside any variant of `$problem`.
macro_rules! each {
    ($problem:expr, $p:ident => $e:expr) => {
        match $problem {
            Problem::Decay($p) => $e,
            Problem::Oscillator($p) => $e,
            Problem::Rational($p) => $e,
            Problem::Kepler($p) => $e,
            Problem::Pr($p) => $e,
            Problem::Motor($p) => $e,
            Problem::StiffKepler($p) => $e,
            Problem::Blowup($p) => $e,
            Problem::Failing($p) => $e,
            Problem::Nan($p) => $e,
        }
    };
}

impl OdeSystem for Problem {
    type Error = RhsFailure;
    fn dim(&self) -> usize {
        each!(self, p => p.dim())
    }
    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RhsFailure> {
        each!(self, p => p.rhs(t, y, dydt).map_err(IntoFailure::into_failure))
    }
}

/// Forward-difference Jacobian of a problem of dimension <= 2.
fn fd<P: OdeSystem>(
    p: &mut P,
    t: f64,
    y: &[f64],
    fy: &[f64],
    jac: &mut [f64],
) -> Result<(), RhsFailure>
where
    P::Error: IntoFailure,
{
    let n = y.len();
    let (mut sy, mut sf) = ([0.0; 2], [0.0; 2]);
    fd_jacobian(p, t, y, fy, jac, &mut sy[..n], &mut sf[..n]).map_err(IntoFailure::into_failure)
}

impl OdeJacobian for Problem {
    fn jacobian(
        &mut self,
        t: f64,
        y: &[f64],
        fy: &[f64],
        jac: &mut [f64],
    ) -> Result<(), RhsFailure> {
        let conv = IntoFailure::into_failure;
        match self {
            Problem::Decay(p) => p.jacobian(t, y, fy, jac).map_err(conv),
            Problem::Oscillator(p) => p.jacobian(t, y, fy, jac).map_err(conv),
            Problem::Rational(p) => p.jacobian(t, y, fy, jac).map_err(conv),
            Problem::Kepler(p) => p.jacobian(t, y, fy, jac).map_err(conv),
            Problem::Pr(p) => p.jacobian(t, y, fy, jac).map_err(conv),
            Problem::Motor(p) => p.jacobian(t, y, fy, jac).map_err(conv),
            Problem::StiffKepler(p) => p.jacobian(t, y, fy, jac).map_err(conv),
            Problem::Blowup(p) => fd(p, t, y, fy, jac),
            Problem::Failing(p) => fd(p, t, y, fy, jac),
            Problem::Nan(p) => fd(p, t, y, fy, jac),
        }
    }

    fn time_derivative(
        &mut self,
        t: f64,
        y: &[f64],
        fy: &[f64],
        dfdt: &mut [f64],
    ) -> Result<bool, RhsFailure> {
        let conv = IntoFailure::into_failure;
        match self {
            Problem::Decay(p) => p.time_derivative(t, y, fy, dfdt).map_err(conv),
            Problem::Oscillator(p) => p.time_derivative(t, y, fy, dfdt).map_err(conv),
            Problem::Rational(p) => p.time_derivative(t, y, fy, dfdt).map_err(conv),
            Problem::Kepler(p) => p.time_derivative(t, y, fy, dfdt).map_err(conv),
            Problem::Pr(p) => p.time_derivative(t, y, fy, dfdt).map_err(conv),
            Problem::Motor(p) => p.time_derivative(t, y, fy, dfdt).map_err(conv),
            Problem::StiffKepler(p) => p.time_derivative(t, y, fy, dfdt).map_err(conv),
            Problem::Blowup(_) | Problem::Failing(_) | Problem::Nan(_) => Ok(false),
        }
    }
}

impl SplitSystem for Problem {
    fn rhs_split(
        &mut self,
        t: f64,
        y: &[f64],
        f_e: &mut [f64],
        f_i: &mut [f64],
    ) -> Result<(), RhsFailure> {
        let conv = IntoFailure::into_failure;
        match self {
            Problem::Pr(p) => p.rhs_split(t, y, f_e, f_i).map_err(conv),
            Problem::Motor(p) => p.rhs_split(t, y, f_e, f_i).map_err(conv),
            Problem::StiffKepler(p) => p.rhs_split(t, y, f_e, f_i).map_err(conv),
            Problem::Failing(p) => {
                f_e.fill(0.0);
                p.rhs(t, y, f_i)
            }
            _ => {
                f_i.fill(0.0);
                self.rhs(t, y, f_e)
            }
        }
    }

    fn solve_implicit(
        &mut self,
        t: f64,
        gamma: f64,
        r: &[f64],
        z: &mut [f64],
    ) -> Result<(), RhsFailure> {
        let conv = IntoFailure::into_failure;
        match self {
            Problem::Pr(p) => p.solve_implicit(t, gamma, r, z).map_err(conv),
            Problem::Motor(p) => p.solve_implicit(t, gamma, r, z).map_err(conv),
            Problem::StiffKepler(p) => p.solve_implicit(t, gamma, r, z).map_err(conv),
            Problem::Failing(p) if t >= p.t_fail => Err(RhsFailure { t }),
            Problem::Failing(_) => {
                // z - gamma (-z) = r
                z[0] = r[0] / (1.0 + gamma);
                Ok(())
            }
            _ => {
                z.copy_from_slice(r);
                Ok(())
            }
        }
    }
}

impl ExactSolution for Problem {
    fn t0(&self) -> f64 {
        each!(self, p => p.t0())
    }
    fn exact(&self, t: f64, y: &mut [f64]) {
        each!(self, p => p.exact(t, y))
    }
}

/// A problem behind a finite-difference Jacobian has the problem's exact solution.
impl<P: ExactSolution> ExactSolution for FdJacobian<P> {
    fn t0(&self) -> f64 {
        self.inner().t0()
    }
    fn exact(&self, t: f64, y: &mut [f64]) {
        self.inner().exact(t, y)
    }
}

/// Failures of a sweep over methods and problems, reported together (with everything that
/// passed printed by the test) when dropped, so one run shows the whole picture.
#[derive(Default)]
pub(super) struct Checks(Vec<String>);

impl Checks {
    /// Records `what()` as a failure unless `ok`.
    pub fn check(&mut self, ok: bool, what: impl FnOnce() -> String) {
        if !ok {
            self.0.push(what());
        }
    }
}

impl Drop for Checks {
    fn drop(&mut self) {
        if !self.0.is_empty() && !std::thread::panicking() {
            panic!("{} failed:\n  {}", self.0.len(), self.0.join("\n  "));
        }
    }
}

/// max_i |y_i - exact_i| / (1 + |exact_i|): the error scaled the way rtol = atol = tol asks
/// for roughly `tol` per step.
pub(super) fn scaled_err(y: &[f64], exact: &[f64]) -> f64 {
    y.iter()
        .zip(exact)
        .map(|(a, b)| (a - b).abs() / (1.0 + b.abs()))
        .fold(0.0, f64::max)
}

/// What [`run_exact`] measured.
pub(super) struct Run {
    /// Scaled error at t_end.
    pub err_end: f64,
    /// Max scaled error of the dense output at 7 interior points of every step.
    pub err_dense: f64,
    pub stats: Stats,
}

/// Integrates `p` with `st` from its t0 to `t_end`, stepping to `t_end` (never past it) and
/// checking the dense output at 7 interior points of every step.
pub(super) fn run_exact<P, St>(mut p: P, st: &mut St, t_end: f64) -> Run
where
    P: ExactSolution,
    St: Stepper<P> + ?Sized,
{
    let n = p.dim();
    let y0 = p.y0();
    let (mut ex, mut yi) = (vec![0.0; n], vec![0.0; n]);
    let t0 = p.t0();
    st.init(&mut p, t0, &y0).expect("init");
    let mut err_dense: f64 = 0.0;
    while st.t() < t_end {
        let t_old = st.t();
        let t_new = st.step(&mut p, t_end).expect("step");
        assert!(t_new <= t_end, "stepped past t_stop: {t_new} > {t_end}");
        for j in 1..8 {
            let tq = t_old + f64::from(j) / 8.0 * (t_new - t_old);
            st.interpolate(tq, &mut yi);
            p.exact(tq, &mut ex);
            err_dense = err_dense.max(scaled_err(&yi, &ex));
        }
    }
    assert_eq!(st.t(), t_end);
    p.exact(t_end, &mut ex);
    Run {
        err_end: scaled_err(st.y(), &ex),
        err_dense,
        stats: st.stats(),
    }
}

/// One step `h` of `st` from the exact state of `p` at `t0` (the step must end at `t0 + h`):
/// checks that the dense output returns both ends exactly and returns its max scaled error at
/// theta = 1/4, 1/2, 3/4.
pub(super) fn local_dense_err<P, St>(mut p: P, st: &mut St, t0: f64, h: f64) -> f64
where
    P: ExactSolution,
    St: Stepper<P> + ?Sized,
{
    let n = p.dim();
    let mut y0 = vec![0.0; n];
    p.exact(t0, &mut y0);
    st.init(&mut p, t0, &y0).expect("init");
    assert_eq!(st.step(&mut p, 100.0).expect("step"), t0 + h);
    let (mut yi, mut ex) = (vec![0.0; n], vec![0.0; n]);
    st.interpolate(t0, &mut yi);
    assert_eq!(yi, y0);
    st.interpolate(t0 + h, &mut yi);
    assert_eq!(yi.as_slice(), st.y());
    let mut e: f64 = 0.0;
    for th in [0.25, 0.5, 0.75] {
        st.interpolate(t0 + th * h, &mut yi);
        p.exact(t0 + th * h, &mut ex);
        e = e.max(scaled_err(&yi, &ex));
    }
    e
}

/// Steps `st` until it fails (panics if it reaches `t_stop`), returning the error.
pub(super) fn run_to_failure<P, St>(
    st: &mut St,
    p: &mut P,
    t_stop: f64,
) -> super::IntegrateError<P::Error>
where
    P: OdeSystem,
    St: Stepper<P> + ?Sized,
{
    loop {
        match st.step(p, t_stop) {
            Ok(t) => assert!(t < t_stop, "reached t_stop = {t_stop} without failing"),
            Err(e) => return e,
        }
    }
}
