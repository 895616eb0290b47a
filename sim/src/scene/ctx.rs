//! The validation context of a scene: errors that name the file, the field and the value, and
//! the checks of numbers, per-joint values, vectors, points and joints that `build` and the
//! target's validation share.

use nalgebra::Vector3;

use super::spec::{PerJoint, PointSpec};
use crate::dynamics::kinematics::{body_point, BodyPoint};
use crate::dynamics::Model;
use crate::error::SceneError;

pub(super) struct Ctx<'a> {
    pub(super) file: &'a str,
}

impl Ctx<'_> {
    pub(super) fn err(&self, field: impl Into<String>, value: impl std::fmt::Display, why: impl Into<String>) -> SceneError {
        SceneError::new(self.file, field, value, why)
    }

    pub(super) fn number(&self, field: &str, x: f64, ok: impl Fn(f64) -> bool, why: &str) -> Result<f64, SceneError> {
        if !x.is_finite() {
            return Err(self.err(field, x, "must be a finite number"));
        }
        if !ok(x) {
            return Err(self.err(field, x, why));
        }
        Ok(x)
    }

    pub(super) fn per_joint(
        &self,
        field: &str,
        p: &PerJoint,
        nv: usize,
        ok: impl Fn(f64) -> bool,
        why: &str,
    ) -> Result<Vec<f64>, SceneError> {
        let v = match p {
            PerJoint::All(x) => vec![*x; nv],
            PerJoint::Each(v) if v.len() == nv => v.clone(),
            PerJoint::Each(v) => {
                return Err(self.err(field, format!("an array of {}", v.len()), format!("needs one value per joint ({nv})")))
            }
        };
        for (j, &x) in v.iter().enumerate() {
            let f = if matches!(p, PerJoint::All(_)) { field.to_string() } else { format!("{field}[{j}]") };
            self.number(&f, x, &ok, why)?;
        }
        Ok(v)
    }

    pub(super) fn vec3(&self, field: &str, v: [f64; 3]) -> Result<Vector3<f64>, SceneError> {
        for (k, x) in v.iter().enumerate() {
            self.number(&format!("{field}[{k}]"), *x, |_| true, "")?;
        }
        Ok(Vector3::from(v))
    }

    pub(super) fn point(&self, field: &str, model: &Model, p: &PointSpec) -> Result<BodyPoint, SceneError> {
        let offset = self.vec3(&format!("{field}.offset"), p.offset)?;
        let link = match (&p.joint, &p.link) {
            (Some(j), None) => match model.urdf_joints.iter().find(|u| &u.name == j) {
                Some(u) => u.child_link.clone(),
                None => return Err(self.err(format!("{field}.joint"), j, format!("no such joint in the URDF (joints: {})", names(model.urdf_joints.iter().map(|u| &u.name))))),
            },
            (None, Some(l)) => l.clone(),
            _ => return Err(self.err(field, "", "give exactly one of `joint` (its origin) or `link`")),
        };
        body_point(model, &link, offset).ok_or_else(|| {
            self.err(format!("{field}.link"), &link, format!("no such link in the URDF (links: {})", names(model.frames.iter().map(|f| &f.name))))
        })
    }

    pub(super) fn dof(&self, field: &str, model: &Model, joint: &str) -> Result<usize, SceneError> {
        model.dof_of_joint(joint).ok_or_else(|| {
            self.err(field, joint, format!("no movable joint of that name (movable joints: {})", model.joint_names().join(", ")))
        })
    }
}

pub(super) fn names<'a>(it: impl Iterator<Item = &'a String>) -> String {
    it.map(String::as_str).collect::<Vec<_>>().join(", ")
}

pub(super) fn positive(x: f64) -> bool {
    x > 0.0
}
pub(super) fn non_negative(x: f64) -> bool {
    x >= 0.0
}
/// `lo <= x <= hi` (a physical range, e.g. [`super::spec::motor_bounds`]).
pub(super) fn within(lo: f64, hi: f64) -> impl Fn(f64) -> bool {
    move |x| (lo..=hi).contains(&x)
}
