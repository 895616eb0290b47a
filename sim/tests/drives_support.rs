//! Set-ups the drive tests share (issue 26: `drive_features.rs`, `stiff_methods.rs`,
//! `thermal.rs`, `convergence.rs`): the gear law and the supply of the all-features scenes, the
//! lead screw on which every entry of the q̈ row is modelled, the structured Jacobian against
//! central differences block by block, the difference Jacobian RODAS takes against central
//! differences, and the convergence harness's order checks.

use std::ops::Range;

use sim::integrate::{fd_jacobian_columns_within, DifferenceIncrement, OdeJacobian as _, Watch};
use sim::ode::ArmSystem;
use sim::scene::spec::{BusSpec, GearFrictionSpec, PerJoint, PerJointFlag, SupplySpec};
use sim::scene::Scene;

use crate::convergence::slope;

/// Gear friction on every joint: Coulomb `coulomb`, breakaway `breakaway` (N m), Stribeck
/// speed `stribeck` (rad/s), forward and backward efficiencies `eta`, `eta_b`.
pub(crate) fn gear_law(coulomb: f64, breakaway: f64, stribeck: f64, eta: f64, eta_b: f64) -> GearFrictionSpec {
    GearFrictionSpec {
        coulomb: Some(PerJoint::All(coulomb)),
        breakaway: Some(PerJoint::All(breakaway)),
        stribeck_velocity: Some(PerJoint::All(stribeck)),
        efficiency: Some(PerJoint::All(eta)),
        back_efficiency: Some(PerJoint::All(eta_b)),
    }
}

/// The gear law of the all-features scenes: τ_c 0.2, τ_s 0.3 N m, Stribeck speed 0.05 rad/s,
/// η 0.85, η_b 0.7 (a small gearbox's range, issue 26).
pub(crate) fn gears() -> GearFrictionSpec {
    gear_law(0.2, 0.3, 0.05, 0.85, 0.7)
}

/// No regeneration in the drives, a bus of η_s 0.9 that dumps its surplus.
pub(crate) fn dumping_bus() -> SupplySpec {
    SupplySpec { regeneration: Some(PerJointFlag::All(false)), bus: Some(BusSpec { efficiency: Some(0.9), regeneration: false }) }
}

/// A slider of 2 kg on a vertical lead screw (a prismatic joint: no Coriolis, no gravity
/// stiffness, so every entry of its q̈ row is one the structured Jacobian models).
const LIFT_URDF: &str = r#"<robot name="lift"><link name="base"/><joint name="screw" type="prismatic"><parent link="base"/><child link="slider"/><axis xyz="0 0 1"/><limit lower="-1e4" upper="1e4" effort="1e4" velocity="1e3"/></joint><link name="slider"><inertial><mass value="2"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>"#;

/// The lead-screw scene (a motor of K 0.05, R 1 Ω, inductance `inductance` H through a 2 mm
/// lead, 1256.6:1), its PD holding 0.1 m; `extra`: more top-level members of the scene
/// (`"drives": …, "thermal": …,`, each with its trailing comma), or "".
#[allow(clippy::result_large_err)] // Scene::from_json's reader closure
pub(crate) fn lift(inductance: f64, extra: &str) -> Scene {
    let json = format!(
        r#"{{"name":"lift","urdf":"lift.urdf","gravity":[0,0,-9.81],"duration":0.3,"output_rate":1000,"joint_damping":0.1,
        "motor":{{"torque_constant":0.05,"resistance":1.0,"inductance":{inductance},"rotor_inertia":1e-6,"gear_ratio":1256.6370614359173,"gear_damping":0}},
        {extra}
        "controller":{{"kp":10,"kd":1}},"hand":{{"link":"slider"}},
        "target":{{"kind":"joint-spline","waypoints":[{{"t":0,"q":[0.1]}},{{"t":1,"q":[0.1]}}]}},
        "initial":{{"q":0}},"integrator":{{"method":"dopri45","rtol":1e-9,"atol":1e-11}},"runs":[{{"name":"lift","contacts":[]}}]}}"#
    );
    Scene::from_json(&json, "lift.json", |_| Ok(LIFT_URDF.to_string())).unwrap()
}

/// The structured Jacobian `j` against central differences `fd` (both row-major, `dim × dim`,
/// at y with f = f(t, y)) on the blocks it models exactly: each entry to 1e-7 of its own size
/// plus 1e-7 of its block's largest entry (a scale per block: a current rate is ~1e3 where a
/// q̈ entry is ~1), plus the rounding of the differences, `4 eps |f_r| / h` with the
/// differences' `h = 1e-6 (1 + |y_c|)` (`stiff_methods::central_jacobian`). `seen(r, c, fd)`
/// is called for every entry checked; returns how many.
pub(crate) fn assert_blocks_match(
    what: &str,
    y: &[f64],
    f: &[f64],
    j: &[f64],
    fd: &[f64],
    blocks: &[(Range<usize>, Vec<Range<usize>>)],
    mut seen: impl FnMut(usize, usize, f64),
) -> usize {
    let dim = y.len();
    let mut checked = 0;
    for (rows, column_groups) in blocks {
        for cols in column_groups {
            let scale = rows.clone().flat_map(|r| cols.clone().map(move |c| fd[r * dim + c].abs())).fold(0.0, f64::max);
            for r in rows.clone() {
                for c in cols.clone() {
                    let (a, b) = (j[r * dim + c], fd[r * dim + c]);
                    // truncation O(h²) well under 1e-7 of the block; rounding eps |f_r| / h of
                    // the differences themselves
                    let h = 1e-6 * (1.0 + y[c].abs());
                    let tol = 1e-7 * (b.abs() + scale) + 4.0 * f64::EPSILON * (f[r].abs() + 1.0) / h;
                    assert!((a - b).abs() <= tol, "{what}: d f[{r}] / d y[{c}]: structured {a}, differences {b} (block scale {scale:e})");
                    seen(r, c, b);
                    checked += 1;
                }
            }
        }
    }
    checked
}

/// The Jacobian RODAS takes on the arm — forward differences over the coupled columns with the
/// arm's increment (`ArmSystem::difference_increment`) — against the central differences `fd`
/// over every column: the quadrature columns of `fd` exactly 0, every coupled entry to 1e-6 of
/// its row's largest, plus the forward differences' rounding `128 eps max|f| / delta`, plus
/// their truncation `delta |f''| / 2`, measured as 4 times the change when the increment is
/// halved (a column taken wrongly, or a term missing from f's differences, does not halve).
pub(crate) fn assert_rodas_differences(sys: &mut ArmSystem, t: f64, y: &[f64], f: &[f64], fd: &[f64], what: &str) {
    let dim = y.len();
    let nc = sys.coupled_dim();
    // a run with contact modes leaves it to the stepper (its floor atol / rtol: 1e-2 here)
    let inc = sys.difference_increment().unwrap_or(DifferenceIncrement { noise: f64::EPSILON, floor: 1e-2 });
    let half = DifferenceIncrement { noise: inc.noise / 4.0, ..inc };
    let (mut jf, mut jh) = (vec![0.0; dim * dim], vec![0.0; dim * dim]);
    let (mut sy, mut sf) = (vec![0.0; dim], vec![0.0; dim]);
    fd_jacobian_columns_within(sys, t, y, f, &mut jf, nc, inc, &mut sy, &mut sf, Watch::default()).unwrap();
    fd_jacobian_columns_within(sys, t, y, f, &mut jh, nc, half, &mut sy, &mut sf, Watch::default()).unwrap();
    let fmax = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for r in 0..dim {
        let scale = (0..nc).map(|c| fd[r * dim + c].abs()).fold(0.0, f64::max);
        for c in 0..dim {
            if c >= nc {
                assert_eq!(fd[r * dim + c], 0.0, "{what}: d f[{r}] / d y[{c}] (a quadrature column)");
                continue;
            }
            let k = r * dim + c;
            let delta = inc.noise.sqrt() * y[c].abs().max(inc.floor);
            let tol = 1e-6 * scale + 128.0 * f64::EPSILON * (fmax + 1.0) / delta + 4.0 * (jf[k] - jh[k]).abs();
            assert!((jf[k] - fd[k]).abs() <= tol, "{what}: RODAS d f[{r}] / d y[{c}]: forward {}, central {} (halved increment {}; row scale {scale:e}, tol {tol:e})", jf[k], fd[k], jh[k]);
        }
    }
}

/// The convergence harness's checks on one adaptive method's ladder: `runs` = (error, work)
/// per rtol of `tols`; the error falls as work^-order (± 0.5) and as rtol (± 0.15).
pub(crate) fn assert_orders(method: &str, order: f64, tols: &[f64], runs: &[(f64, f64)]) {
    let (e, n): (Vec<f64>, Vec<f64>) = runs.iter().copied().unzip();
    let p = -slope(&n, &e);
    assert!((p - order).abs() <= 0.5, "{method}: error ~ N^-{p:.2}, order {order} ({runs:?})");
    let q = slope(tols, &e);
    assert!((q - 1.0).abs() <= 0.15, "{method}: error ~ rtol^{q:.2} ({runs:?})");
}
