//! Independent checks of the physics the README's findings rest on, each against something the
//! simulator does not compute the same way, with a tolerance derived from the accuracy stated:
//!
//! - the Newton residual of eq 14 at every recorded sample of the paper's three runs, with the
//!   constraint Jacobian by central differences of the contact positions (not the simulator's
//!   `constraint_jacobian`) — a sign error in J_c, in f_n or in eq 12's τ breaks it;
//! - the normal forces of an arm resting on the table against statics by hand;
//! - the link work W_j against the mechanical energy it must account for (a link-side balance);
//! - a DC motor driving a constant inertia against the closed-form solution of its two linear
//!   ODEs (eq 11 and the rotor's Newton equation) — the back-EMF's sign and size included;
//! - the unsupported hand sagging downward.
//!
//! The paper runs are recorded to files and read back typed (`schemas`), so what is checked is
//! what a recording holds.

use std::path::Path;

use nalgebra::{Complex, Matrix2, Vector2};
use schemas::{ConstraintState, EnergyState, HandState, JointState, MotorState};
use sim::dynamics::kinematics::forward_kinematics;
use sim::dynamics::rnea::rnea;
use sim::dynamics::Data;
use sim::scene::spec::PerJoint;
use sim::scene::Scene;

fn resting() -> Scene {
    Scene::load(Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/checks/resting.json"))).unwrap()
}

/// The recording of `run` of `scene`, read back: (joint states, motors, constraints, energy).
struct Recorded {
    joints: Vec<(f64, JointState)>,
    motors: Vec<(f64, MotorState)>,
    constraints: Vec<(f64, ConstraintState)>,
    energy: Vec<(f64, EnergyState)>,
    hand: Vec<(f64, HandState)>,
}

fn record(scene: &Scene, run: &str) -> Recorded {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(format!("{run}.mcap"));
    let r = scene.run(run).unwrap().clone();
    sim::run::run_to_file(scene, &r, &path, |_| {}).unwrap();
    let rec = schemas::read_recording(&path).unwrap();
    Recorded {
        joints: rec.read().unwrap(),
        motors: rec.read().unwrap(),
        constraints: rec.read().unwrap(),
        energy: rec.read().unwrap(),
        hand: rec.read().unwrap(),
    }
}

/// Eq 14 at every recorded sample of the paper's runs:
/// `M(q) q'' + h(q, q') + D q' − τ − J_c(q)ᵀ f_n = 0`, τ the recorded effort (eq 12's torque on
/// the link). q'' is recovered from eq 12 itself, `q'' = (K_m i − D_m q' − τ) / J_m`, from the
/// recorded current and effort; `M q'' + h` is RNEA (its identities with CRBA and Walker–Orin:
/// `properties.rs`); J_c is central differences of the recorded contacts' positions.
///
/// Tolerance: the differences' error, `h² |C'''| + ε |C| / h` with h = 1e-5 rad and |C''|,
/// |C'''| ≲ 2 m (the arm's reach), is ~3e-10 per entry of J_c, times |f_n| ≤ 32 N: 1e-8 N m;
/// recovering q'' costs `ε |K_m i| / J_m` ≈ 5e-12 rad/s², times |M| ≲ 1 kg m². So 1e-7 N m, which
/// is 3e-9 of the largest torque (30 N m). A flipped J_c or f_n leaves |J_cᵀ f_n| ≈ 1–60 N m.
#[test]
fn newton_residual_of_eq_14_at_every_recorded_sample() {
    let scene = Scene::paper().unwrap();
    let (model, drives) = (scene.model(), scene.drives());
    let nv = model.nv;
    let mut data = Data::new(model);
    let mut worst = (0.0f64, String::new());
    let mut samples = 0;
    for run in scene.runs() {
        let r = record(&scene, &run.name);
        let contacts = scene.run_contacts(run);
        let contact_position = |data: &mut Data, q: &[f64], k: usize| {
            forward_kinematics(model, data, q);
            contacts[k].position(data)
        };
        for (s, ((_, js), ((_, m), (_, c)))) in r.joints.iter().zip(r.motors.iter().zip(&r.constraints)).enumerate() {
            let (q, qd, tau) = (&js.position, &js.velocity, &js.effort);
            let qdd: Vec<f64> = (0..nv).map(|j| (drives.km[j] * m.current[j] - drives.dm[j] * qd[j] - tau[j]) / drives.jm[j]).collect();
            let mut res: Vec<f64> = rnea(model, &mut data, q, qd, &qdd, &model.gravity).iter().copied().collect();
            for j in 0..nv {
                res[j] += drives.d[j] * qd[j] - tau[j];
            }
            let mut qp = q.clone();
            for (k, f_n) in c.normal_force.iter().enumerate() {
                for (j, r) in res.iter_mut().enumerate() {
                    let h = 1e-5;
                    qp[j] = q[j] + h;
                    let plus = contact_position(&mut data, &qp, k);
                    qp[j] = q[j] - h;
                    let minus = contact_position(&mut data, &qp, k);
                    qp[j] = q[j];
                    *r -= (plus - minus) / (2.0 * h) * f_n;
                }
            }
            let r_max = res.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            if r_max > worst.0 {
                worst = (r_max, format!("run {} sample {s}", run.name));
            }
            samples += 1;
        }
    }
    assert_eq!(samples, 3 * 5001);
    assert!(worst.0 <= 1e-7, "largest |residual| {:e} N m at {}", worst.0, worst.1);
}

/// An arm lying on the table, motors off: both rods rest on it, at joint3 and at the hand. By
/// statics (uniform rods; moments about joint3 for rod 3, then about joint2 for both) the table
/// pushes up with `(m2 + m3) g / 2` at joint3 and `m3 g / 2` at the hand, at every sample: the
/// arm cannot move (the two contacts fix both pitch joints, gravity has no moment about the yaw
/// axis). Tolerance 1e-10 of the force (a few solves of small, well-conditioned systems).
#[test]
fn normal_forces_of_an_arm_resting_on_the_table_are_those_of_statics() {
    let scene = resting();
    let (m2, m3, g) = (2.0, 1.0, 9.81);
    let expected = [(m2 + m3) * g / 2.0, m3 * g / 2.0];
    let r = record(&scene, "resting");
    assert_eq!(r.constraints.len(), 501);
    for (t, c) in &r.constraints {
        for (f, want) in c.normal_force.iter().zip(expected) {
            assert!(f > &0.0, "t = {t}: the table pulls ({f} N)");
            assert!((f - want).abs() <= 1e-10 * want, "t = {t}: f_n = {f} N, statics {want} N");
        }
    }
}

/// The link work W_j of eq 12 accounts for the links' mechanical energy: on the link side,
/// `Σ_j W_j(t) = ΔT_links + ΔV + ∫ Σ D q'² dt` (ideal constraints do no work; the rotors' energy
/// and the gear friction D_m are on the motor side of τ). T_links is the recorded kinetic energy
/// minus the rotors' `½ Σ J_m q'²`, the D loss the recorded friction loss minus its gear part.
///
/// Tolerance: every term is integrated or evaluated at rtol 1e-10 on energies of at most ~10 J
/// (|T|, |V| changes, W); the drift |C| < 1e-13 m lets f_n (≤ 32 N) do < 1e-11 J. So 1e-8 J.
/// A sign error in eq 12's J_m q'' or D_m q' term shifts W by ½ J_m q'² or ∫ D_m q'² (0.1–1 J).
#[test]
fn link_work_accounts_for_the_mechanical_energy_at_every_sample() {
    let scene = Scene::paper().unwrap();
    let jm = &scene.drives().jm;
    for run in scene.runs() {
        let r = record(&scene, &run.name);
        let t_links = |e: &EnergyState, qd: &[f64]| e.kinetic - 0.5 * qd.iter().zip(jm.iter()).map(|(v, j)| j * v * v).sum::<f64>();
        let (e0, js0) = (&r.energy[0].1, &r.joints[0].1);
        let (t0, v0) = (t_links(e0, &js0.velocity), e0.potential);
        let mut worst = 0.0f64;
        for ((t, e), (_, js)) in r.energy.iter().zip(&r.joints) {
            let joint_friction = e.friction_loss - e.gear_friction_loss;
            let balance = e.link_work_total - (t_links(e, &js.velocity) - t0 + e.potential - v0 + joint_friction);
            assert!(balance.abs() <= 1e-8, "run {} t = {t}: W - (dT + dV + D loss) = {balance:e} J", run.name);
            worst = worst.max(balance.abs());
        }
        // the check is not empty: the work is of the size of the energies it balances
        assert!(r.energy.last().unwrap().1.link_work_total.abs() > 1.0, "run {}", run.name);
        assert!(worst < 1e-8);
    }
}

/// The state of a DC motor driving a constant inertia J with viscous friction c, with no applied
/// voltage, from an initial current i0: `L i' = −R i − K_m ω`, `J ω' = K_m i − c ω` (eqs 11
/// and 12 with the link's Newton equation), i.e. x' = A x with x = (i, ω). Closed form:
/// `e^{At} = e^{λ1 t} I + (e^{λ1 t} − e^{λ2 t}) / (λ1 − λ2) (A − λ1 I)` (Putzer; λ the
/// eigenvalues of A, complex here: the motor rings).
fn motor_closed_form(a: &Matrix2<f64>, x0: &Vector2<f64>, t: f64) -> Vector2<f64> {
    let (tr, det) = (a.trace(), a.determinant());
    let disc = Complex::new(tr * tr - 4.0 * det, 0.0).sqrt();
    let (l1, l2) = ((tr + disc) / 2.0, (tr - disc) / 2.0);
    let (e1, e2) = ((l1 * t).exp(), (l2 * t).exp());
    let k = (e1 - e2) / (l1 - l2);
    let ac = a.map(|x| Complex::new(x, 0.0));
    let m = nalgebra::Matrix2::identity() * e1 + (ac - nalgebra::Matrix2::identity() * l1) * k;
    let x = m * x0.map(|x| Complex::new(x, 0.0));
    assert!(x.iter().all(|c| c.im.abs() <= 1e-9 * (1.0 + c.re.abs())), "{x:?}");
    x.map(|c| c.re)
}

/// The resting arm's yaw joint alone: the other joints are held by the table and their motors
/// carry no current, the rods lie in the plane of rotation, so the yaw axis sees the constant
/// inertia of the rods (m l²/12 about each centre plus m d² to the axis: the parallel-axis
/// theorem, by hand from the URDF's numbers) plus the rotor's J_m = I_m k², and the friction
/// D + D_m k². Its winding is given L = 0.5 H (L/R = 0.45 s, so that the current drives the
/// inertia long enough for the back-EMF to matter). A full `sim` run from i0 = 5 A must follow
/// the closed form: current and speed to 1e-8 of their largest values (dopri45 at rtol 1e-10),
/// at every sample of 0.5 s.
#[test]
fn dc_motor_with_inertia_follows_its_closed_form() {
    let scene = resting()
        .vary(|s| {
            s.motor.inductance = PerJoint::Each(vec![0.5, 0.0017, 0.0017]);
            s.initial.current = PerJoint::Each(vec![5.0, 0.0, 0.0]);
        })
        .unwrap();
    // the URDF: link1 a disc (izz 6.25e-4), link2 2 kg x 0.4 m from the axis, link3 1 kg x 0.3 m
    // starting 0.4 m out
    let j_links = 0.000625 + (2.0 * 0.4 * 0.4 / 12.0 + 2.0 * 0.2 * 0.2) + (0.3 * 0.3 / 12.0 + 0.55 * 0.55);
    let (k, r, l, im, gear, dm, d) = (0.203, 1.1, 0.5, 0.000164, 3.0, 0.01, 0.5);
    let (km, jm) = (k * gear, im * gear * gear);
    let (j, c) = (j_links + jm, d + dm * gear * gear);
    let a = Matrix2::new(-r / l, -km / l, km / j, -c / j);
    let x0 = Vector2::new(5.0, 0.0);
    let run = scene.run("resting").unwrap().clone();
    let mut out = Vec::new();
    sim::run::simulate(&scene, &run, |o| {
        out.push((o.t, o.current.clone(), o.qd.clone(), o.back_emf.clone(), o.tau_motor.clone()));
        Ok(())
    })
    .unwrap();
    let exact: Vec<Vector2<f64>> = out.iter().map(|o| motor_closed_form(&a, &x0, o.0)).collect();
    let peak_i = exact.iter().fold(0.0f64, |m, x| m.max(x[0].abs()));
    let peak_w = exact.iter().fold(0.0f64, |m, x| m.max(x[1].abs()));
    assert!(peak_w > 1.0, "the motor turns: peak speed {peak_w} rad/s");
    for ((t, i, qd, emf, tau), x) in out.iter().zip(&exact) {
        assert!((i[0] - x[0]).abs() <= 1e-8 * peak_i, "t = {t}: i = {} A, closed form {} A", i[0], x[0]);
        assert!((qd[0] - x[1]).abs() <= 1e-8 * peak_w, "t = {t}: w = {} rad/s, closed form {} rad/s", qd[0], x[1]);
        // the back-EMF opposes the motion; the torque on the link is K_m i - J_m w' - D_m w
        assert!((emf[0] - km * qd[0]).abs() <= 1e-12 * km * peak_w, "t = {t}");
        let w_dot = (km * x[0] - c * x[1]) / j;
        assert!((tau[0] - (km * x[0] - jm * w_dot - dm * gear * gear * x[1])).abs() <= 1e-7 * km * peak_i, "t = {t}: tau {}", tau[0]);
        // the held joints stay still and carry no current
        assert!(qd[1].abs() < 1e-9 && qd[2].abs() < 1e-9 && i[1].abs() < 1e-9 && i[2].abs() < 1e-9, "t = {t}: {qd:?} {i:?}");
    }
}

/// Without elbows the arm sags under gravity: the hand is below its target for most of the run
/// and its largest z error is downward (the paper's Fig. 2); with two elbows much less so.
#[test]
fn the_unsupported_hand_sags_downward() {
    let scene = Scene::paper().unwrap().vary(|s| s.duration = 2.0).unwrap();
    let z_errors = |run: &str| -> Vec<f64> { record(&scene, run).hand.iter().map(|(_, h)| h.error.z).collect() };
    let free = z_errors("no-elbow");
    let below = free.iter().filter(|&&z| z < 0.0).count() as f64 / free.len() as f64;
    let lowest = free.iter().copied().fold(f64::INFINITY, f64::min);
    let highest = free.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    assert!(below > 0.9, "below the target {:.0} % of the time", below * 100.0);
    assert!(lowest < -0.1 && -lowest > 10.0 * highest.max(0.0), "z error from {lowest} to {highest} m");
    let supported = z_errors("two-elbow");
    let lowest_supported = supported.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(lowest_supported > 0.5 * lowest, "two elbows: lowest {lowest_supported} m, none: {lowest} m");
}
