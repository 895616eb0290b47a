//! One run of a scene: integrate from t = 0 to the scene's duration and hand the outputs,
//! sampled on a fixed grid (the scene's output rate) independent of the solver's steps, to a
//! sink (the recorder, or a test). Knows nothing about the recording format.

use crate::error::RunError;
use crate::integrate::{IntegrateError, Stats};
use crate::scene::{Run, Scene};
use crate::ode::{ArmSystem, Outputs};

/// What a run reports besides its samples.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunReport {
    pub stats: Stats,
    pub samples: usize,
    /// The last sample.
    pub last: Outputs,
}

fn map_err(e: IntegrateError<RunError>, names: &dyn Fn(usize) -> String) -> RunError {
    match e {
        IntegrateError::Rhs(e) | IntegrateError::Sample { source: e, .. } => e,
        IntegrateError::StepSizeTooSmall { t, h } => RunError::StepSizeTooSmall { t, h },
        IntegrateError::SingularMatrix { t, h } => RunError::SingularIterationMatrix { t, h },
        IntegrateError::NonFiniteState { t, index } => RunError::NonFiniteState { t, index, name: names(index) },
        IntegrateError::TooManySteps { t, max_steps } => {
            RunError::TooManySteps { t, max_steps: usize::try_from(max_steps).unwrap_or(usize::MAX) }
        }
        IntegrateError::InvalidOutputGrid { t0, t_end, dt_out } => RunError::Dynamics(crate::error::DynamicsError::NonFinite {
            t: t0,
            what: format!("the output grid (t_end = {t_end}, dt = {dt_out})"),
        }),
    }
}

/// Integrate `run` of `scene`, calling `sink` at every output time with the derived outputs.
pub fn simulate(
    scene: &Scene,
    run: &Run,
    mut sink: impl FnMut(&Outputs) -> Result<(), RunError>,
) -> Result<RunReport, RunError> {
    let mut sys = ArmSystem::new(scene, run);
    let y0 = sys.initial_state();
    let dt_out = 1.0 / scene.output_rate;
    let joints = scene.model.joint_names();
    let layout = sys.layout();
    let names = move |k: usize| layout.name(k, &joints);
    let mut out = Outputs::default();
    let mut samples = 0usize;
    // a second system evaluates the outputs, so the stepper's system keeps its scratch
    let mut probe = ArmSystem::new(scene, run);
    let mut on_sample = |t: f64, y: &[f64]| -> Result<(), RunError> {
        probe.outputs(t, y, &mut out)?;
        samples += 1;
        sink(&out)
    };
    let stats = scene.integrator.integrate(&mut sys, &y0, scene.duration, dt_out, &mut on_sample)
    .map_err(|e| map_err(e, &names))?;
    Ok(RunReport { stats, samples, last: out })
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
    mut progress: impl FnMut(f64),
) -> Result<FileReport, RunError> {
    let mut rec = crate::record::Recorder::create(path, scene, run)?;
    let result = simulate(scene, run, |o| {
        progress(o.t);
        rec.record(o)
    });
    match result {
        Ok(report) => {
            let path = rec.finish(Ok(&report.stats))?;
            Ok(FileReport { path, report })
        }
        Err(e @ RunError::Recording { .. }) => Err(e),
        Err(e) => {
            rec.finish(Err(&e))?;
            Err(e)
        }
    }
}
