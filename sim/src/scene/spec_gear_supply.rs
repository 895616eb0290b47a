//! The scene file's gear friction and supply (issue 26, items 3 and 4), as written, and their
//! validation into [`GearFriction`] and [`Supply`] (`dynamics/gear_friction.rs`,
//! `dynamics/supply.rs` give the laws). Part of [`super::spec`] (re-exported there).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::ctx::{non_negative, within, Ctx};
use super::spec::PerJoint;
use crate::dynamics::gear_friction::GearFriction;
use crate::dynamics::supply::{Bus, Supply};
use crate::error::SceneError;

/// `"gear_friction"`: Coulomb (optionally static and Stribeck) friction of each joint's gear,
/// and its efficiency in each direction of the power flow, at the link side of the gear. Stick
/// and slip, reversals and changes of power direction are events.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GearFrictionSpec {
    /// Coulomb (sliding) friction torque τ_c at the joint, N m (N for a prismatic joint), per
    /// joint; >= 0 (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coulomb: Option<PerJoint>,
    /// Static (breakaway) torque τ_s >= τ_c, N m, per joint (default: τ_c).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub breakaway: Option<PerJoint>,
    /// Stribeck speed v_s > 0, rad/s (m/s), per joint: the sliding friction falls from τ_s to
    /// τ_c as exp(−(q̇/v_s)²) (default: none, τ_c while sliding).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stribeck_velocity: Option<PerJoint>,
    /// Efficiency η while the motor drives the load, 0 < η <= 1, per joint (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub efficiency: Option<PerJoint>,
    /// Efficiency η_b while the load drives the motor (back-driving), 0 < η_b <= 1, per joint
    /// (default: `efficiency`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub back_efficiency: Option<PerJoint>,
}

/// A flag for every joint, or one per joint.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum PerJointFlag {
    All(bool),
    Each(Vec<bool>),
}

/// `"supply"`: the electric supply behind the drives. Absent: each drive's ideal supply takes
/// braking power back (the supply energy is E = Σ ∫ i v dt).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SupplySpec {
    /// Whether each drive's amplifier regenerates (returns braking power to its DC side);
    /// without, braking power is dumped in the drive's brake resistor. One flag or one per
    /// joint (default true).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub regeneration: Option<PerJointFlag>,
    /// A shared DC bus: the drives' DC powers meet on it first, then one supply (default: none,
    /// each drive has its own ideal supply).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bus: Option<BusSpec>,
}

/// `"supply": {"bus": ...}`: the shared DC bus and its supply.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BusSpec {
    /// The supply's efficiency η_s, 0 < η_s <= 1 (both directions; default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub efficiency: Option<f64>,
    /// Whether the supply takes a surplus of the bus back (else the bus's brake resistor dumps
    /// it; default false).
    #[serde(default)]
    pub regeneration: bool,
}

fn efficiency(x: f64) -> bool {
    x > 0.0 && x <= 1.0
}

/// The scene's gear friction, validated (`None` when absent).
pub(super) fn gear_friction(c: &Ctx, spec: Option<&GearFrictionSpec>, nv: usize, passive: &[bool]) -> Result<Option<GearFriction>, SceneError> {
    let Some(g) = spec else { return Ok(None) };
    let per = |field: &str, p: &Option<PerJoint>, ok: fn(f64) -> bool, why: &str, default: &[f64]| -> Result<Vec<f64>, SceneError> {
        match p {
            Some(p) => c.per_joint(&format!("gear_friction.{field}"), p, nv, ok, why),
            None => Ok(default.to_vec()),
        }
    };
    let coulomb = per("coulomb", &g.coulomb, non_negative, "must be >= 0 N m", &vec![0.0; nv])?;
    let breakaway = per("breakaway", &g.breakaway, non_negative, "must be >= 0 N m", &coulomb)?;
    let stribeck_velocity = per("stribeck_velocity", &g.stribeck_velocity, |x| x > 0.0, "must be > 0 rad/s", &vec![0.0; nv])?;
    let eta = per("efficiency", &g.efficiency, efficiency, "must be within 0 < efficiency <= 1", &vec![1.0; nv])?;
    let eta_b = per("back_efficiency", &g.back_efficiency, efficiency, "must be within 0 < back_efficiency <= 1", &eta)?;
    for j in 0..nv {
        if breakaway[j] < coulomb[j] {
            let f = if matches!(g.breakaway, Some(PerJoint::Each(_))) { format!("gear_friction.breakaway[{j}]") } else { "gear_friction.breakaway".into() };
            return Err(c.err(f, breakaway[j], format!("must be >= the Coulomb torque {} N m", coulomb[j])));
        }
        if passive[j] && (eta[j] != 1.0 || eta_b[j] != 1.0) {
            return Err(c.err(format!("gear_friction.efficiency[{j}]"), eta[j], "a passive joint has no motor to drive through a gear: leave its efficiency at 1"));
        }
    }
    // limits keep the numbers physical: within((0, 1e6)) as the motor values (motor_bounds)
    for (field, v) in [("coulomb", &coulomb), ("breakaway", &breakaway)] {
        if let Some(j) = v.iter().position(|&x| !within(0.0, 1e6)(x)) {
            return Err(c.err(format!("gear_friction.{field}[{j}]"), v[j], "must be within 0 ..= 1e6 N m"));
        }
    }
    Ok(Some(GearFriction { coulomb, breakaway, stribeck_velocity, efficiency: eta, back_efficiency: eta_b }))
}

/// rk4 is refused with an efficiency-only gear (an efficiency below 1 and no breakaway torque
/// on some joint): that gear's stick band is `(1/η_b − η) |K_m i|` wide, a point where its
/// current is 0, and whether the joint sticks there is decided by how its torques leave 0
/// within nanoseconds (`ode/gear_decide.rs`). Measured on the paper arm (η 0.8 / η_b 0.7,
/// no-elbow): with rk4 steps of 5e-5 s and longer joints 5 and 8 switch 33 times at t = 0 and
/// the run stops; 2e-5 s runs the first 0.3 s; the adaptive methods run. The mechanism, as far
/// as traced: a function that starts at 0 is watched from its start value and fires at the
/// restart when it reaches its firing side by more than its tolerance within the first step
/// (`integrate/events.rs`); an adaptive method's first step after a restart is short, rk4's is
/// its fixed step, and the same decision at the same state restarts it without end. Refused
/// before the run starts rather than left to a step size that depends on the scene.
pub(super) fn refuse_fixed_step(c: &Ctx, g: Option<&GearFriction>, method: &str, joint: impl Fn(usize) -> String) -> Result<(), SceneError> {
    let Some(g) = g else { return Ok(()) };
    let bare: Vec<String> = (0..g.nv()).filter(|&j| g.active(j) && g.breakaway[j] == 0.0).map(joint).collect();
    if method != "rk4" || bare.is_empty() {
        return Ok(());
    }
    Err(c.err(
        "integrator.method",
        "rk4",
        format!(
            "cannot run gears with an efficiency below 1 and no breakaway torque ({}): such a gear holds nothing at zero current, and whether its joint sticks or slides there is decided by what its torques do within nanoseconds, which rk4's fixed step cannot follow (its events are located on the step's interpolant and the step does not shrink after a mode change, so the joint switches at the same instant without end); use an adaptive method (dopri45, rosenbrock, imex, rodas5p), or give these gears a breakaway torque (gear_friction.breakaway > 0)",
            bare.join(", ")
        ),
    ))
}

/// The scene's supply, validated (`None` when absent).
pub(super) fn supply(c: &Ctx, spec: Option<&SupplySpec>, nv: usize) -> Result<Option<Supply>, SceneError> {
    let Some(s) = spec else { return Ok(None) };
    let regeneration = match &s.regeneration {
        None => vec![true; nv],
        Some(PerJointFlag::All(b)) => vec![*b; nv],
        Some(PerJointFlag::Each(v)) if v.len() == nv => v.clone(),
        Some(PerJointFlag::Each(v)) => {
            return Err(c.err("supply.regeneration", format!("an array of {}", v.len()), format!("needs one flag per joint ({nv})")))
        }
    };
    let bus = match &s.bus {
        None => None,
        Some(b) => {
            let efficiency = match b.efficiency {
                Some(x) => c.number("supply.bus.efficiency", x, efficiency, "must be within 0 < efficiency <= 1")?,
                None => 1.0,
            };
            Some(Bus { efficiency, regeneration: b.regeneration })
        }
    };
    Ok(Some(Supply { regeneration, bus }))
}
