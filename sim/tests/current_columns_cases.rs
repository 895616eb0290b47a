//! The exact current columns (`ode/current_columns.rs`) and the exact `∂f/∂t`
//! (`ode/time_derivative.rs`) on the scenes whose terms the paper scenes do not exercise, and
//! the fallbacks asserted TAKEN (issue 24, the review of the seventh pass), each against
//! central differences of full right-hand sides (`current_columns.rs`'s `check`, δ = 1e-3 A):
//!
//! - written and exact (to 1e-9 of the row block's largest entry, `check`: f is affine in i
//!   for fixed q, q̇ and modes, so only rounding remains): `pd-gravity` with and without its
//!   friction feed-forward and a back-EMF constant K_e ≠ K_m (the conversion loss's column
//!   `(K_e − K_m) q̇`; `∂f/∂t` with the feed-forward's `K_e k q̈_d` and `R/K_m (D + D_m) q̈_d`,
//!   to 1e-7, `check_time_derivative`); Baumgarte-stabilised bilateral constraints (the bias
//!   `−2α Ċ − β² C` does not read i; `Q = M_c⁻¹ K_m`); a compliant contact in touch beside a
//!   unilateral one (its spring-damper force does not read i, so the columns are exact, not
//!   declined).
//! - declined (`exact_columns` returns `Ok(false)` and writes nothing), the columns then
//!   differenced as RODAS does: in a stick → slip onset, where the margin rule chose a
//!   statically indeterminate contact's force (whose A is singular too: the pivot rule
//!   declines those states as well, pivot ratios 1e-16), with gear friction, a supply, the
//!   thermal model, a current loop. The differenced columns match the central ones to
//!   [`declined_bound`]. (A near-singular A whose forces are the solve's λ was not reached from
//!   a scene: a point 1e-6 … 3e-5 m off joint 3's axis point never sticks, and at 1e-7 m the
//!   indeterminate rule takes it.)

#![allow(clippy::result_large_err)]

use sim::dynamics::contact::ContactMode;
use sim::dynamics::forward::Stabilization;
use sim::integrate::{fd_jacobian_column_range_within, DifferenceIncrement, HybridSystem as _, OdeJacobian as _, OdeSystem, Watch};
use sim::ode::{ArmSystem, Outputs};
use sim::scene::spec::{InitialQ, LawSpec, PerJoint, RunSpec};
use sim::scene::Scene;

use crate::current_columns::{central_current_columns, check, check_time_derivative, row_block};
use crate::drives_support::{dumping_bus, gears};
use crate::rng_support::Lcg;

type State = (f64, Vec<f64>, Vec<f64>, Vec<f64>);

fn load(name: &str) -> Scene {
    Scene::load(std::path::Path::new(&format!("{}/scenes/{name}", env!("CARGO_MANIFEST_DIR")))).unwrap()
}

/// `n` states (t, q, q̇, i) of the paper's bilateral two-elbow run over its first 0.3 s: both
/// elbows on z = 0 at rest relative to it, the currents those of the circle's tracking.
fn paper_states(n: usize) -> Vec<State> {
    states_of("paper.json", "two-elbow", n)
}

/// `n` states (t, q, q̇, i) of the run `run` of the scene file `file` over its first 0.3 s.
fn states_of(file: &str, run: &str, n: usize) -> Vec<State> {
    let scene = load(file).vary(|s| s.duration = 0.3).unwrap();
    let mut out = Vec::new();
    sim::run::simulate(&scene, scene.run(run).unwrap(), |o| {
        if out.len() < n && o.t >= 0.3 / n as f64 * (out.len() + 1) as f64 - 1e-9 {
            out.push((o.t, o.q.clone(), o.qd.clone(), o.current.clone()));
        }
        Ok(())
    })
    .unwrap();
    assert_eq!(out.len(), n);
    out
}

/// The system of `scene`'s run `run` at `(q, q̇, i)` with its contact and drive modes chosen
/// as a run's start chooses them (`init_modes`); `None` where no consistent contact forces
/// exist (Painlevé).
fn system_at<'a>(scene: &'a Scene, run: &str, t: f64, q: &[f64], qd: &[f64], cur: &[f64]) -> Option<(ArmSystem<'a>, Vec<f64>)> {
    let mut sys = ArmSystem::new(scene, scene.run(run).unwrap());
    let l = sys.layout();
    let mut y = sys.initial_state();
    y[l.q()].copy_from_slice(q);
    y[l.qd()].copy_from_slice(qd);
    y[l.current()].copy_from_slice(cur);
    sys.init_modes(t, &mut y).ok()?;
    Some((sys, y))
}

/// The contacts' recorded quantities at `(t, y)`.
fn contacts_at(sys: &mut ArmSystem, t: f64, y: &[f64]) -> Vec<sim::dynamics::contact::ContactOutput> {
    let mut o = Outputs::default();
    sys.outputs(t, y, &mut o).unwrap();
    o.contacts
}

/// What a declined column may differ from the central one by, relative to its row block's
/// largest entry: 1e-5, for the truncation of the two differences where f is not affine in i
/// (the forward one's `h |∂²f/∂i²| / 2`: the copper heating `R i²` of the thermal model's
/// winding row gives `h / (2 |i|)` of the block, 1.6e-6 at 0.1 A with RODAS's h = 3.2e-7 A
/// on a run without contacts, measured 1.8e-6; the central one's `δ² |∂³f/∂i³| / 6` with
/// δ = 1e-3 A, as in an onset whose anchor turns with b), plus the forward difference's
/// rounding `2 · 1e-13 |f|_block / h` (f's noise bound, `ode/jacobian.rs`; h RODAS's
/// increment, down to 1.5e-10 A for a current near 0 in a contact run,
/// `sqrt(eps) max(|i|, atol / rtol)`).
fn declined_bound(scale: f64, f_block: f64, h: f64) -> f64 {
    1e-5 * scale + 2e-13 * f_block / h
}

/// Asserts that the system declines its exact current columns at `(t, y)` (`Ok(false)`,
/// nothing written) and that the columns RODAS then differences match the central ones to
/// [`declined_bound`]; returns the largest error relative to the bound.
fn check_declined(sys: &mut ArmSystem, t: f64, y: &[f64], what: &str) -> f64 {
    let n = y.len();
    let l = sys.layout();
    let mut f = vec![0.0; n];
    sys.rhs(t, y, &mut f).unwrap();
    // the currents' columns are offered (from their start) or not at all (then RODAS
    // differences them in its sweep)
    let k = sys.exact_columns_start().min(l.current().start);
    let inc = sys.difference_increment().unwrap_or(DifferenceIncrement { noise: f64::EPSILON, floor: 1e-2 });
    let (mut sy, mut sf) = (vec![0.0; n], vec![0.0; n]);
    let mut jac = vec![f64::NAN; n * n];
    // as RODAS calls it: the sweep over the leading columns, then the exact ones
    fd_jacobian_column_range_within(sys, t, y, &f, &mut jac, 0..k, inc, &mut sy, &mut sf, Watch::default()).unwrap();
    assert!(!sys.exact_columns(t, y, &f, &mut jac).unwrap(), "{what} (modes {:?}): the exact current columns were given", sys.contact_modes());
    for c in l.current() {
        assert!((0..n).all(|r| jac[r * n + c].is_nan()), "{what}: declined, but column {c} was written");
    }
    // the columns RODAS differences when the system declines
    fd_jacobian_column_range_within(sys, t, y, &f, &mut jac, l.current(), inc, &mut sy, &mut sf, Watch::default()).unwrap();
    let central = central_current_columns(sys, t, y);
    let mut worst = 0.0f64;
    for r in 0..n {
        let block = row_block(sys, r);
        let scale = block.clone().flat_map(|i| l.current().map(move |c| (i, c))).map(|(i, c)| central[i * n + c].abs()).fold(0.0, f64::max);
        let f_block = block.map(|i| f[i].abs()).fold(0.0, f64::max);
        for c in l.current() {
            let h = inc.noise.max(f64::EPSILON).sqrt() * y[c].abs().max(inc.floor);
            let (a, b) = (jac[r * n + c], central[r * n + c]);
            let bound = declined_bound(scale, f_block, h);
            let err = (a - b).abs();
            assert!(err <= bound, "{what}: d f[{r}] / d y[{c}]: differenced {a:e}, central {b:e}, error {err:.1e} > bound {bound:.1e} (block {scale:.2e})");
            if bound > 0.0 {
                worst = worst.max(err / bound);
            }
        }
    }
    worst
}

/// Half the states with the joint speeds and currents moved at random (so that contacts
/// slide, leave, and the motors' terms differ from the tracking run's).
fn moved(rng: &mut Lcg, k: usize, qd: &[f64], cur: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let (mut qd, mut cur) = (qd.to_vec(), cur.to_vec());
    if k % 2 == 1 {
        for j in 0..qd.len() {
            qd[j] += 0.3 * rng.next();
            cur[j] += 2.0 * rng.next();
        }
    }
    (qd, cur)
}

/// `pd-gravity` (with and without its friction feed-forward) on motors with a back-EMF
/// constant K_e = 1.3 K_m: the exact current columns equal the central differences to 1e-9
/// of the row block (the conversion loss's `(K_e − K_m) q̇` among them) and the exact ∂f/∂t
/// to 1e-7 (the feed-forward's `K_e k q̈_d` and `R/K_m (D + D_m) q̈_d`), at 8 states of each
/// of the unilateral runs two-elbow and one-elbow and of the bilateral two-elbow and
/// no-elbow runs. The controller's gravity term `R/K_m g(q)` reads q only: no term in the
/// current columns (checked: they are the central ones) nor in ∂f/∂t.
#[test]
fn pd_gravity_and_a_back_emf_constant_keep_the_columns_and_f_t_exact() {
    let states = paper_states(8);
    let mut rng = Lcg(77);
    let (mut exact, mut declined, mut worst, mut worst_t) = (0, 0, 0.0f64, 0.0f64);
    for friction in [false, true] {
        let with = |s: &mut sim::scene::spec::SceneSpec| {
            s.controller.law = Some(LawSpec::PdGravity);
            s.controller.friction = Some(friction);
            s.motor.back_emf_constant = Some(PerJoint::All(1.3 * 0.203));
        };
        let unilateral = load("paper_unilateral.json").vary(with).unwrap();
        let bilateral = load("paper.json").vary(with).unwrap();
        for (scene, run) in [(&unilateral, "two-elbow-unilateral"), (&unilateral, "one-elbow-unilateral"), (&bilateral, "two-elbow"), (&bilateral, "no-elbow")] {
            assert_ne!(scene.drives().ke[0], scene.drives().km[0], "K_e = K_m");
            for (k, (t, q, qd, cur)) in states.iter().enumerate() {
                let (qd, cur) = moved(&mut rng, k, qd, cur);
                let Some((mut sys, y)) = system_at(scene, run, *t, q, &qd, &cur) else { continue };
                let what = format!("pd-gravity (friction {friction}) {run} state {k}");
                worst_t = worst_t.max(check_time_derivative(&mut sys, *t, &y, &what));
                match check(&mut sys, *t, &y, &what) {
                    Some(e) => {
                        exact += 1;
                        worst = worst.max(e);
                    }
                    None => declined += 1,
                }
            }
        }
    }
    eprintln!("pd-gravity, K_e = 1.3 K_m: {exact} states exact (largest error {worst:.1e} of the row block), {declined} declined; f_t largest error {worst_t:.1e}");
    assert!(exact >= 56 && declined <= 4, "{exact} exact, {declined} declined");
}

/// Baumgarte's stabilisation (α = β = 20 /s) on the paper's bilateral runs, at states whose
/// constraints are violated (q moved by up to 1e-3 rad, q̇ and i at random): the exact
/// columns (`Q = M_c⁻¹ K_m`, the bias not reading i) equal the central differences to 1e-9 of
/// the row block, and ∂f/∂t to 1e-7, at every state.
#[test]
fn baumgarte_stabilised_constraints_keep_the_columns_exact() {
    let scene = load("paper.json").vary(|s| s.dynamics.stabilization = Stabilization::Baumgarte { alpha: 20.0, beta: 20.0 }).unwrap();
    let mut rng = Lcg(91);
    let mut worst = 0.0f64;
    let mut n = 0;
    for run in ["two-elbow", "one-elbow"] {
        for (k, (t, q, qd, cur)) in paper_states(6).iter().enumerate() {
            let q: Vec<f64> = q.iter().map(|v| v + 1e-3 * rng.next()).collect();
            let (qd, cur) = moved(&mut rng, k, qd, cur);
            let (mut sys, y) = system_at(&scene, run, *t, &q, &qd, &cur).unwrap();
            let what = format!("baumgarte {run} state {k}");
            check_time_derivative(&mut sys, *t, &y, &what);
            worst = worst.max(check(&mut sys, *t, &y, &what).unwrap_or_else(|| panic!("{what}: declined")));
            n += 1;
        }
    }
    eprintln!("baumgarte: {n} states exact, largest error {worst:.1e} of the row block");
}

/// A compliant contact (elbow4: k = 1e5 N/m, c = 300 N s/m, μ = 0.5, its plane 1 mm above
/// the elbow: in touch, pushing) beside a unilateral one (elbow7): its force, a function of
/// q and q̇, does not read i, so the columns are EXACT, not declined (its rows are not in the
/// mode problem; `current_columns.rs` skips it in the forces' check and in the friction
/// work), at every state, to 1e-9 of the row block.
#[test]
fn a_compliant_contact_keeps_the_columns_exact() {
    let scene = load("paper_unilateral.json")
        .vary(|s| {
            let c = s.contacts.iter_mut().find(|c| c.name == "elbow4").unwrap();
            c.model = Some("compliant".into());
            c.restitution = None;
            c.stiffness = Some(1e5);
            c.damping = Some(300.0);
            c.plane.offset = 1e-3;
        })
        .unwrap();
    let mut rng = Lcg(5);
    let (mut n, mut worst) = (0, 0.0f64);
    for (k, (t, q, qd, cur)) in paper_states(8).iter().enumerate() {
        let (qd, cur) = moved(&mut rng, k, qd, cur);
        let Some((mut sys, y)) = system_at(&scene, "two-elbow-unilateral", *t, q, &qd, &cur) else { continue };
        let c = contacts_at(&mut sys, *t, &y);
        assert!(c[0].normal_force > 0.0 && c[0].gap < 0.0, "state {k}: the compliant contact is not in touch: {:?}", (c[0].gap, c[0].normal_force));
        let what = format!("compliant elbow4 state {k} (modes {:?})", sys.contact_modes());
        worst = worst.max(check(&mut sys, *t, &y, &what).unwrap_or_else(|| panic!("{what}: declined")));
        n += 1;
    }
    eprintln!("compliant: {n} states exact, largest error {worst:.1e} of the row block");
    assert!(n >= 6, "{n} states");
}

/// In a stick → slip onset (one-elbow-unilateral, the arm at rest on the table, the currents
/// moved by up to ±30 A until the elbow's stick breaks: it slides from rest, its friction
/// anchored on the sticking force's direction, a function of b), the columns are declined and
/// the differenced ones match the central ones to [`declined_bound`].
#[test]
fn an_onset_declines_the_columns() {
    let scene = load("paper_unilateral.json");
    let mut rng = Lcg(11);
    let (mut n, mut worst, mut tries) = (0, 0.0f64, 0);
    for (k, (t, q, _, cur)) in paper_states(8).iter().enumerate() {
        for _ in 0..20 {
            tries += 1;
            let cur: Vec<f64> = cur.iter().map(|c| c + 30.0 * rng.next()).collect();
            let qd = vec![0.0; q.len()];
            let Some((mut sys, y)) = system_at(&scene, "one-elbow-unilateral", *t, q, &qd, &cur) else { continue };
            if sys.contact_modes()[0] != ContactMode::Sliding {
                continue;
            }
            let what = format!("onset state {k}");
            worst = worst.max(check_declined(&mut sys, *t, &y, &what));
            n += 1;
            break;
        }
    }
    eprintln!("onset: {n} states (of {tries} draws) declined, differences within {worst:.1e} of the bound");
    assert!(n >= 6, "{n} onsets");
}

/// A statically indeterminate contact whose force the margin rule chose: a sticking contact at
/// joint 3's origin (moved by joints 1 and 2 only: rows of rank 2, `indeterminate.rs`), its
/// plane through the point, the arm at rest, the currents moved at random: wherever it
/// sticks the columns are declined (the force is not the solve's λ; A = W M_J⁻¹ Wᵀ of the
/// rank-2 rows is singular too, so the pivot rule is the backstop: with the forces' check
/// deleted it declines the same states), and the differenced ones match the central ones to
/// [`declined_bound`].
#[test]
fn a_force_the_margin_rule_chose_declines_the_columns() {
    let base = load("paper_unilateral.json");
    let mut rng = Lcg(23);
    let (mut n, mut worst) = (0, 0.0f64);
    for (k, (t, q, _, cur)) in paper_states(8).iter().enumerate() {
        let qd = vec![0.0; q.len()];
        // the plane through joint 3's origin at q
        let probe = base
            .vary(|s| {
                s.runs = vec![RunSpec { name: "shoulder".into(), contacts: vec!["joint3".into()] }];
                s.contacts.retain(|c| c.name == "joint3");
            })
            .unwrap();
        let (mut sys, y) = system_at(&probe, "shoulder", *t, q, &qd, cur).unwrap();
        let mut o = Outputs::default();
        sys.outputs(*t, &y, &mut o).unwrap();
        let z = o.contact_point[0].z;
        let scene = probe
            .vary(|s| {
                let c = s.contacts.iter_mut().find(|c| c.name == "joint3").unwrap();
                c.plane.offset = z;
                s.initial.q = InitialQ::Values(PerJoint::Each(q.clone()));
            })
            .unwrap();
        for _ in 0..10 {
            let cur: Vec<f64> = cur.iter().map(|c| c + 5.0 * rng.next()).collect();
            let Some((mut sys, y)) = system_at(&scene, "shoulder", *t, q, &qd, &cur) else { continue };
            if sys.contact_modes()[0] != ContactMode::Sticking {
                continue;
            }
            let what = format!("indeterminate joint3 state {k}");
            worst = worst.max(check_declined(&mut sys, *t, &y, &what));
            n += 1;
        }
    }
    eprintln!("margin rule: {n} sticking states declined, differences within {worst:.1e} of the bound");
    assert!(n >= 10, "{n} sticking states");
}

/// Gear friction, a supply without regeneration, the thermal model and a current loop
/// (computed torque with k_i = 5 V/A) make f's dependence on i not the formula's (efficiency
/// switches and locks, R(T_w), the loop's `k_i i` in v): the system offers no exact columns
/// (`exact_columns_start() == coupled_dim()`, so RODAS differences them all) and
/// `exact_columns` declines at every state; the differenced columns match the central ones
/// to [`declined_bound`]. On the unilateral runs (gears, current loop) and the bilateral ones
/// (supply, thermal).
#[test]
fn drive_features_and_a_current_loop_decline_the_columns() {
    let unilateral = load("paper_unilateral.json");
    let bilateral = load("paper.json");
    let thermal = load("drives/paper_thermal.json");
    let cases = [
        ("gear friction", unilateral.vary(|s| s.gear_friction = Some(gears())).unwrap(), "two-elbow-unilateral"),
        ("supply", bilateral.vary(|s| s.supply = Some(dumping_bus())).unwrap(), "two-elbow"),
        ("thermal model", thermal, "two-elbow"),
        (
            "current loop",
            unilateral
                .vary(|s| {
                    s.controller.law = Some(LawSpec::ComputedTorque);
                    s.controller.kp = PerJoint::All(400.0);
                    s.controller.kd = PerJoint::All(40.0);
                    s.controller.current_gain = Some(PerJoint::All(5.0));
                })
                .unwrap(),
            "one-elbow-unilateral",
        ),
    ];
    let states = paper_states(6);
    let mut rng = Lcg(57);
    for (what, scene, run) in &cases {
        let (mut n, mut worst) = (0, 0.0f64);
        for (k, (t, q, qd, cur)) in states.iter().enumerate() {
            let (qd, cur) = moved(&mut rng, k, qd, cur);
            let Some((mut sys, y)) = system_at(scene, run, *t, q, &qd, &cur) else { continue };
            assert_eq!(sys.exact_columns_start(), sys.coupled_dim(), "{what}: exact columns offered");
            worst = worst.max(check_declined(&mut sys, *t, &y, &format!("{what} {run} state {k}")));
            n += 1;
        }
        eprintln!("{what}: {n} states declined, differences within {worst:.1e} of the bound");
        assert!(n >= 5, "{what}: {n} states");
    }
}
