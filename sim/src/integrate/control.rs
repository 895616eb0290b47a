//! The step-control settings of the adaptive steppers ([`StepControl`]), their validation
//! ([`SettingsError`]), and the per-method controller constants ([`Controller`]).
//!
//! The split follows Hairer's codes (`dopri5.f`, `ros4.f`): the user states tolerances and
//! limits (`RTOL`, `ATOL`, `H`, `HMAX`, `NMAX`); the controller's safety factor and bounds on
//! `h_new / h` (`SAFE`, `FAC1`, `FAC2`) are properties of each method, fixed to the values of
//! its reference code. References: HNW I = Hairer, Nørsett & Wanner, *Solving Ordinary
//! Differential Equations I*, 2nd ed., Springer 1993, §II.4 (error norm, controller (4.13),
//! starting step); HNW II = Hairer & Wanner, *Solving Ordinary Differential Equations II*, 2nd
//! ed., Springer 1996, §IV.8 (8.21): Gustafsson's predictive controller ([`StepSizeControl`],
//! K. Gustafsson, "Control-theoretic techniques for stepsize selection in implicit Runge–Kutta
//! methods", ACM TOMS 20 (1994) 496–517; coded as in Hairer's `radau5.f`, `IWORK(8) = 1`).
//!
//! [`StepControl`] has no `Default`: the library imposes no limit unless asked
//! ([`StepControl::new`]); user-facing defaults (a step budget, `h_max` = the output interval)
//! belong to the layer that reads the user's settings.

use std::fmt;

/// An out-of-range setting: a field of [`StepControl`], or a stepper's own setting (e.g.
/// [`super::Rosenbrock::try_with_jacobian_reuse`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SettingsError {
    /// Where the field lives: `"StepControl"`, or the stepper's name (e.g. `"Rosenbrock"`).
    pub settings: &'static str,
    /// Field name.
    pub field: &'static str,
    /// Offending value (integers converted to f64).
    pub value: f64,
    /// What the value must satisfy.
    pub requirement: &'static str,
}

impl fmt::Display for SettingsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "invalid {}.{} = {}: must be {}",
            self.settings, self.field, self.value, self.requirement
        )
    }
}

impl std::error::Error for SettingsError {}

/// Tolerances and step-size limits of an adaptive stepper ([`super::DormandPrince45`],
/// [`super::Rosenbrock`], [`super::ArkImex`]); same meaning for all three.
///
/// A step is accepted when its error estimate `e` satisfies `||e|| <= 1` in the RMS norm
/// with weights `atol + rtol max(|y_i|, |y_new_i|)` (HNW I (4.11)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepControl {
    /// Relative tolerance, >= 0.
    pub rtol: f64,
    /// Absolute tolerance (same unit as y), > 0.
    pub atol: f64,
    /// First step to try, s; `None` uses Hairer's starting-step algorithm (HNW I §II.4; one
    /// extra evaluation of `f`).
    pub h_init: Option<f64>,
    /// Largest step, s, > 0 (may be infinite).
    pub h_max: f64,
    /// Smallest step, s, before giving up with `StepSizeTooSmall`, >= 0 (a final step
    /// shortened to land on `t_stop` may be smaller).
    pub h_min: f64,
    /// Most step attempts (accepted + rejected) between `init` and `TooManySteps`, > 0.
    pub max_steps: u64,
}

impl StepControl {
    /// `rtol`/`atol` with no other limit: `h_init` `None` (Hairer's starting step),
    /// `h_max = ∞`, `h_min = 0`, `max_steps = u64::MAX`. Not validated; see
    /// [`StepControl::validate`].
    pub fn new(rtol: f64, atol: f64) -> Self {
        Self {
            rtol,
            atol,
            h_init: None,
            h_max: f64::INFINITY,
            h_min: 0.0,
            max_steps: u64::MAX,
        }
    }

    /// Checks every field's range (see the field docs); the steppers' `try_new` call it.
    ///
    /// # Errors
    /// The first field out of range, with its value and the requirement
    /// (`settings = "StepControl"`).
    pub fn validate(&self) -> Result<(), SettingsError> {
        let bad = |field, value, requirement| {
            Err(SettingsError {
                settings: "StepControl",
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
        Ok(())
    }
}

/// The elementary step-size controller of HNW I (4.13), with one method's constants (from its
/// reference code, not user settings): `h_new / h = safety err^(-expo)`, bounded to
/// `[fac_min, fac_max]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Controller {
    /// Safety factor on the predicted optimal step, in (0, 1].
    pub safety: f64,
    /// Lower bound on `h_new / h`, in (0, 1]; also the factor applied after a non-finite
    /// stage.
    pub fac_min: f64,
    /// Upper bound on `h_new / h`, >= 1.
    pub fac_max: f64,
}

/// How an adaptive stepper chooses the step after an accepted one (the rejected ones always
/// use the elementary rule). A user setting, as `radau5.f`'s `IWORK(8)`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum StepSizeControl {
    /// The elementary controller of HNW I (4.13) ([`Controller::factor`]): the step the last
    /// error predicts, as Hairer's `rodas.f`.
    #[default]
    Elementary,
    /// Gustafsson's predictive controller (HNW II §IV.8 (8.21), `radau5.f`): after the second
    /// accepted step since a (re)start, the smaller of the elementary step and the one
    /// extrapolated from the last two accepted steps' sizes and errors
    /// ([`Controller::predictive_factor`]). It damps the elementary rule's growth where the
    /// error grows faster than `h^(q+1)` (the pattern "grow, reject, shrink").
    Predictive,
}

impl Controller {
    /// Gustafsson's predictive factor `h_new / h` after an accepted step `h` with scaled error
    /// `err`, the accepted step before it having had size `h_acc` and error `err_acc`
    /// (HNW II §IV.8 (8.21); `radau5.f` keeps `err_acc >= 1e-2`, which the caller does):
    /// `safety (h / h_acc) (err_acc / err^2)^expo`, `expo = 1/(q+1)` for an error estimate of
    /// order `q`, bounded to `[fac_min, fac_max]`; a NaN or infinite `err` gives `fac_min`,
    /// `err = 0` gives `fac_max`.
    pub fn predictive_factor(&self, err: f64, expo: f64, h: f64, h_acc: f64, err_acc: f64) -> f64 {
        let finite = err < f64::INFINITY; // false for inf and NaN
        if !finite {
            return self.fac_min;
        }
        if err == 0.0 {
            return self.fac_max;
        }
        (self.safety * (h / h_acc) * (err_acc / (err * err)).powf(expo)).clamp(self.fac_min, self.fac_max)
    }

    /// Step-size factor `h_new / h` for the scaled error `err` of a method whose error
    /// estimate is `O(h^(1/expo))` (HNW I (4.13)): `safety err^(-expo)` bounded to
    /// `[fac_min, fac_max]`; a NaN or infinite `err` gives `fac_min`.
    pub fn factor(&self, err: f64, expo: f64) -> f64 {
        let finite = err < f64::INFINITY; // false for inf and NaN
        if !finite {
            return self.fac_min;
        }
        if err == 0.0 {
            return self.fac_max;
        }
        (self.safety * err.powf(-expo)).clamp(self.fac_min, self.fac_max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn controller_factor_is_bounded() {
        let c = Controller {
            safety: 0.9,
            fac_min: 0.2,
            fac_max: 6.0,
        };
        assert_eq!(c.factor(0.0, 1.0 / 3.0), 6.0);
        assert_eq!(c.factor(f64::NAN, 1.0 / 3.0), 0.2);
        assert_eq!(c.factor(f64::INFINITY, 1.0 / 3.0), 0.2);
        assert!((c.factor(1.0, 1.0 / 3.0) - 0.9).abs() < 1e-15);
        assert!((c.factor(8.0, 1.0 / 3.0) - 0.45).abs() < 1e-15);
    }

    /// HNW II (8.21) on a known sequence of accepted steps: `h_{n+1} = safety h_n
    /// (1/err_{n+1})^(1/k) (h_n/h_{n-1}) (err_n/err_{n+1})^(1/k)` with `k = q + 1 = 5`
    /// (RODAS5P's embedded order 4). Steps 1e-3, 2e-3 with errors 0.3, 0.6: the elementary
    /// rule would grow by 0.9 0.6^(-1/5) = 0.9968 (`radau5.f`'s `quot`), the predictive one by
    /// 0.9 2 (0.3 / 0.36)^(1/5) = 1.7355 — here the larger, so `radau5.f` keeps the
    /// elementary 0.9968 (the smaller step); with the errors the other way round (0.6, 0.3:
    /// an error falling as h grew) 0.9 (2) (0.6/0.09)^(1/5) = 2.6306, against the elementary
    /// 1.1450. The old code had no such factor: this test does not compile on it.
    #[test]
    fn predictive_factor_is_gustafssons_formula() {
        let c = Controller { safety: 0.9, fac_min: 0.2, fac_max: 6.0 };
        let k = 5.0;
        let hnw = |h_n: f64, h_prev: f64, err_n: f64, err_new: f64| 0.9 * (1.0 / err_new).powf(1.0 / k) * (h_n / h_prev) * (err_n / err_new).powf(1.0 / k);
        for (h_prev, h_n, err_n, err_new) in [(1e-3, 2e-3, 0.3, 0.6), (1e-3, 2e-3, 0.6, 0.3), (1.5e-3, 1e-3, 0.05, 0.8), (2e-3, 2e-3, 0.5, 0.5)] {
            let want = hnw(h_n, h_prev, err_n, err_new);
            let got = c.predictive_factor(err_new, 1.0 / k, h_n, h_prev, err_n);
            assert!((got - want).abs() <= 1e-14 * want, "{got} vs {want}");
        }
        assert!((c.predictive_factor(0.6, 0.2, 2e-3, 1e-3, 0.3) - 1.735_5).abs() < 1e-4);
        assert!((c.factor(0.6, 0.2) - 0.996_8).abs() < 1e-4);
        // equal steps and errors: (8.21) reduces to the elementary rule
        assert!((c.predictive_factor(0.5, 0.2, 2e-3, 2e-3, 0.5) - c.factor(0.5, 0.2)).abs() < 1e-15);
        // bounds and non-finite errors as the elementary rule
        assert_eq!(c.predictive_factor(1e-12, 0.2, 1.0, 1e-3, 1.0), 6.0);
        assert_eq!(c.predictive_factor(0.99, 0.2, 1e-3, 1.0, 1e-2), 0.2);
        assert_eq!(c.predictive_factor(f64::NAN, 0.2, 1.0, 1.0, 1.0), 0.2);
        assert_eq!(c.predictive_factor(0.0, 0.2, 1.0, 1.0, 1.0), 6.0);
    }

    #[test]
    fn step_control_new_sets_no_limit_and_validates() {
        let c = StepControl::new(1e-6, 1e-9);
        assert_eq!((c.rtol, c.atol, c.h_init), (1e-6, 1e-9, None));
        assert_eq!(
            (c.h_max, c.h_min, c.max_steps),
            (f64::INFINITY, 0.0, u64::MAX)
        );
        assert_eq!(c.validate(), Ok(()));
        let e = StepControl { max_steps: 0, ..c }
            .validate()
            .expect_err("max_steps 0");
        assert_eq!(
            (e.settings, e.field, e.value),
            ("StepControl", "max_steps", 0.0)
        );
        assert_eq!(
            e.to_string(),
            "invalid StepControl.max_steps = 0: must be > 0"
        );
    }
}
