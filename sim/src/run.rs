//! One run of a scene: integrate from t = 0 to the scene's duration and hand the outputs,
//! sampled on a fixed grid (the scene's output rate) independent of the solver's steps, to a
//! sink (the recorder, or a test). Knows nothing about the recording format.

use std::time::{Duration, Instant};

use crate::error::{DynamicsError, RunError};
use crate::limits::DEFAULT_MAX_WALL_TIME;
use crate::integrate::{IntegrateError, Stats};
use crate::scene::{Run, Scene};
use crate::joint_limits::{LimitMonitor, LimitsSummary};
use crate::ode::{ArmSystem, OutputLevel, Outputs};

/// What a run reports besides its samples.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunReport {
    pub stats: Stats,
    pub samples: usize,
    /// The last sample.
    pub last: Outputs,
    /// The limits monitor's verdict (`joint_limits.rs`), when the scene monitors limits.
    pub limits: Option<LimitsSummary>,
}

/// What one run may spend besides its steps (`integrator.max_steps`, a setting of the scene):
/// wall-clock time, a setting of the command (`--max-wall-time`), since it depends on the
/// machine and not on the experiment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    pub wall_time: Duration,
    /// After this much wall time a run whose pace projects more than twice `wall_time` stops
    /// ([`RunError::TooSlow`]) rather than at its limit.
    pub judge_pace_after: Duration,
}

impl Budget {
    /// `wall_time`, the pace judged after [`crate::integrate::PACE_AFTER`].
    pub fn wall_time(wall_time: Duration) -> Self {
        Budget { wall_time, judge_pace_after: crate::integrate::PACE_AFTER }
    }
}

impl Default for Budget {
    /// [`DEFAULT_MAX_WALL_TIME`].
    fn default() -> Self {
        Budget::wall_time(DEFAULT_MAX_WALL_TIME)
    }
}

fn map_err(e: IntegrateError<RunError>, names: &dyn Fn(usize) -> String, budget: Budget, method: &'static str, max_events_at_one_time: u32) -> RunError {
    match e {
        IntegrateError::Stiff { t, h, h_lambda } => RunError::Stiff { t, h, h_lambda },
        IntegrateError::OutOfTime { t, during } => RunError::OutOfTime { t, limit_s: budget.wall_time.as_secs_f64(), method, during },
        // the budget ran out inside the system's own loop (the contact mode enumeration)
        IntegrateError::Rhs(RunError::Dynamics(DynamicsError::OutOfTime { t, during })) => {
            RunError::OutOfTime { t, limit_s: budget.wall_time.as_secs_f64(), method, during }
        }
        IntegrateError::TooSlow { t, projected_s } => RunError::TooSlow { t, projected_s, limit_s: budget.wall_time.as_secs_f64(), method },
        IntegrateError::Rhs(e) | IntegrateError::Sample { source: e, .. } => e,
        IntegrateError::StepSizeTooSmall { t, h } => RunError::StepSizeTooSmall { t, h },
        IntegrateError::SingularMatrix { t, h } => RunError::SingularIterationMatrix { t, h },
        IntegrateError::NonFiniteState { t, index } => RunError::NonFiniteState { t, index, name: names(index) },
        IntegrateError::TooManySteps { t, max_steps } => {
            RunError::TooManySteps { t, max_steps: usize::try_from(max_steps).unwrap_or(usize::MAX), method }
        }
        IntegrateError::TooManyEvents { t, max_events } => RunError::TooManyEvents { t, max_events },
        IntegrateError::Chattering { t, count, window, events } => RunError::Chattering { t, count, window, limit: max_events_at_one_time, events },
        IntegrateError::InvalidOutputGrid { t0, t_end, dt_out } => RunError::Dynamics(crate::error::DynamicsError::NonFinite {
            t: t0,
            what: format!("the output grid (t_end = {t_end}, dt = {dt_out})"),
        }),
    }
}

/// Integrate `run` of `scene`, calling `sink` at every output time with the derived outputs,
/// within the default [`Budget`].
pub fn simulate(
    scene: &Scene,
    run: &Run,
    sink: impl FnMut(&Outputs) -> Result<(), RunError>,
) -> Result<RunReport, RunError> {
    simulate_within(scene, run, Budget::default(), sink)
}

/// [`simulate`] within `budget`: past its wall time the run fails with
/// [`RunError::OutOfTime`] at the time reached.
#[allow(clippy::result_large_err)] // RunError carries schemas::Error, as in `simulate`
pub fn simulate_within(
    scene: &Scene,
    run: &Run,
    budget: Budget,
    sink: impl FnMut(&Outputs) -> Result<(), RunError>,
) -> Result<RunReport, RunError> {
    simulate_outputs(scene, run, budget, OutputLevel::Full, sink)
}

/// [`simulate_within`] with the samples' outputs evaluated at `level` only: a consumer that
/// reads the hand, the quadratures and the drift (`sim precision`) passes
/// [`OutputLevel::Kinematic`] and pays forward kinematics per sample instead of a right-hand
/// side (`ode/outputs.rs` says which quantity needs what).
#[allow(clippy::result_large_err)] // RunError carries schemas::Error, as in `simulate`
pub fn simulate_outputs(
    scene: &Scene,
    run: &Run,
    budget: Budget,
    level: OutputLevel,
    mut sink: impl FnMut(&Outputs) -> Result<(), RunError>,
) -> Result<RunReport, RunError> {
    let deadline = Instant::now()
        .checked_add(budget.wall_time)
        .map(|at| crate::integrate::Deadline { at, judge_pace_after: budget.judge_pace_after });
    let mut sys = ArmSystem::new(scene, run);
    // the system's own long loop (the contact mode enumeration) looks at the deadline too
    sys.set_watch(crate::integrate::Watch::new(deadline));
    let y0 = sys.initial_state();
    let dt_out = 1.0 / scene.output_rate;
    let joints = scene.model.joint_names();
    let layout = sys.layout();
    let names = move |k: usize| layout.name(k, &joints);
    let mut out = Outputs::default();
    let mut samples = 0usize;
    // a second system evaluates the outputs, so the stepper's system keeps its scratch
    let mut probe = ArmSystem::new(scene, run);
    // limits are monitored on the full outputs only (they need τ, i and the command)
    let mut monitor =
        if level == OutputLevel::Full { LimitMonitor::for_scene(scene, dt_out) } else { None };
    // one sample; `hybrid`: the stepper's system of an event-driven run, whose modes the probe
    // takes over first and whose event log (since the last sample) moves into the outputs
    let mut on_sample = |t: f64, y: &[f64], hybrid: Option<&mut ArmSystem<'_>>| -> Result<(), RunError> {
        match hybrid {
            Some(sys) => {
                probe.copy_modes_from(sys);
                probe.outputs_at(level, t, y, &mut out)?;
                out.events.clear();
                sys.drain_events(&mut out.events);
            }
            None => probe.outputs_at(level, t, y, &mut out)?,
        }
        samples += 1;
        if let Some(m) = monitor.as_mut() {
            m.observe(&out);
        }
        sink(&out)
    };
    let result = if sys.is_event_driven() {
        // unilateral or compliant contacts: event-driven, with the scene's `events` settings
        let cs = &scene.contact_settings;
        let settings = crate::integrate::EventSettings {
            time_tol: cs.time_tol,
            max_events: cs.max_events,
            max_events_at_one_time: cs.max_events_at_one_time,
        };
        scene.integrator.integrate_hybrid(&mut sys, &y0, scene.duration, dt_out, deadline, settings, |t, y, sys| on_sample(t, y, Some(sys)))
    } else {
        // every contact bilateral (the paper's runs): the smooth path, as before
        scene.integrator.integrate(&mut sys, &y0, scene.duration, dt_out, deadline, |t, y| on_sample(t, y, None))
    };
    let chatter_limit = scene.contact_settings.max_events_at_one_time;
    let stats = result.map_err(|e| match map_err(e, &names, budget, scene.integrator.method(), chatter_limit) {
        // the driver names event-function indices; the system knows the contacts and their
        // current modes (review F5)
        RunError::Chattering { t, count, window, limit, events } => match sys.chattering_gears(&events) {
            // only gears' functions: their stick decisions, not the contacts' (issue 26)
            Some((joints, breakaway)) => RunError::GearsChatter { t, count, window, limit, joints: joints.join(", "), breakaway },
            None => RunError::Chattering { t, count, window, limit, events: sys.describe_event_functions(&events) },
        },
        other => other,
    })?;
    Ok(RunReport { stats, samples, last: out, limits: monitor.map(|m| m.summary()) })
}

/// What `run_to_file` reports.
#[derive(Clone, Debug)]
pub struct FileReport {
    pub path: std::path::PathBuf,
    pub report: RunReport,
}

/// Run and record to `path` (written under a temporary name, renamed when complete).
/// `progress(t)` is called with the simulated time of every sample. On a numerical failure the
/// recording is closed with every sample so far and a result record saying when and why, and
/// the error is returned.
pub fn run_to_file(
    scene: &Scene,
    run: &Run,
    path: &std::path::Path,
    progress: impl FnMut(f64),
) -> Result<FileReport, RunError> {
    run_to_file_within(scene, run, path, Budget::default(), progress)
}

/// [`run_to_file`] within `budget` (a run out of time is a failure, recorded as such).
#[allow(clippy::result_large_err)] // RunError carries schemas::Error, as in `run_to_file`
pub fn run_to_file_within(
    scene: &Scene,
    run: &Run,
    path: &std::path::Path,
    budget: Budget,
    progress: impl FnMut(f64),
) -> Result<FileReport, RunError> {
    run_to_file_tapped(scene, run, path, budget, None, progress).map(|(report, _)| report)
}

/// [`run_to_file_within`], every record written also fed to `tap` ([`schemas::Tap`]: the
/// messages reach its visitor as a read of the finished file would hand them over); what the
/// tap saw comes back with a complete run.
#[allow(clippy::result_large_err)] // RunError carries schemas::Error, as in `run_to_file`
pub fn run_to_file_tapped(
    scene: &Scene,
    run: &Run,
    path: &std::path::Path,
    budget: Budget,
    tap: Option<schemas::Tap>,
    progress: impl FnMut(f64),
) -> Result<(FileReport, Option<schemas::Tapped>), RunError> {
    run_to_file_mirrored(scene, run, path, budget, tap, None, progress)
}

/// [`run_to_file_tapped`], every record written also handed to `mirror` ([`schemas::Mirror`],
/// after the tap, with the bytes written: `sim --live`); the recording does not depend on it.
#[allow(clippy::result_large_err)] // RunError carries schemas::Error, as in `run_to_file`
pub fn run_to_file_mirrored(
    scene: &Scene,
    run: &Run,
    path: &std::path::Path,
    budget: Budget,
    tap: Option<schemas::Tap>,
    mirror: Option<Box<dyn schemas::Mirror>>,
    mut progress: impl FnMut(f64),
) -> Result<(FileReport, Option<schemas::Tapped>), RunError> {
    let mut rec = crate::record::Recorder::create_mirrored(path, scene, run, tap, mirror)?;
    let result = simulate_within(scene, run, budget, |o| {
        progress(o.t);
        rec.record(o)
    });
    match result {
        Ok(report) => {
            let (path, tapped) = rec.finish(Ok(&report.stats))?;
            Ok((FileReport { path, report }, tapped))
        }
        Err(e @ RunError::Recording { .. }) => Err(e),
        Err(e) => {
            rec.finish(Err(&e))?;
            Err(e)
        }
    }
}
