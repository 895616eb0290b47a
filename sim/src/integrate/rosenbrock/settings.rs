//! Settings of [`super::Rosenbrock`].

use super::super::adaptive::Control;
use super::super::SettingsError;

/// Tolerances, step-size controller and Jacobian reuse for [`super::Rosenbrock`].
///
/// Defaults are those of [`Default`]; the controller constants follow Hairer's `ros4.f`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RosenbrockSettings {
    /// Relative tolerance, >= 0.
    pub rtol: f64,
    /// Absolute tolerance (same unit as y), > 0.
    pub atol: f64,
    /// First step to try; `None` uses Hairer's starting-step algorithm (one extra evaluation).
    pub h_init: Option<f64>,
    /// Largest step, > 0 (may be infinite).
    pub h_max: f64,
    /// Smallest step before giving up with `StepSizeTooSmall`, >= 0.
    pub h_min: f64,
    /// Most step attempts (accepted + rejected) between `init` and `TooManySteps`, > 0.
    pub max_steps: usize,
    /// Safety factor on the predicted optimal step, in (0, 1].
    pub safety: f64,
    /// Lower bound on `h_new / h`, in (0, 1].
    pub fac_min: f64,
    /// Upper bound on `h_new / h`, >= 1.
    pub fac_max: f64,
    /// Accepted steps between Jacobian evaluations, >= 1 (1: a fresh `J` every step). The
    /// Jacobian is also refreshed after a rejection if it was not evaluated at the current
    /// point.
    pub jacobian_reuse: usize,
}

impl Default for RosenbrockSettings {
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
            fac_max: 6.0,
            jacobian_reuse: 1,
        }
    }
}

impl RosenbrockSettings {
    pub(super) fn control(&self) -> Control {
        Control {
            rtol: self.rtol,
            atol: self.atol,
            h_init: self.h_init,
            h_max: self.h_max,
            h_min: self.h_min,
            max_steps: self.max_steps,
            safety: self.safety,
            fac_min: self.fac_min,
            fac_max: self.fac_max,
        }
    }

    /// Checks every field's range (see the field docs).
    ///
    /// # Errors
    /// The first field out of range, with its value and the requirement.
    pub fn validate(&self) -> Result<(), SettingsError> {
        self.control().validate("RosenbrockSettings")?;
        if self.jacobian_reuse == 0 {
            return Err(SettingsError {
                settings: "RosenbrockSettings",
                field: "jacobian_reuse",
                value: 0.0,
                requirement: ">= 1",
            });
        }
        Ok(())
    }
}
