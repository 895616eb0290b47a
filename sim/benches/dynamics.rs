//! Dynamics kernels on the paper's 10-joint arm, and the ODE right-hand side of its runs.
//!
//! `cargo bench -p sim --bench dynamics`; results and ratios in BENCHMARKS.md.
//!
//! Groups (criterion ids, also the directories under `target/criterion/`):
//! - `paper_arm/{rnea, crba, crba_world, walker_orin}`: at q = q0 and a random q̇ (and q̈ for
//!   RNEA); `crba_world` (the world-aligned CRBA the right-hand side uses) at the placements of
//!   one forward-kinematics call.
//! - `paper_arm/forward/{crba,walker-orin}-{schur,kkt}`: eq 21 with the two elbow contacts,
//!   random q̇, currents and voltages, and the scene's constraint stabilisation.
//! - `paper_rhs/{two-elbow, one-elbow, no-elbow}`: `ArmSystem::rhs` (IK targets, PD voltages,
//!   eq 21, quadratures) with the scene's plant (CRBA + Schur); `paper_rhs/two-elbow-*` the
//!   two-elbow run with the other plants, for the CRBA vs Walker–Orin and Schur vs KKT ratios.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use sim::dynamics::forward::{forward_dynamics, ConstraintSolver, ForwardData, MassMatrixMethod, Plant};
use sim::dynamics::samples::SplitMix64;
use sim::dynamics::{crba, rnea, walker_orin, Data};
use sim::integrate::OdeSystem;
use sim::scene::Scene;
use sim::ode::ArmSystem;

const PLANTS: [(&str, MassMatrixMethod, ConstraintSolver); 4] = [
    ("crba-schur", MassMatrixMethod::Crba, ConstraintSolver::Schur),
    ("crba-kkt", MassMatrixMethod::Crba, ConstraintSolver::Kkt),
    ("walker-orin-schur", MassMatrixMethod::WalkerOrin, ConstraintSolver::Schur),
    ("walker-orin-kkt", MassMatrixMethod::WalkerOrin, ConstraintSolver::Kkt),
];

fn kernels(c: &mut Criterion) {
    let scene = Scene::paper().expect("the built-in scene is valid");
    let model = scene.model();
    let nv = model.nv;
    let mut rng = SplitMix64(2024);
    let q = scene.q0().to_vec();
    let qd = rng.vector(nv, -1.0, 1.0);
    let qdd = rng.vector(nv, -1.0, 1.0);
    let current = rng.vector(nv, -3.0, 3.0);
    let voltage = rng.vector(nv, -10.0, 10.0);
    let mut data = Data::new(model);

    let mut g = c.benchmark_group("paper_arm");
    g.bench_function("rnea", |b| {
        b.iter(|| {
            rnea::rnea(model, &mut data, black_box(&q), black_box(&qd), black_box(&qdd), &model.gravity);
            black_box(data.tau[0])
        })
    });
    g.bench_function("crba", |b| {
        b.iter(|| {
            crba::crba(model, &mut data, black_box(&q));
            black_box(data.m[(0, 0)])
        })
    });
    sim::dynamics::kinematics::forward_kinematics(model, &mut data, &q);
    g.bench_function("crba_world", |b| {
        b.iter(|| {
            crba::crba_world(model, black_box(&mut data));
            black_box(data.m[(0, 0)])
        })
    });
    g.bench_function("walker_orin", |b| {
        b.iter(|| {
            walker_orin::mass_matrix(model, &mut data, black_box(&q));
            black_box(data.m[(0, 0)])
        })
    });
    for (name, mass_matrix, solver) in PLANTS {
        let plant = Plant {
            model,
            drives: &scene.drives(),
            contacts: &scene.contacts(),
            mass_matrix,
            solver,
            stabilization: scene.stabilization(),
        };
        let mut fd = ForwardData::new(nv, scene.contacts().len());
        g.bench_function(BenchmarkId::new("forward", name), |b| {
            b.iter(|| {
                forward_dynamics(&plant, &mut data, &mut fd, 0.0, black_box(&q), black_box(&qd), &current, &voltage)
                    .expect("solvable");
                black_box(fd.qdd[0])
            })
        });
    }
    g.finish();
}

fn rhs(c: &mut Criterion) {
    let scene = Scene::paper().expect("the built-in scene is valid");
    let nv = scene.model().nv;
    let mut g = c.benchmark_group("paper_rhs");
    // the scene's plant on each run, then the two-elbow run with every other plant
    let mut cases: Vec<(String, Scene, usize)> =
        (0..scene.runs().len()).map(|k| (scene.runs()[k].name.clone(), scene.clone(), k)).collect();
    let two = scene.runs().iter().position(|r| r.contacts.len() == 2).expect("a two-elbow run");
    for (name, mass_matrix, solver) in &PLANTS[1..] {
        let s = scene
            .vary(|sp| {
                sp.dynamics.mass_matrix = *mass_matrix;
                sp.dynamics.constraint_solver = *solver;
            })
            .expect("a valid variation");
        cases.push((format!("{}-{name}", scene.runs()[two].name), s, two));
    }
    for (name, s, k) in &cases {
        let mut sys = ArmSystem::new(s, &s.runs()[*k]);
        let mut y = sys.initial_state();
        let l = sys.layout();
        let mut rng = SplitMix64(7);
        y[l.qd()].copy_from_slice(&rng.vector(nv, -1.0, 1.0));
        y[l.current()].copy_from_slice(&rng.vector(nv, -3.0, 3.0));
        let mut dydt = vec![0.0; sys.dim()];
        g.bench_function(name.as_str(), |b| {
            b.iter(|| {
                sys.rhs(black_box(0.3), black_box(&y), &mut dydt).expect("rhs");
                black_box(dydt[nv])
            })
        });
    }
    g.finish();
}

fn config() -> Criterion {
    Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(2))
}

criterion_group! {
    name = benches;
    config = config();
    targets = kernels, rhs
}
criterion_main!(benches);
