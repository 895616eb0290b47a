//! The scene's `hand_load`: a rigid payload held at the hand (mass, centre of mass and
//! rotational inertia, in the hand link's frame), validated once and merged into the inertia of
//! the body that carries the hand link, as a fixed child link's `<inertial>` is merged
//! (`dynamics/model.rs`; Featherstone, *Rigid Body Dynamics Algorithms*, 2008, eq 2.63 for the
//! inertia about the centre of mass and eq 2.66 for its change of frame). A payload is a
//! physical body, so its rotational inertia must be positive semi-definite and its principal
//! moments must satisfy the triangle inequality (Traversaro, Brossette, Escande and Nori,
//! IROS 2016), the same checks as a URDF link's.
//!
//! Absent, nothing changes: the model is the URDF's, bit for bit.

use nalgebra::{Matrix3, Vector3};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::ctx::Ctx;
use super::spec::PointSpec;
use crate::dynamics::spatial::Inertia;
use crate::dynamics::Model;
use crate::error::{short, SceneError};

/// Largest payload mass, kg (a bound on input, far above any arm's payload).
pub const MAX_LOAD_MASS: f64 = 1e4;

/// `"hand_load"`: a payload rigidly held at the hand, in the hand link's frame (the link of
/// `hand`: the link it names, or the child link of the joint it names).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HandLoadSpec {
    /// The payload's mass, kg (0 <= mass <= 1e4; 0: no payload).
    pub mass: f64,
    /// The payload's centre of mass in the hand link's frame, m (default: the hand point,
    /// `hand.offset`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub com: Option<[f64; 3]>,
    /// The payload's rotational inertia about its centre of mass, in the hand link's axes,
    /// kg m^2 (default: all 0, a point mass).
    #[serde(default, skip_serializing_if = "LoadInertiaSpec::is_zero")]
    pub inertia: LoadInertiaSpec,
}

/// A rotational inertia about the centre of mass, as a URDF `<inertia>` writes it, kg m^2;
/// every entry defaults to 0.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LoadInertiaSpec {
    /// I_xx, kg m^2 (default 0).
    #[serde(default)]
    pub ixx: f64,
    /// I_yy, kg m^2 (default 0).
    #[serde(default)]
    pub iyy: f64,
    /// I_zz, kg m^2 (default 0).
    #[serde(default)]
    pub izz: f64,
    /// I_xy, kg m^2 (default 0).
    #[serde(default)]
    pub ixy: f64,
    /// I_xz, kg m^2 (default 0).
    #[serde(default)]
    pub ixz: f64,
    /// I_yz, kg m^2 (default 0).
    #[serde(default)]
    pub iyz: f64,
}

impl LoadInertiaSpec {
    pub fn is_zero(&self) -> bool {
        *self == LoadInertiaSpec::default()
    }

    fn matrix(&self) -> Matrix3<f64> {
        Matrix3::new(self.ixx, self.ixy, self.ixz, self.ixy, self.iyy, self.iyz, self.ixz, self.iyz, self.izz)
    }
}

/// The URDF link the hand point belongs to (its `link`, or its `joint`'s child link).
fn hand_link(c: &Ctx, model: &Model, hand: &PointSpec) -> Result<String, SceneError> {
    match (&hand.joint, &hand.link) {
        (Some(j), None) => model.urdf_joints.iter().find(|u| &u.name == j).map(|u| u.child_link.clone()).ok_or_else(|| c.err("hand.joint", j, "no such joint in the URDF")),
        (None, Some(l)) => Ok(l.clone()),
        _ => Err(c.err("hand", "", "give exactly one of `joint` (its origin) or `link`")),
    }
}

/// The payload as an inertia about the hand link's origin in its axes, checked; errors name
/// `hand_load.<field>` and the value.
pub(super) fn load_inertia(c: &Ctx, spec: &HandLoadSpec, hand: &PointSpec) -> Result<Inertia, SceneError> {
    let m = c.number("hand_load.mass", spec.mass, |x| (0.0..=MAX_LOAD_MASS).contains(&x), "must be in [0, 1e4] kg")?;
    let com = match spec.com {
        Some(p) => c.vec3("hand_load.com", p)?,
        None => Vector3::from(hand.offset),
    };
    let i = &spec.inertia;
    for (k, x) in [("ixx", i.ixx), ("iyy", i.iyy), ("izz", i.izz), ("ixy", i.ixy), ("ixz", i.ixz), ("iyz", i.iyz)] {
        c.number(&format!("hand_load.inertia.{k}"), x, |_| true, "")?;
    }
    let i_com = i.matrix();
    let written = || format!("ixx={} iyy={} izz={} ixy={} ixz={} iyz={}", short(i.ixx), short(i.iyy), short(i.izz), short(i.ixy), short(i.ixz), short(i.iyz));
    if m == 0.0 && !i.is_zero() {
        return Err(c.err("hand_load.inertia", written(), "a payload of mass 0 with a non-zero inertia is not a physical body: give its mass, or drop the inertia"));
    }
    // principal moments, ascending: positive semi-definite and the triangle inequality
    let mut lam: Vec<f64> = i_com.symmetric_eigen().eigenvalues.iter().copied().collect();
    lam.sort_by(f64::total_cmp);
    let tol = 1e-9 * lam.iter().fold(0.0f64, |a, b| a.max(b.abs())).max(f64::MIN_POSITIVE);
    if lam[0] < -tol {
        return Err(c.err("hand_load.inertia", written(), format!("is not positive semi-definite (principal moments {:.6e}, {:.6e}, {:.6e} kg m^2)", lam[0], lam[1], lam[2])));
    }
    if lam[0] + lam[1] < lam[2] - tol {
        return Err(c.err("hand_load.inertia", written(), format!("principal moments {:.6e}, {:.6e}, {:.6e} kg m^2 violate the triangle inequality of a physical body (the largest exceeds the sum of the other two)", lam[0], lam[1], lam[2])));
    }
    Ok(Inertia::from_com(m, com, i_com))
}

/// The model with the scene's `hand_load` merged into the body that carries the hand link
/// (unchanged, bit for bit, without one).
pub(super) fn with_hand_load(c: &Ctx, spec: Option<&HandLoadSpec>, hand: &PointSpec, mut model: Model) -> Result<Model, SceneError> {
    let Some(load) = spec else { return Ok(model) };
    let i_link = load_inertia(c, load, hand)?;
    let link = hand_link(c, &model, hand)?;
    let field = if hand.link.is_some() { "hand.link" } else { "hand.joint" };
    let Some(frame) = model.frame(&link).cloned() else {
        return Err(c.err(field, &link, "no such link in the URDF: the hand load has no link to sit on"));
    };
    let Some(b) = frame.body else {
        return Err(c.err("hand_load", format!("on link `{link}`"), "the hand's link is fixed to the base: a load there never moves, so it changes nothing; drop `hand_load` or move `hand`"));
    };
    model.bodies[b].inertia = model.bodies[b].inertia.add(&i_link.to_parent(&frame.x_body_frame));
    Ok(model)
}
