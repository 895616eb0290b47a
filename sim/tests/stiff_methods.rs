//! The stiff methods on the arm: the structured Jacobian against finite differences, the
//! Rosenbrock-W and IMEX runs against the Dormand–Prince reference, and constraint drift with
//! no stabilisation, Baumgarte and projection.

use sim::dynamics::forward::Stabilization;
use sim::integrate::{OdeJacobian, OdeSystem};
use sim::scene::spec::{AdaptiveSpec, IntegratorSpec, PerJoint};
use sim::scene::Scene;
use sim::ode::ArmSystem;
use std::ops::Range;

use crate::drives_support::{assert_blocks_match, assert_rodas_differences, dumping_bus, gear_law, lift};

/// The system of `run` and its initial state with every motor current set to a different
/// non-zero value, so that the current-dependent terms are exercised.
fn with_currents<'a>(scene: &'a Scene, run: &'a sim::scene::Run) -> (ArmSystem<'a>, Vec<f64>) {
    let sys = ArmSystem::new(scene, run);
    let l = sys.layout();
    let mut y = sys.initial_state();
    for (k, v) in y[l.current()].iter_mut().enumerate() {
        *v = 0.3 * (k as f64 - 4.0);
    }
    (sys, y)
}

/// Central differences of the right-hand side (h relative to each component).
pub(crate) fn central_jacobian(sys: &mut ArmSystem, t: f64, y: &[f64]) -> Vec<f64> {
    let dim = y.len();
    let mut jac = vec![0.0; dim * dim];
    let (mut yp, mut fp, mut fm) = (y.to_vec(), vec![0.0; dim], vec![0.0; dim]);
    for c in 0..dim {
        let h = 1e-6 * (1.0 + y[c].abs());
        yp[c] = y[c] + h;
        sys.rhs(t, &yp, &mut fp).unwrap();
        yp[c] = y[c] - h;
        sys.rhs(t, &yp, &mut fm).unwrap();
        yp[c] = y[c];
        for r in 0..dim {
            jac[r * dim + c] = (fp[r] - fm[r]) / (2.0 * h);
        }
    }
    jac
}

/// At (t, y): the right-hand side f, the structured Jacobian and its central differences
/// (both row-major, dim × dim).
pub(crate) fn jacobian_and_differences(sys: &mut ArmSystem, t: f64, y: &[f64]) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let dim = y.len();
    let mut f = vec![0.0; dim];
    sys.rhs(t, y, &mut f).unwrap();
    let mut j = vec![0.0; dim * dim];
    sys.jacobian(t, y, &f, &mut j).unwrap();
    let fd = central_jacobian(sys, t, y);
    (f, j, fd)
}

/// The structured Jacobian equals central differences on every entry it models exactly, for
/// every constraint solver (Schur and KKT), mass-matrix method (CRBA and Walker–Orin), contact
/// set (none, one and two elbows) and electrical model (inductive and L = 0), at a state at
/// rest (q' = 0, where the Coriolis and J'q' terms it leaves out have no derivative): the rows
/// of q, all of q'' against q' (and the currents), all of the current rates. Each entry to
/// 1e-7 of its own size plus 1e-7 of its block's largest entry (a scale per block: a current
/// rate is ~1e3 where a q'' entry is ~1), plus the rounding of the differences, eps |f| / h.
/// A sign or a missing constraint term in `M_c^-1` (what a KKT solve once lost) fails it.
#[test]
fn structured_jacobian_matches_central_differences_for_every_plant() {
    use sim::dynamics::forward::{ConstraintSolver, MassMatrixMethod};
    let paper = Scene::paper().unwrap();
    for inductance in [0.0017, 0.0] {
        for (mm, solver) in [
            (MassMatrixMethod::Crba, ConstraintSolver::Schur),
            (MassMatrixMethod::Crba, ConstraintSolver::Kkt),
            (MassMatrixMethod::WalkerOrin, ConstraintSolver::Schur),
            (MassMatrixMethod::WalkerOrin, ConstraintSolver::Kkt),
        ] {
            let scene = paper
                .vary(|s| {
                    s.motor.inductance = sim::scene::spec::PerJoint::All(inductance);
                    s.dynamics.mass_matrix = mm;
                    s.dynamics.constraint_solver = solver;
                })
                .unwrap();
            for run in scene.runs() {
                let (mut sys, y) = with_currents(&scene, run);
                let l = sys.layout();
                let t = 0.37;
                let (f, j, fd) = jacobian_and_differences(&mut sys, t, &y);
                let what = format!("{mm:?} {solver:?} L = {inductance} run {}", run.name);
                // the blocks the structured Jacobian models exactly: rows of q (all columns),
                // q'' against q' and i, the current rates against everything
                let blocks: [(Range<usize>, Vec<Range<usize>>); 3] = [
                    (l.q(), vec![l.q(), l.qd(), l.current()]),
                    (l.qd(), vec![l.qd(), l.current()]),
                    (l.current(), vec![l.q(), l.qd(), l.current()]),
                ];
                let checked = assert_blocks_match(&what, &y, &f, &j, &fd, &blocks, |_, _, _| {});
                assert!(checked >= 2 * l.nv * l.nv, "{what}: {checked} entries");
            }
        }
    }
}

/// The Jacobian the classical Rosenbrock methods (RODAS5P) use on the arm: forward
/// differences over the coupled columns (q, q', i: `coupled_dim`) only, the quadrature columns
/// zero, with the arm's increment `sqrt(1e-13) max(|y_j|, 1)` (`ArmSystem::difference_increment`;
/// the numbers below were measured with the earlier `sqrt(eps) max(|y_j|, 1e-2)`, whose
/// rounding error cost RODAS its order with gear friction, `drive_features.rs`). Against central differences over every column, for every contact set, with and
/// without inductance, at a moving state (q' != 0, currents != 0, where Coriolis and the
/// other terms the structured Jacobian leaves out have derivatives): the quadrature columns of
/// the central differences are exactly 0 (the quadratures never enter f), the coupled columns
/// agree entry by entry, the quadrature rows included, to 1e-6 of the row's largest entry
/// plus the rounding of the forward differences, 128 eps max|f| / h (max|f| ~ 1e5, the current
/// rates, couples into every row through the constraint solve; measured up to 15 eps
/// max|f| / h with the body-frame CRBA, 95 eps with the world-frame one of `forward_dynamics`, whose
/// rounding grows with the links' distance from the world origin (the L = 0 two-elbow run,
/// d q''_10 / d q_1, exactly 0 by the yaw symmetry: 5.3 forward at h = 1.5e-10, 8e-5 central); 1.1e-5 of the row scale at an angle of 0 rad); and the structured approximation
/// misses the exact Jacobian by more than 1e-3 of the q'' rows' scale (what RODAS would lose
/// order on).
#[test]
fn rodas_jacobian_is_exact_on_the_coupled_block() {
    let paper = Scene::paper().unwrap();
    for inductance in [0.0017, 0.0] {
        let scene = paper.vary(|s| s.motor.inductance = PerJoint::All(inductance)).unwrap();
        for run in scene.runs() {
            let (mut sys, mut y) = with_currents(&scene, run);
            let l = sys.layout();
            let dim = l.dim();
            let nc = sys.coupled_dim();
            assert_eq!(nc, 2 * l.nv + l.ni());
            for (k, v) in y[l.qd()].iter_mut().enumerate() {
                *v = 0.2 * (k as f64 - 3.5);
            }
            let t = 0.37;
            let mut f = vec![0.0; dim];
            sys.rhs(t, &y, &mut f).unwrap();
            let mut probe = vec![0.0; dim * dim];
            assert!(!sys.exact_jacobian(t, &y, &f, &mut probe).unwrap(), "the arm leaves the exact Jacobian to differences");
            let central = central_jacobian(&mut sys, t, &y);
            let what = format!("L = {inductance} run {}", run.name);
            assert_rodas_differences(&mut sys, t, &y, &f, &central, &what);
            let mut approx = vec![0.0; dim * dim];
            sys.jacobian(t, &y, &f, &mut approx).unwrap();
            let rows = l.qd();
            let scale = rows.clone().flat_map(|r| (0..nc).map(move |c| (r, c))).map(|(r, c)| central[r * dim + c].abs()).fold(0.0, f64::max);
            let miss = rows.flat_map(|r| (0..nc).map(move |c| (r, c))).map(|(r, c)| (approx[r * dim + c] - central[r * dim + c]).abs()).fold(0.0, f64::max);
            assert!(miss > 1e-3 * scale, "{what}: the structured Jacobian should differ from the exact one: {miss:e} vs scale {scale:e}");
        }
    }
}

/// IMEX's split and implicit solve, for every constraint solver and contact set: `f_E + f_I`
/// is the right-hand side (exactly), and `solve_implicit` solves its stage equation
/// `z − γ f_I(t, z) = r` (the circuit is linear in i: to 1e-12 of the terms).
#[test]
fn imex_split_and_implicit_solve_are_exact_for_every_plant() {
    use sim::dynamics::forward::ConstraintSolver;
    use sim::integrate::SplitSystem;
    for solver in [ConstraintSolver::Schur, ConstraintSolver::Kkt] {
        let scene = Scene::paper().unwrap().vary(|s| s.dynamics.constraint_solver = solver).unwrap();
        for run in scene.runs() {
            let (mut sys, y) = with_currents(&scene, run);
            let l = sys.layout();
            let dim = l.dim();
            let t = 0.37;
            let (mut f, mut fe, mut fi) = (vec![0.0; dim], vec![0.0; dim], vec![0.0; dim]);
            sys.rhs(t, &y, &mut f).unwrap();
            sys.rhs_split(t, &y, &mut fe, &mut fi).unwrap();
            for k in 0..dim {
                assert_eq!(fe[k] + fi[k], f[k], "{solver:?} {}: component {k}", run.name);
            }
            let gamma = 1e-3;
            let mut z = vec![0.0; dim];
            sys.solve_implicit(t, gamma, &y, &mut z).unwrap();
            sys.rhs_split(t, &z, &mut fe, &mut fi).unwrap();
            for k in l.current() {
                let scale = y[k].abs() + (gamma * fi[k]).abs() + 1e-9;
                assert!((z[k] - gamma * fi[k] - y[k]).abs() <= 1e-12 * scale, "{solver:?} {}: current {k}", run.name);
            }
        }
    }
}

/// Rosenbrock-W takes the same steps whatever solves the constraints: KKT and Schur give the
/// same Jacobian (within 2 % of the step count, on the two-elbow paper run at rtol 1e-6).
#[test]
fn rosenbrock_steps_do_not_depend_on_the_constraint_solver() {
    use sim::dynamics::forward::ConstraintSolver;
    let steps = |solver| {
        let scene = Scene::paper()
            .unwrap()
            .vary(|s| {
                s.duration = 1.0;
                s.integrator = IntegratorSpec::adaptive("rosenbrock", 1e-6, Some(0.5)).unwrap();
                s.dynamics.constraint_solver = solver;
            })
            .unwrap();
        let run = scene.run("two-elbow").unwrap().clone();
        sim::run::simulate(&scene, &run, |_| Ok(())).unwrap().stats.steps as f64
    };
    let (schur, kkt) = (steps(ConstraintSolver::Schur), steps(ConstraintSolver::Kkt));
    assert!((kkt - schur).abs() <= 0.02 * schur, "Schur {schur} steps, KKT {kkt}");
}

fn hand_path(scene: &Scene) -> (Vec<nalgebra::Vector3<f64>>, f64) {
    let run = scene.run("two-elbow").unwrap().clone();
    let mut hand = Vec::new();
    let mut res = 0.0f64;
    let rep = sim::run::simulate(scene, &run, |o| {
        hand.push(o.hand);
        res = res.max(o.balance_residual.abs());
        Ok(())
    })
    .unwrap();
    (hand, res / rep.last.electric_energy.iter().sum::<f64>())
}

/// Rosenbrock-W, IMEX, RODAS5P and RODAS4 (rtol 1e-8) follow the Dormand–Prince (rtol 1e-11) hand
/// path over 1 s, with the motors' inductance (L di/dt) and without it (L = 0: the quasi-static
/// current and the Jacobian's L = 0 branch), and close the energy balance to 1e-6 of E.
/// The bound is what the tolerance asks for, rtol × |x| (|x| ≈ 2.2 m, the size of the hand's
/// position): 2.2e-8 m. Measured: 1.6e-10 to 2.0e-10 m (Rosenbrock), 1.7e-11 to 3.1e-11 m
/// (IMEX); a method of the wrong order, or a wrong Jacobian branch that fools the step-size
/// control, misses it by orders of magnitude.
#[test]
fn stiff_methods_agree_with_the_reference() {
    let rtol = 1e-8;
    for inductance in [0.0017, 0.0] {
        let paper = Scene::paper().unwrap().vary(|s| {
            s.duration = 1.0;
            s.motor.inductance = PerJoint::All(inductance);
        });
        let paper = paper.unwrap();
        let with = |integrator: IntegratorSpec| paper.vary(|s| s.integrator = integrator).unwrap();
        let (reference, _) = hand_path(&with(IntegratorSpec::Dopri45(AdaptiveSpec { rtol: 1e-11, atol: 1e-13, h_max: Some(1e-3), max_steps: None })));
        let scale = reference.iter().map(|x| x.norm()).fold(0.0, f64::max);
        for method in ["rosenbrock", "imex", "rodas5p", "rodas4"] {
            let integrator = IntegratorSpec::adaptive(method, rtol, Some(0.1)).unwrap();
            let (hand, res) = hand_path(&with(integrator.clone()));
            let err = hand.iter().zip(&reference).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
            assert!(err < rtol * scale, "L = {inductance} H, {integrator:?}: {err:e} m");
            assert!(res < 1e-6, "L = {inductance} H, {integrator:?}: balance {res:e}");
        }
    }
}

fn drift(scene: &Scene) -> f64 {
    let run = scene.run("two-elbow").unwrap().clone();
    let mut d = 0.0f64;
    sim::run::simulate(scene, &run, |o| {
        d = o.constraint_position.iter().fold(d, |m, c| m.max(c.abs()));
        Ok(())
    })
    .unwrap();
    d
}

/// At a loose tolerance (rtol 1e-6) over 10 s, eq 15 alone lets the elbows drift; Baumgarte
/// (α = β = 20 1/s) keeps the drift smaller, and projection after every step keeps |C| below
/// 1e-12 m.
#[test]
fn stabilisation_bounds_the_drift() {
    let with = |stabilization: Stabilization| {
        let scene = Scene::paper().unwrap().vary(|s| {
            s.duration = 10.0;
            s.integrator = IntegratorSpec::Dopri45(AdaptiveSpec { rtol: 1e-6, atol: 1e-8, h_max: Some(1e-3), max_steps: None });
            s.dynamics.stabilization = stabilization;
        });
        drift(&scene.unwrap())
    };
    let plain = with(Stabilization::None);
    let baumgarte = with(Stabilization::Baumgarte { alpha: 20.0, beta: 20.0 });
    let projected = with(Stabilization::Projection);
    assert!(baumgarte < plain, "plain {plain:e}, baumgarte {baumgarte:e}");
    assert!(projected < 1e-12 && projected < plain, "plain {plain:e}, projected {projected:e}");
}

/// The modes the README names as what limits explicit methods: at the start of each paper run,
/// the Jacobian's eigenvalues of largest modulus are the electromechanical pair −450 ± 1900i 1/s
/// with the motors' inductance, and a real −5800 1/s with L = 0 (each within 5 %; measured
/// −455 ± 1878i and −5777 to −5787).
#[test]
fn the_fastest_modes_are_the_ones_stated() {
    for (inductance, stated) in [(0.0017, nalgebra::Complex::new(-450.0, 1900.0)), (0.0, nalgebra::Complex::new(-5800.0, 0.0))] {
        let scene = Scene::paper().unwrap().vary(|s| s.motor.inductance = PerJoint::All(inductance)).unwrap();
        for run in scene.runs() {
            let mut sys = ArmSystem::new(&scene, run);
            let y = sys.initial_state();
            let dim = y.len();
            let mut f = vec![0.0; dim];
            sys.rhs(0.0, &y, &mut f).unwrap();
            let mut j = vec![0.0; dim * dim];
            sys.jacobian(0.0, &y, &f, &mut j).unwrap();
            let eigenvalues = nalgebra::DMatrix::from_row_slice(dim, dim, &j).complex_eigenvalues();
            let fastest = eigenvalues.iter().max_by(|a, b| a.norm().total_cmp(&b.norm())).unwrap();
            // the pair's upper member (the conjugate has the same modulus)
            let fastest = nalgebra::Complex::new(fastest.re, fastest.im.abs());
            assert!((fastest - stated).norm() <= 0.05 * stated.norm(), "L = {inductance} H, {}: fastest mode {fastest}, stated {stated}", run.name);
        }
    }
}

/// With gear friction (efficiencies below 1, Stribeck) and a supply on: the structured
/// Jacobian against central differences on the entries it models exactly, (a) on the paper
/// arm at rest with currents of both signs (every gear sliding forward and driving, the modes
/// `ArmSystem::new` starts in: the efficiency factor on K_m in `∂q̈/∂i` and in the quasi-static
/// rows), (b) on a lead screw lifting a slider (no Coriolis, no gravity stiffness: every
/// entry of the q̈ rows is modelled) while it moves, where the Stribeck slope enters
/// `∂q̈/∂q̇`; and RODAS's forward differences over the coupled columns against central ones.
/// Without the gear terms in `jacobian.rs` (c = 1, no slope) (a) and (b) fail.
#[test]
fn jacobians_match_differences_with_gear_friction_and_a_supply() {
    let gear = |s: &mut sim::scene::SceneSpec| {
        s.gear_friction = Some(gear_law(0.1, 0.3, 0.05, 0.8, 0.6));
        s.supply = Some(dumping_bus());
    };
    let mut scenes = Vec::new();
    for inductance in [0.0017, 0.0] {
        scenes.push((Scene::paper().unwrap().vary(|s| {
            s.motor.inductance = PerJoint::All(inductance);
            gear(s);
        }).unwrap(), 0.0));
        scenes.push((lift(inductance, "").vary(gear).unwrap(), 0.03));
    }
    for (scene, speed) in &scenes {
        for run in scene.runs() {
            let (mut sys, mut y) = with_currents(scene, run);
            let l = sys.layout();
            for v in y[l.qd()].iter_mut() {
                *v = *speed;
            }
            let t = 0.37;
            let (f, j, fd) = jacobian_and_differences(&mut sys, t, &y);
            let what = format!("{} L = {} run {}", scene.spec().name, l.ni() > 0, run.name);
            let blocks: [(Range<usize>, Vec<Range<usize>>); 3] = [
                (l.q(), vec![l.q(), l.qd(), l.current()]),
                (l.qd(), vec![l.qd(), l.current()]),
                (l.current(), vec![l.q(), l.qd(), l.current()]),
            ];
            assert_blocks_match(&what, &y, &f, &j, &fd, &blocks, |_, _, _| {});
            // RODAS: forward differences over the coupled columns, the quadratures' columns 0
            assert_rodas_differences(&mut sys, t, &y, &f, &fd, &what);
        }
    }
}
