//! Cost against chain length: random serial chains (`dynamics::samples::random_chain`) of
//! n = 5 … 100 revolute joints.
//!
//! `cargo bench -p sim --bench scaling`; results, per-n costs and fitted exponents in
//! BENCHMARKS.md.
//!
//! Groups (criterion ids `<group>/<n>`): `scaling_rnea`, `scaling_crba`, `scaling_walker_orin`,
//! and `scaling_forward` (eq 21 with two point-on-plane contacts, CRBA + Schur, no
//! stabilisation).

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use nalgebra::{Unit, Vector3};
use sim::dynamics::constraints::PointOnPlane;
use sim::dynamics::forward::{forward_dynamics, ConstraintSolver, ForwardData, MassMatrixMethod, Plant, Stabilization};
use sim::dynamics::kinematics::BodyPoint;
use sim::dynamics::motor::{Drives, MotorParams};
use sim::dynamics::samples::{random_chain, SplitMix64};
use sim::dynamics::{crba, rnea, walker_orin, Data, Model};

const NS: [usize; 7] = [5, 10, 20, 30, 50, 75, 100];

/// A chain of n joints, its scratch and a random state.
struct Case {
    n: usize,
    model: Model,
    data: Data,
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
    current: Vec<f64>,
    voltage: Vec<f64>,
}

fn cases() -> Vec<Case> {
    NS.iter()
        .map(|&n| {
            let model = random_chain(n, 1000 + n as u64);
            let data = Data::new(&model);
            let mut rng = SplitMix64(17 + n as u64);
            Case {
                n,
                model,
                data,
                q: rng.vector(n, -2.0, 2.0),
                qd: rng.vector(n, -1.0, 1.0),
                qdd: rng.vector(n, -1.0, 1.0),
                current: rng.vector(n, -3.0, 3.0),
                voltage: rng.vector(n, -10.0, 10.0),
            }
        })
        .collect()
}

/// The paper's motor on every joint (as in the dynamics tests).
fn drives(n: usize) -> Drives {
    let m = MotorParams {
        torque_constant: 0.203,
        resistance: 1.1,
        inductance: 0.0017,
        rotor_inertia: 0.000164,
        gear_ratio: 3.0,
        gear_damping: 0.01,
    };
    Drives::new(&vec![m; n], &vec![0.5; n])
}

/// Two points held on planes of random normal: on the middle body and on the last one.
fn contacts(n: usize) -> Vec<PointOnPlane> {
    let mut rng = SplitMix64(29);
    [n / 2, n - 1]
        .iter()
        .enumerate()
        .map(|(k, &body)| PointOnPlane {
            name: format!("c{k}"),
            point: BodyPoint { body: Some(body), p_body: Vector3::new(0.0, 0.0, 0.1) },
            normal_world: Unit::new_normalize(rng.unit_vector()),
            offset: 0.0,
        })
        .collect()
}

fn scaling(c: &mut Criterion) {
    let mut cases = cases();

    let mut g = c.benchmark_group("scaling_rnea");
    for cs in &mut cases {
        let Case { n, model, data, q, qd, qdd, .. } = cs;
        g.bench_with_input(BenchmarkId::from_parameter(*n), n, |b, _| {
            b.iter(|| {
                rnea::rnea(model, data, black_box(q), black_box(qd), black_box(qdd), &model.gravity);
                black_box(data.tau[0])
            })
        });
    }
    g.finish();

    let mut g = c.benchmark_group("scaling_crba");
    for cs in &mut cases {
        let Case { n, model, data, q, .. } = cs;
        g.bench_with_input(BenchmarkId::from_parameter(*n), n, |b, _| {
            b.iter(|| {
                crba::crba(model, data, black_box(q));
                black_box(data.m[(0, 0)])
            })
        });
    }
    g.finish();

    let mut g = c.benchmark_group("scaling_walker_orin");
    for cs in &mut cases {
        let Case { n, model, data, q, .. } = cs;
        g.bench_with_input(BenchmarkId::from_parameter(*n), n, |b, _| {
            b.iter(|| {
                walker_orin::mass_matrix(model, data, black_box(q));
                black_box(data.m[(0, 0)])
            })
        });
    }
    g.finish();

    let mut g = c.benchmark_group("scaling_forward");
    for cs in &mut cases {
        let Case { n, model, data, q, qd, current, voltage, .. } = cs;
        let drives = drives(*n);
        let contacts = contacts(*n);
        let plant = Plant {
            model,
            drives: &drives,
            contacts: &contacts,
            mass_matrix: MassMatrixMethod::Crba,
            solver: ConstraintSolver::Schur,
            stabilization: Stabilization::None,
        };
        let mut fd = ForwardData::new(*n, contacts.len());
        g.bench_with_input(BenchmarkId::from_parameter(*n), n, |b, _| {
            b.iter(|| {
                forward_dynamics(&plant, data, &mut fd, 0.0, black_box(q), black_box(qd), current, voltage)
                    .expect("solvable");
                black_box(fd.qdd[0])
            })
        });
    }
    g.finish();
}

fn config() -> Criterion {
    Criterion::default()
        .sample_size(15)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(2))
}

criterion_group! {
    name = benches;
    config = config();
    targets = scaling
}
criterion_main!(benches);
