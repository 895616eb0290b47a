//! Whole runs: the paper's two-elbow configuration, 5 s simulated, through `run::simulate`
//! with outputs sampled at the scene's 1 kHz but not recorded (no file).
//!
//! `cargo bench -p sim --bench runs`; results and simulated-time / wall-time factors in
//! BENCHMARKS.md.
//!
//! Ids `paper_run/<case>`:
//! - `two-elbow-dopri45`: the scene as it is (CRBA + Schur, Dormand–Prince 5(4), rtol 1e-8).
//! - `two-elbow-rk4`: CRBA + Schur, RK4 with a fixed step of 1e-4 s.
//! - `two-elbow-paper-baseline`: the paper's method, Walker–Orin mass matrix + KKT (LU of the
//!   block system) + RK4 1e-4 s.
//!
//! Before timing, each case is run once and its step counts are printed to stderr.

// the sink closures must return `sim::error::RunError`, whose size is the library's choice
#![allow(clippy::result_large_err)]

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode};
use sim::dynamics::forward::{ConstraintSolver, MassMatrixMethod};
use sim::run::simulate;
use sim::scene::spec::IntegratorSpec;
use sim::scene::Scene;

fn runs(c: &mut Criterion) {
    let paper = Scene::paper().expect("the built-in scene is valid");
    let two = paper.runs().iter().position(|r| r.contacts.len() == 2).expect("a two-elbow run");

    let rk4 = paper.vary(|s| s.integrator = IntegratorSpec::rk4(1e-4)).expect("a valid variation");
    let baseline = rk4
        .vary(|s| {
            s.dynamics.mass_matrix = MassMatrixMethod::WalkerOrin;
            s.dynamics.constraint_solver = ConstraintSolver::Kkt;
        })
        .expect("a valid variation");
    let cases = [("two-elbow-dopri45", paper), ("two-elbow-rk4", rk4), ("two-elbow-paper-baseline", baseline)];

    let mut g = c.benchmark_group("paper_run");
    // a run takes 0.1–3 s: the same iteration count in every sample (10 runs, not 55)
    g.sampling_mode(SamplingMode::Flat);
    for (name, scene) in &cases {
        let run = &scene.runs()[two];
        let report = simulate(scene, run, |_| Ok(())).expect("the run completes");
        eprintln!(
            "{name}: {} s simulated, {} steps ({} rejected), {} rhs evaluations, {} samples",
            scene.duration(), report.stats.steps, report.stats.rejected, report.stats.rhs_evals, report.samples
        );
        g.bench_function(*name, |b| {
            b.iter(|| {
                let report = simulate(scene, run, |o| {
                    black_box(o);
                    Ok(())
                })
                .expect("the run completes");
                black_box(report.samples)
            })
        });
    }
    g.finish();
}

fn config() -> Criterion {
    Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(5))
}

criterion_group! {
    name = benches;
    config = config();
    targets = runs
}
criterion_main!(benches);
