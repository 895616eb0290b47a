//! The integrator of a scene, in one place: the validated [`Integrator`] made from the scene's
//! [`IntegratorSpec`] (the only place user-facing defaults are filled in), its description in a
//! recording ([`Integrator::describe`]), and the stepper it runs ([`Integrator::integrate`]).
//! The methods themselves are robot-agnostic and live in [`crate::integrate`] (references
//! there).

use schemas::IntegratorInfo;

use crate::error::{short, SceneError};
use crate::integrate::{
    integrate_hybrid, integrate_sampled_within, ArkImex, EventSettings, HybridSystem, DormandPrince45, IntegrateError, OdeJacobian, Rk4, Rodas, RodasMethod, Rosenbrock, SplitSystem, Stats,
    StepControl, StepSizeControl, Stepper,
};
use crate::scene::spec::{AdaptiveSpec, IntegratorSpec, RosenbrockSpec, StepSizeControlSpec};

/// Most step attempts of a run when a scene does not say (`max_steps`).
pub const DEFAULT_MAX_STEPS: u64 = 100_000_000;

/// A validated integrator and its settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
    /// Classical Runge–Kutta, fixed `step`, s.
    Rk4 { step: f64 },
    /// Dormand–Prince 5(4).
    Dopri45(StepControl),
    /// ROS34PW2 with the arm's structured Jacobian, refreshed every `jacobian_reuse` steps.
    Rosenbrock { control: StepControl, jacobian_reuse: usize, step_size_control: StepSizeControl },
    /// ARK4(3)6L[2]SA, the armature circuits implicit.
    Imex(StepControl),
    /// RODAS5P or RODAS4 with the exact Jacobian (finite differences over the q, q̇, i block),
    /// refreshed every `jacobian_reuse` steps.
    Rodas { method: RodasMethod, control: StepControl, jacobian_reuse: usize, step_size_control: StepSizeControl },
}

impl Integrator {
    /// Validates `spec` of a scene read from `file` whose runs last `duration` s and are
    /// recorded every `output_interval` s. Defaults: `h_max` = the output interval (no step
    /// skips over a sample), `max_steps` = [`DEFAULT_MAX_STEPS`], `jacobian_reuse` = 1,
    /// `step_size_control` = elementary.
    pub fn from_spec(spec: &IntegratorSpec, file: &str, duration: f64, output_interval: f64) -> Result<Self, SceneError> {
        let err = |field: &str, value: &dyn std::fmt::Display, why: &str| SceneError::new(file, format!("integrator.{field}"), value, why);
        let control = |rtol: f64, atol: f64, h_max: Option<f64>, max_steps: Option<u64>| -> Result<StepControl, SceneError> {
            if !(rtol.is_finite() && (1e-14..1.0).contains(&rtol)) {
                return Err(err("rtol", &rtol, "must be in [1e-14, 1)"));
            }
            if !(atol.is_finite() && atol > 0.0) {
                return Err(err("atol", &atol, "must be > 0"));
            }
            let h_max = h_max.unwrap_or(output_interval);
            if !(h_max.is_finite() && h_max > 0.0) {
                return Err(err("h_max", &h_max, "must be > 0 s"));
            }
            let max_steps = max_steps.unwrap_or(DEFAULT_MAX_STEPS);
            if max_steps == 0 {
                return Err(err("max_steps", &max_steps, "must be >= 1"));
            }
            // no step is longer than h_max: a run needs at least duration / h_max of them
            let fewest = (duration / h_max).ceil();
            if fewest > max_steps as f64 {
                return Err(err(
                    "h_max",
                    &short(h_max),
                    &format!("needs at least {fewest:.3e} steps in duration = {duration} s, more than max_steps = {max_steps} (h_max defaults to the output interval)"),
                ));
            }
            Ok(StepControl { rtol, atol, h_init: None, h_max, h_min: 0.0, max_steps })
        };
        Ok(match spec {
            IntegratorSpec::Rk4(s) => {
                if !(s.step.is_finite() && s.step > 0.0 && s.step <= duration) {
                    return Err(err("step", &s.step, "must be > 0 s and <= duration"));
                }
                let steps = (duration / s.step).ceil();
                if steps > DEFAULT_MAX_STEPS as f64 {
                    return Err(err(
                        "step",
                        &short(s.step),
                        &format!("gives {steps:.3e} steps in duration = {duration} s, more than the limit of {DEFAULT_MAX_STEPS}; use a larger step, or an adaptive method"),
                    ));
                }
                Integrator::Rk4 { step: s.step }
            }
            IntegratorSpec::Dopri45(AdaptiveSpec { rtol, atol, h_max, max_steps }) => {
                Integrator::Dopri45(control(*rtol, *atol, *h_max, *max_steps)?)
            }
            IntegratorSpec::Imex(AdaptiveSpec { rtol, atol, h_max, max_steps }) => {
                Integrator::Imex(control(*rtol, *atol, *h_max, *max_steps)?)
            }
            IntegratorSpec::Rosenbrock(s) | IntegratorSpec::Rodas5p(s) | IntegratorSpec::Rodas4(s) => {
                let RosenbrockSpec { rtol, atol, h_max, max_steps, jacobian_reuse, step_size_control } = s;
                let step_size_control = match step_size_control {
                    None | Some(StepSizeControlSpec::Elementary) => StepSizeControl::Elementary,
                    Some(StepSizeControlSpec::Predictive) => StepSizeControl::Predictive,
                };
                let reuse = jacobian_reuse.unwrap_or(1);
                if reuse == 0 {
                    return Err(err("jacobian_reuse", &reuse, "must be >= 1"));
                }
                let jacobian_reuse = usize::try_from(reuse).unwrap_or(usize::MAX);
                let control = control(*rtol, *atol, *h_max, *max_steps)?;
                match spec {
                    IntegratorSpec::Rodas5p(_) => Integrator::Rodas { method: RodasMethod::Rodas5P, control, jacobian_reuse, step_size_control },
                    IntegratorSpec::Rodas4(_) => Integrator::Rodas { method: RodasMethod::Rodas4, control, jacobian_reuse, step_size_control },
                    _ => Integrator::Rosenbrock { control, jacobian_reuse, step_size_control },
                }
            }
        })
    }

    /// Why this method cannot run a scene run with a frictional rigid contact, said before it
    /// starts (issue 23 item 3), or `None`. The explicit methods (dopri45, rk4, and imex, whose
    /// mechanics are explicit) cannot integrate a slow slip: below
    /// [`crate::dynamics::contact::forward::SLIP_DIRECTION_SPEED`] (1e-6 m/s) the friction's
    /// direction turns at a rate of about `μ f_n / (m_eff v_s)` (~1e7 /s for the paper arm's
    /// elbow), so their stability bound asks for steps of ~1e-7 s there: dopri45 stops at the
    /// first slip from rest with "the problem is stiff" (the paper's two- and one-elbow runs at
    /// 0.245 s and 0.716 s, at any tolerance). rodas5p (or rodas4) steps through it.
    pub fn frictional_limit(&self, friction: impl IntoIterator<Item = f64>) -> Option<String> {
        let explicit = matches!(self, Integrator::Rk4 { .. } | Integrator::Dopri45(_) | Integrator::Imex(_));
        let mu = friction.into_iter().fold(0.0, f64::max);
        (explicit && mu > 0.0).then(|| {
            format!(
                "{} cannot integrate a slow frictional slip (a rigid contact with friction {mu}): below 1e-6 m/s the friction's direction turns at ~mu f_n / (m v_s), about 1e7 /s, so an explicit method needs steps of ~1e-7 s there and stops at the first slip from rest (\"the problem is stiff\"); use rodas5p",
                self.method()
            )
        })
    }

    /// The method's name in scenes.
    pub fn method(&self) -> &'static str {
        match self {
            Integrator::Rk4 { .. } => "rk4",
            Integrator::Dopri45(_) => "dopri45",
            Integrator::Rosenbrock { .. } => "rosenbrock",
            Integrator::Imex(_) => "imex",
            Integrator::Rodas { method: RodasMethod::Rodas5P, .. } => "rodas5p",
            Integrator::Rodas { method: RodasMethod::Rodas4, .. } => "rodas4",
        }
    }

    /// As recorded in a recording's `run` record.
    pub fn describe(&self) -> IntegratorInfo {
        let info = |method: &str, c: Option<&StepControl>| IntegratorInfo {
            method: method.into(),
            step: None,
            rtol: c.map(|c| c.rtol),
            atol: c.map(|c| c.atol),
            h_max: c.map(|c| c.h_max),
            max_steps: c.map(|c| c.max_steps),
            jacobian_reuse: None,
        };
        // "name (what)", the step-size control named when it is not the default
        let named = |name: &str, what: &str, control: StepSizeControl| match control {
            StepSizeControl::Elementary => format!("{name} ({what})"),
            StepSizeControl::Predictive => format!("{name} ({what}, predictive step-size control)"),
        };
        match self {
            Integrator::Rk4 { step } => IntegratorInfo { step: Some(*step), ..info("rk4", None) },
            Integrator::Dopri45(c) => info("dopri45", Some(c)),
            Integrator::Rosenbrock { control, jacobian_reuse, step_size_control } => IntegratorInfo {
                jacobian_reuse: Some(*jacobian_reuse as u64),
                ..info(&named("rosenbrock", "ROS34PW2, structured Jacobian", *step_size_control), Some(control))
            },
            Integrator::Imex(c) => info("imex (ARK4(3)6L[2]SA, armature circuits implicit)", Some(c)),
            Integrator::Rodas { method, control, jacobian_reuse, step_size_control } => IntegratorInfo {
                jacobian_reuse: Some(*jacobian_reuse as u64),
                ..info(
                    &match method {
                        RodasMethod::Rodas5P => named("rodas5p", "RODAS5P, exact Jacobian by differences", *step_size_control),
                        RodasMethod::Rodas4 => named("rodas4", "RODAS4, exact Jacobian by differences", *step_size_control),
                    },
                    Some(control),
                )
            },
        }
    }

    /// Integrates `sys` from `y0` at t = 0 to `t_end` with this method and hands the solution to
    /// `on_sample` on the grid `k dt_out` (dense output, independent of the steps), stopping
    /// with [`crate::integrate::IntegrateError::OutOfTime`] once the wall clock passes
    /// `deadline` (or [`crate::integrate::IntegrateError::TooSlow`] when its pace cannot make it).
    pub fn integrate<S: OdeJacobian + SplitSystem>(
        &self,
        sys: &mut S,
        y0: &[f64],
        t_end: f64,
        dt_out: f64,
        deadline: Option<crate::integrate::Deadline>,
        on_sample: impl FnMut(f64, &[f64]) -> Result<(), S::Error>,
    ) -> Result<Stats, IntegrateError<S::Error>> {
        let mut stepper: Box<dyn Stepper<S>> = self.stepper(y0.len());
        integrate_sampled_within(stepper.as_mut(), sys, 0.0, y0, t_end, dt_out, deadline, on_sample)
    }

    /// The step control's tolerances `(rtol, atol)` of an adaptive method (`None` for rk4's
    /// fixed step): a step is accepted with each component's error within about
    /// `atol + rtol |y_i|` (HNW I (4.11)).
    pub fn tolerances(&self) -> Option<(f64, f64)> {
        match *self {
            Integrator::Rk4 { .. } => None,
            Integrator::Dopri45(c) | Integrator::Imex(c) | Integrator::Rosenbrock { control: c, .. } | Integrator::Rodas { control: c, .. } => Some((c.rtol, c.atol)),
        }
    }

    /// The stepper of this method for a system of dimension `dim`.
    fn stepper<S: OdeJacobian + SplitSystem>(&self, dim: usize) -> Box<dyn Stepper<S>> {
        match *self {
            Integrator::Rk4 { step } => Box::new(Rk4::new(dim, step)),
            Integrator::Dopri45(c) => Box::new(DormandPrince45::new(dim, c)),
            Integrator::Rosenbrock { control, jacobian_reuse, step_size_control } => {
                Box::new(Rosenbrock::new(dim, control).with_jacobian_reuse(jacobian_reuse).with_step_size_control(step_size_control))
            }
            Integrator::Imex(c) => Box::new(ArkImex::new(dim, c)),
            Integrator::Rodas { method, control, jacobian_reuse, step_size_control } => {
                Box::new(Rodas::new(dim, control).with_method(method).with_jacobian_reuse(jacobian_reuse).with_step_size_control(step_size_control))
            }
        }
    }

    /// [`Integrator::integrate`] for a [`HybridSystem`] (rigid or compliant contacts): the
    /// same stepper driven by [`integrate_hybrid`] (events located on its dense output, the
    /// system's modes switched there, the stepper restarted), with `settings`. `on_sample`
    /// gets the system too (its modes and its event log). For rk4 the event times are those
    /// of its cubic Hermite interpolant (O(h⁴)), and a sign change and back within one step
    /// goes unseen (`integrate/events.rs`).
    #[allow(clippy::too_many_arguments)]
    pub fn integrate_hybrid<S: OdeJacobian + SplitSystem + HybridSystem>(
        &self,
        sys: &mut S,
        y0: &[f64],
        t_end: f64,
        dt_out: f64,
        deadline: Option<crate::integrate::Deadline>,
        settings: EventSettings,
        on_sample: impl FnMut(f64, &[f64], &mut S) -> Result<(), S::Error>,
    ) -> Result<Stats, IntegrateError<S::Error>> {
        let mut stepper: Box<dyn Stepper<S>> = self.stepper(y0.len());
        integrate_hybrid(stepper.as_mut(), sys, 0.0, y0, t_end, dt_out, deadline, settings, on_sample)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(json: &str) -> IntegratorSpec {
        serde_json::from_str(json).unwrap()
    }

    #[test]
    fn defaults_are_filled_in_one_place() {
        let i = Integrator::from_spec(&spec(r#"{"method":"dopri45","rtol":1e-10,"atol":1e-12}"#), "s.json", 5.0, 1e-3).unwrap();
        assert_eq!(i, Integrator::Dopri45(StepControl { rtol: 1e-10, atol: 1e-12, h_init: None, h_max: 1e-3, h_min: 0.0, max_steps: DEFAULT_MAX_STEPS }));
        assert_eq!(DEFAULT_MAX_STEPS, 100_000_000, "the README states 10^8");
        let i = Integrator::from_spec(&spec(r#"{"method":"rosenbrock","rtol":1e-5,"atol":1e-7,"h_max":0.5}"#), "s.json", 5.0, 1e-3).unwrap();
        assert!(matches!(i, Integrator::Rosenbrock { jacobian_reuse: 1, control, step_size_control: StepSizeControl::Elementary } if control.h_max == 0.5));
        assert_eq!(i.describe().phrase(), "rosenbrock (ROS34PW2, structured Jacobian) rtol 1e-5 atol 1e-7 h_max 5e-1 jacobian_reuse 1");
        let i = Integrator::from_spec(&spec(r#"{"method":"rodas5p","rtol":1e-6,"atol":1e-8}"#), "s.json", 5.0, 1e-3).unwrap();
        assert!(matches!(i, Integrator::Rodas { method: RodasMethod::Rodas5P, jacobian_reuse: 1, control, step_size_control: StepSizeControl::Elementary } if control.h_max == 1e-3));
        assert_eq!(i.method(), "rodas5p");
        assert_eq!(i.describe().phrase(), "rodas5p (RODAS5P, exact Jacobian by differences) rtol 1e-6 atol 1e-8 h_max 1e-3 jacobian_reuse 1");
        let i = Integrator::from_spec(&spec(r#"{"method":"rodas4","rtol":1e-6,"atol":1e-8,"jacobian_reuse":3}"#), "s.json", 5.0, 1e-3).unwrap();
        assert!(matches!(i, Integrator::Rodas { method: RodasMethod::Rodas4, jacobian_reuse: 3, .. }));
        let i = Integrator::from_spec(&spec(r#"{"method":"rodas5p","rtol":1e-8,"atol":1e-10,"step_size_control":"predictive"}"#), "s.json", 5.0, 1e-3).unwrap();
        assert!(matches!(i, Integrator::Rodas { step_size_control: StepSizeControl::Predictive, .. }));
        assert!(i.describe().phrase().contains("predictive step-size control"));
        assert!(serde_json::from_str::<IntegratorSpec>(r#"{"method":"rodas5p","rtol":1e-8,"atol":1e-10,"step_size_control":"pi"}"#).unwrap_err().to_string().contains("unknown variant `pi`"));
    }

    #[test]
    fn each_method_accepts_only_its_own_settings() {
        let bad = |json: &str| serde_json::from_str::<IntegratorSpec>(json).unwrap_err().to_string();
        assert!(bad(r#"{"method":"dopri45","rtol":1e-6,"atol":1e-8,"step":1e-3}"#).contains("unknown field `step`"));
        assert!(bad(r#"{"method":"imex","rtol":1e-6,"atol":1e-8,"jacobian_reuse":2}"#).contains("unknown field `jacobian_reuse`"));
        assert!(bad(r#"{"method":"rk4","step":1e-3,"rtol":1e-6}"#).contains("unknown field `rtol`"));
        assert!(bad(r#"{"method":"rk4"}"#).contains("missing field `step`"));
        assert!(bad(r#"{"method":"euler","step":1e-3}"#).contains("unknown variant `euler`"));
        // the serde form is the scene's: the tag first, unset settings left out
        let text = serde_json::to_string(&spec(r#"{"atol":1e-12,"method":"dopri45","rtol":1e-10}"#)).unwrap();
        assert_eq!(text, r#"{"method":"dopri45","rtol":1e-10,"atol":1e-12}"#);
    }

    #[test]
    fn out_of_range_settings_name_field_and_value() {
        let msg = |json: &str| Integrator::from_spec(&spec(json), "s.json", 5.0, 1e-3).unwrap_err().to_string();
        assert!(msg(r#"{"method":"dopri45","rtol":0,"atol":1e-8}"#).contains("integrator.rtol` = 0"));
        assert!(msg(r#"{"method":"dopri45","rtol":1e-6,"atol":-1}"#).contains("integrator.atol` = -1"));
        assert!(msg(r#"{"method":"imex","rtol":1e-6,"atol":1e-8,"max_steps":0}"#).contains("integrator.max_steps` = 0"));
        assert!(msg(r#"{"method":"rosenbrock","rtol":1e-6,"atol":1e-8,"jacobian_reuse":0}"#).contains("jacobian_reuse` = 0"));
        assert!(msg(r#"{"method":"rodas5p","rtol":1e-6,"atol":1e-8,"jacobian_reuse":0}"#).contains("jacobian_reuse` = 0"));
        assert!(msg(r#"{"method":"rodas4","rtol":2,"atol":1e-8}"#).contains("integrator.rtol` = 2"));
        assert!(msg(r#"{"method":"rk4","step":6}"#).contains("integrator.step` = 6"));
        for method in ["dopri45", "imex", "rosenbrock", "rodas5p", "rodas4"] {
            let m = msg(&format!(r#"{{"method":"{method}","rtol":1e-6,"atol":1e-8,"max_steps":0}}"#));
            assert!(m.contains("integrator.max_steps` = 0: must be >= 1"), "{m}");
        }
    }

    /// A step so small that the run needs more steps than its budget is refused up front,
    /// with the count: rk4's fixed step, an adaptive method's h_max (default: the output
    /// interval) against its max_steps.
    #[test]
    fn too_many_steps_are_refused_before_the_run() {
        let msg = |json: &str| Integrator::from_spec(&spec(json), "s.json", 5.0, 1e-3).unwrap_err().to_string();
        assert_eq!(
            msg(r#"{"method":"rk4","step":1e-12}"#),
            "s.json: field `integrator.step` = 1e-12: gives 5.000e12 steps in duration = 5 s, more than the limit of 100000000; use a larger step, or an adaptive method"
        );
        Integrator::from_spec(&spec(r#"{"method":"rk4","step":5e-8}"#), "s.json", 5.0, 1e-3).expect("exactly 10^8 steps");
        let m = msg(r#"{"method":"dopri45","rtol":1e-6,"atol":1e-8,"h_max":1e-300}"#);
        assert!(m.contains("integrator.h_max` = 1e-300: needs at least 5.000e300 steps") && m.contains("max_steps = 100000000"), "{m}");
        let m = msg(r#"{"method":"imex","rtol":1e-6,"atol":1e-8,"max_steps":4999}"#);
        assert!(m.contains("integrator.h_max` = 0.001: needs at least 5.000e3 steps") && m.contains("defaults to the output interval"), "{m}");
        Integrator::from_spec(&spec(r#"{"method":"imex","rtol":1e-6,"atol":1e-8,"max_steps":5000}"#), "s.json", 5.0, 1e-3).unwrap();
    }
}
