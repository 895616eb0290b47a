//! Locating the earliest root of the event functions in an accepted step: the Illinois
//! (modified regula falsi) iteration of SUNDIALS CVODE's `cvRootfind` (Hindmarsh et al., ACM
//! TOMS 31 (2005) 363–396, §2.4), on the stepper's dense output (HNW I §II.6).

use super::HybridSystem;
use crate::integrate::{IntegrateError, Phase, Stepper, Watch};

/// Most trial points of one root search: far more than the ~log2(h / time_tol) ≈ 40 a
/// bisection would need, so the bound only stops a search that cannot shrink its bracket
/// (which the inward adjustment below rules out).
const MAX_TRIALS: u32 = 400;

/// The event functions at the ends of a bracket, the trial values, the directions and which
/// functions fired: sized once per run (`n` functions).
pub(super) struct Bracket {
    pub(super) g_lo: Vec<f64>,
    pub(super) g_hi: Vec<f64>,
    g_mid: Vec<f64>,
    pub(super) dir: Vec<i8>,
    pub(super) fired: Vec<bool>,
    /// The start value `g₀` a function is watched from (module doc of `events`), and whether it
    /// is watched so; `g_lo`, `g_hi` and the trial values hold `g − g₀` for those.
    base: Vec<f64>,
    watched: Vec<bool>,
    /// `event_tolerance(i)` of the watched functions, read with the bases.
    tolerance: Vec<f64>,
    /// `event_departure(i)` of the watched functions (at most their tolerance), read with the
    /// bases: how far off its firing side a probe of [`departed_inside`] must find it.
    departure: Vec<f64>,
    /// The functions [`Bracket::left_at_start`] fired, kept while another function's root in
    /// the same step is located ([`Bracket::hold_start_firing`]).
    start_fired: Vec<bool>,
}

/// Which end of the bracket a fresh evaluation of the functions went into.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Side {
    Hi,
}

impl Bracket {
    pub(super) fn new(n: usize) -> Self {
        Bracket {
            g_lo: vec![0.0; n],
            g_hi: vec![0.0; n],
            g_mid: vec![0.0; n],
            dir: vec![0; n],
            fired: vec![false; n],
            base: vec![0.0; n],
            watched: vec![false; n],
            tolerance: vec![0.0; n],
            departure: vec![0.0; n],
            start_fired: vec![false; n],
        }
    }

    /// At a (re)start, with `g_lo` the raw values there: a function of direction −1 (+1) at or
    /// on its firing side (`≤ 0`, `≥ 0`) is watched from its value, so `g_lo` becomes 0 for it.
    pub(super) fn set_bases<S: HybridSystem>(&mut self, sys: &S) {
        for i in 0..self.g_lo.len() {
            let g = self.g_lo[i];
            let on_firing_side = match self.dir[i] {
                d if d < 0 => g <= 0.0,
                d if d > 0 => g >= 0.0,
                _ => false,
            };
            let tolerance = sys.event_tolerance(i);
            self.watched[i] = on_firing_side && g.is_finite() && tolerance.is_some();
            self.base[i] = if self.watched[i] { g } else { 0.0 };
            self.tolerance[i] = tolerance.unwrap_or(0.0);
            self.departure[i] = sys.event_departure(i).map_or(self.tolerance[i], |d| d.min(self.tolerance[i]));
            if self.watched[i] {
                self.g_lo[i] = 0.0;
            }
        }
    }

    /// At a step start, with `g_lo` the raw values there: a watched function that has left its
    /// firing side (`> 0` for direction −1, `< 0` for +1) is watched no more; the others are
    /// shifted by their start value.
    pub(super) fn release_and_shift_lo(&mut self) {
        for i in 0..self.g_lo.len() {
            if !self.watched[i] {
                continue;
            }
            let g = self.g_lo[i];
            let left = match self.dir[i] {
                d if d < 0 => g > 0.0,
                d if d > 0 => g < 0.0,
                _ => true,
            };
            if left {
                self.watched[i] = false;
                self.base[i] = 0.0;
            } else {
                self.g_lo[i] = g - self.base[i];
            }
        }
    }

    /// Shift a fresh evaluation by the start values of the watched functions.
    pub(super) fn shift(&mut self, side: Side) {
        let v = match side {
            Side::Hi => &mut self.g_hi,
        };
        shift(v, &self.base, &self.watched);
    }

    /// Whether a watched function sat at (or before) its start value at the step's start and
    /// has moved past it to its firing side by more than its tolerance at the step's end: then
    /// those functions fire, at the step's start; `fired` is set.
    pub(super) fn left_at_start(&mut self) -> bool {
        let mut any = false;
        for i in 0..self.g_lo.len() {
            let (lo, hi, tol) = (self.g_lo[i], self.g_hi[i], self.tolerance[i]);
            self.fired[i] = self.watched[i]
                && match self.dir[i] {
                    d if d < 0 => lo <= 0.0 && hi < -tol,
                    d if d > 0 => lo >= 0.0 && hi > tol,
                    _ => false,
                };
            any |= self.fired[i];
        }
        any
    }

    /// After [`Bracket::left_at_start`] fired watched functions, which did not leave and come
    /// back inside the step ([`departed_inside`]): whether another function changes sign in the
    /// same step. Then the start firing is held (`fired` cleared, the fired set kept) while that
    /// root is located: a function watched from its start value that has not yet moved past its
    /// tolerance at the other function's root cannot have fired before it (it was still at its
    /// start value, inside its dead band, when the other event happened).
    pub(super) fn hold_start_firing(&mut self) -> bool {
        let n = self.g_lo.len();
        let other = (0..n).any(|i| !self.fired[i] && crosses(self.dir[i], self.g_lo[i], self.g_hi[i]));
        if other {
            self.start_fired.copy_from_slice(&self.fired);
            self.fired.iter_mut().for_each(|f| *f = false);
        }
        other
    }

    /// After [`Bracket::hold_start_firing`] and the location of the other root (`g_hi` its
    /// values there): whether a held function had already moved past its tolerance to its
    /// firing side by then — then it fires at the step's start after all (the earliest event),
    /// and `fired` is the held set again; otherwise the other root's firing stands.
    pub(super) fn start_firing_before_root(&mut self) -> bool {
        let n = self.g_lo.len();
        let past = (0..n).any(|i| {
            self.start_fired[i]
                && match self.dir[i] {
                    d if d < 0 => self.g_hi[i] < -self.tolerance[i],
                    d if d > 0 => self.g_hi[i] > self.tolerance[i],
                    _ => false,
                }
        });
        if past {
            self.fired.copy_from_slice(&self.start_fired);
        }
        past
    }

    /// At a (re)start, after [`Bracket::set_bases`]: whether a function that is not watched
    /// starts at 0 or on its firing side (`≤ 0` for direction −1, `≥ 0` for +1), so that
    /// [`crosses`] cannot fire it in the first step (disarmed; a NaN too).
    pub(super) fn any_disarmed(&self) -> bool {
        (0..self.g_lo.len()).any(|i| {
            let g = self.g_lo[i];
            !self.watched[i]
                && !match self.dir[i] {
                    d if d < 0 => g > 0.0,
                    d if d > 0 => g < 0.0,
                    _ => g != 0.0,
                }
        })
    }

    /// Reads the directions of the current mode from `sys`.
    pub(super) fn refresh_directions<S: HybridSystem>(&mut self, sys: &S) {
        for (i, d) in self.dir.iter_mut().enumerate() {
            *d = sys.event_direction(i);
        }
    }
}

/// Whether a function of direction `dir` going from `lo` to `g` has changed sign: from `> 0`
/// to `≤ 0` (`dir = −1`), from `< 0` to `≥ 0` (`+1`), either (`0`). `lo = 0` never (disarmed);
/// a NaN never.
#[inline]
pub(super) fn crosses(dir: i8, lo: f64, g: f64) -> bool {
    let down = lo > 0.0 && g <= 0.0;
    let up = lo < 0.0 && g >= 0.0;
    match dir {
        d if d < 0 => down,
        d if d > 0 => up,
        _ => down || up,
    }
}

/// The earliest root in `[t_lo, t_hi]` (an accepted step of `stepper`, whose `br.g_lo`,
/// `br.g_hi` hold the functions at its ends and have a sign change): narrows the bracket to
/// `≤ tol` and returns its upper end `t*`, with `br.fired` the functions that changed sign
/// over the final bracket and `br.g_hi` their values at `t*`. `y` is scratch (length dim).
/// Each trial point evaluates every event function (for the arm, a right-hand side), so the
/// clock is read before each: past `watch`'s deadline the location stops with
/// [`IntegrateError::OutOfTime`] at `t_lo` (where the stepper's state is still the step's).
#[allow(clippy::too_many_arguments)]
pub(super) fn locate_root<S: HybridSystem, St: Stepper<S> + ?Sized>(
    stepper: &St,
    sys: &mut S,
    br: &mut Bracket,
    mut t_lo: f64,
    mut t_hi: f64,
    tol: f64,
    watch: Watch,
    y: &mut [f64],
) -> Result<f64, IntegrateError<S::Error>> {
    let n = br.g_lo.len();
    // the function to take the secant on: the largest |g_hi| / |g_hi - g_lo| among the crossing
    let pick = |lo: &[f64], hi: &[f64], dir: &[i8]| -> Option<usize> {
        let mut best: Option<(usize, f64)> = None;
        for i in 0..n {
            if crosses(dir[i], lo[i], hi[i]) {
                let frac = (hi[i] / (hi[i] - lo[i])).abs();
                if best.is_none_or(|(_, f)| frac > f) {
                    best = Some((i, frac));
                }
            }
        }
        best.map(|(i, _)| i)
    };
    let Some(mut imax) = pick(&br.g_lo, &br.g_hi, &br.dir) else {
        unreachable_bracket(br);
        return Ok(t_hi);
    };
    let mut alpha = 1.0;
    // side of the last two reductions: 1 = the root was in the low part, 2 = in the high part
    let (mut side, mut side_prev) = (0u8, 0u8);
    let mut trials = 0;
    while t_hi - t_lo > tol && trials < MAX_TRIALS {
        if watch.out_of_time() {
            return Err(IntegrateError::OutOfTime { t: t_lo, during: Phase::LocatingEvent { trials: trials as usize } });
        }
        trials += 1;
        // Illinois weight: the same side twice in a row -> weight the retained end's value
        alpha = if trials > 2 && side == side_prev { if side == 2 { alpha * 2.0 } else { alpha * 0.5 } } else { 1.0 };
        let (glo, ghi) = (br.g_lo[imax], br.g_hi[imax]);
        let mut t_mid = t_hi - (t_hi - t_lo) * ghi / (ghi - alpha * glo);
        if !t_mid.is_finite() {
            t_mid = 0.5 * (t_lo + t_hi);
        }
        // keep the trial point at least tol/2 inside the bracket (cvRootfind's adjustment)
        let width = t_hi - t_lo;
        let inward = || {
            let frac_int = width / tol;
            (if frac_int > 5.0 { 0.1 } else { 0.5 / frac_int }) * width
        };
        if t_mid - t_lo < 0.5 * tol {
            t_mid = t_lo + inward();
        }
        if t_hi - t_mid < 0.5 * tol {
            t_mid = t_hi - inward();
        }
        if !(t_mid > t_lo && t_mid < t_hi) {
            break; // the bracket is down to adjacent floating-point numbers
        }
        stepper.interpolate(t_mid, y);
        sys.events(t_mid, y, &mut br.g_mid).map_err(IntegrateError::Rhs)?;
        shift(&mut br.g_mid, &br.base, &br.watched);
        side_prev = side;
        match pick(&br.g_lo, &br.g_mid, &br.dir) {
            Some(i) => {
                // a sign change in [t_lo, t_mid]: the root (the earliest) is there
                imax = i;
                t_hi = t_mid;
                br.g_hi.copy_from_slice(&br.g_mid);
                side = 1;
            }
            None => {
                t_lo = t_mid;
                br.g_lo.copy_from_slice(&br.g_mid);
                side = 2;
            }
        }
    }
    for i in 0..n {
        br.fired[i] = crosses(br.dir[i], br.g_lo[i], br.g_hi[i]);
    }
    Ok(t_hi)
}

/// After [`Bracket::left_at_start`] fired watched functions (each at its start value at the
/// step's start, past it towards its firing side at the end): whether they left towards the
/// other side first and came back inside the step — a joint that starts sliding from rest,
/// turns and stops within one step; a contact force that grows from 0, then falls below it.
/// Then the root is the return, inside the step, not the step's start. The dense output is
/// probed at `t_lo + (t_hi − t_lo) 2^−k`, k = 1, 2, … while the probe is more than `tol` past
/// `t_lo` (the excursion starts at `t_lo`, so halving finds any longer than `tol`); at the
/// first probe `t_p` where every fired function is off its firing side, `fired` is cleared and
/// the bracket to locate returned: `[t_p, t_hi]` with the probe's values as `g_lo`, or
/// `[t_lo, t_p]` with them as `g_hi` when some function changes sign before `t_p` (the earlier
/// root). Off the firing side means by more than the function's departure bound
/// ([`HybridSystem::event_departure`], by default its [`HybridSystem::event_tolerance`], as
/// past it towards the firing side does for firing).
/// `None`: they moved straight to their firing side; they fire at the step's start.
/// `y` is scratch (length dim).
#[allow(clippy::too_many_arguments)]
pub(super) fn departed_inside<S: HybridSystem, St: Stepper<S> + ?Sized>(
    stepper: &St,
    sys: &mut S,
    br: &mut Bracket,
    t_lo: f64,
    t_hi: f64,
    tol: f64,
    watch: Watch,
    y: &mut [f64],
) -> Result<Option<(f64, f64)>, IntegrateError<S::Error>> {
    let n = br.g_lo.len();
    let mut k = 1;
    loop {
        let t_p = t_lo + (t_hi - t_lo) * 0.5f64.powi(k);
        let gap = t_p - t_lo;
        if gap.is_nan() || gap <= tol {
            return Ok(None);
        }
        if watch.out_of_time() {
            return Err(IntegrateError::OutOfTime { t: t_lo, during: Phase::LocatingEvent { trials: k as usize } });
        }
        stepper.interpolate(t_p, y);
        sys.events(t_p, y, &mut br.g_mid).map_err(IntegrateError::Rhs)?;
        shift(&mut br.g_mid, &br.base, &br.watched);
        // off the firing side by more than the function's departure bound (its tolerance, as
        // firing needs past it, unless the system resolves it finer: a force of −c t³ computed
        // as +1e-20 at a tiny probe is no departure; a gap 1e-11 m up is)
        let departed = (0..n).filter(|&i| br.fired[i]).all(|i| match br.dir[i] {
            d if d < 0 => br.g_mid[i] > br.departure[i],
            d if d > 0 => br.g_mid[i] < -br.departure[i],
            _ => false,
        });
        if departed {
            br.fired.iter_mut().for_each(|f| *f = false);
            let earlier = (0..n).any(|i| crosses(br.dir[i], br.g_lo[i], br.g_mid[i]));
            return Ok(Some(if earlier {
                br.g_hi.copy_from_slice(&br.g_mid);
                (t_lo, t_p)
            } else {
                br.g_lo.copy_from_slice(&br.g_mid);
                (t_p, t_hi)
            }));
        }
        k += 1;
    }
}

/// `v[i] -= base[i]` for the watched functions.
fn shift(v: &mut [f64], base: &[f64], watched: &[bool]) {
    for ((x, b), w) in v.iter_mut().zip(base).zip(watched) {
        if *w {
            *x -= b;
        }
    }
}

/// Called without a sign change: fires nothing (the caller checked there is one).
fn unreachable_bracket(br: &mut Bracket) {
    br.fired.iter_mut().for_each(|f| *f = false);
}
