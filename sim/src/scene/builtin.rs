//! The scenes built into the binary, by name: the paper's scene, the paper's arm over a real
//! table (`paper-unilateral`, issue 11: the table only pushes), and the real-arm scenes of
//! `sim/scenes/arms/` (issue 10, item 5), each with the URDF it names. They are embedded
//! (`include_str!`), so a `sim` installed with `cargo install` runs them by name (`sim ur5e-like`)
//! without the repository; `sim export-scene NAME` writes one out to edit.
//!
//! The paper's entry is the text of [`super::PAPER_SCENE_JSON`] and [`super::PAPER_URDF`], and
//! [`Builtin::load`] of it is [`Scene::paper`] (same source name), so that its recordings stay
//! byte-identical whichever way it is started.
//!
//! Where each arm's numbers come from: `sim/scenes/arms/SOURCES.md` and the comments in each
//! URDF (UR's published DH parameters and masses; Franka's FCI kinematics and Gaz et al., IEEE
//! RA-L 4(4), 2019; TheRobotStudio's SO-100 URDF and the Feetech STS3215 datasheet).

use crate::dynamics::Model;
use crate::error::SceneError;

use super::{Scene, PAPER_SCENE_JSON, PAPER_URDF};

/// One built-in scene: its name (the scene's own `name`), its JSON and the files it names.
#[derive(Clone, Copy, Debug)]
pub struct Builtin {
    /// The name `sim NAME` and `sim run NAME` accept (= the scene's `name`).
    pub name: &'static str,
    /// The scene file's name, as `sim export-scene` writes it.
    pub file: &'static str,
    /// The scene JSON.
    pub json: &'static str,
    /// The files the scene names (its URDF): (file name, text).
    pub files: &'static [(&'static str, &'static str)],
}

/// Every built-in scene, the paper's first.
pub const BUILTINS: &[Builtin] = &[
    Builtin { name: "paper", file: "paper.json", json: PAPER_SCENE_JSON, files: &[("paper_arm.urdf", PAPER_URDF)] },
    Builtin {
        name: "paper-unilateral",
        file: "paper_unilateral.json",
        json: include_str!("../../scenes/paper_unilateral.json"),
        files: &[("paper_arm.urdf", PAPER_URDF)],
    },
    Builtin {
        name: "ur5e-like",
        file: "ur5e_like.json",
        json: include_str!("../../scenes/arms/ur5e_like.json"),
        files: &[("ur5e_like.urdf", include_str!("../../scenes/arms/ur5e_like.urdf"))],
    },
    Builtin {
        name: "panda-like",
        file: "panda_like.json",
        json: include_str!("../../scenes/arms/panda_like.json"),
        files: &[("panda_like.urdf", include_str!("../../scenes/arms/panda_like.urdf"))],
    },
    Builtin {
        name: "hobby-arm",
        file: "hobby_arm.json",
        json: include_str!("../../scenes/arms/hobby_arm.json"),
        files: &[("hobby_arm.urdf", include_str!("../../scenes/arms/hobby_arm.urdf"))],
    },
];

/// The built-in scene called `name`.
pub fn find(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}

/// The names of the built-in scenes, in order.
pub fn names() -> Vec<&'static str> {
    BUILTINS.iter().map(|b| b.name).collect()
}

/// What `sim list` shows of a built-in scene: read from its JSON and URDF without validating
/// the whole scene (a listing never fails on a scene this build cannot run; [`Builtin::load`]
/// says why).
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    pub name: String,
    pub description: String,
    /// Degrees of freedom of its URDF.
    pub dof: usize,
    /// The robot's name in its URDF.
    pub robot: String,
    /// Its runs, in order.
    pub runs: Vec<String>,
    /// The URDF file it names.
    pub urdf: String,
}

impl Builtin {
    /// Where a scene loaded from here says it came from.
    pub fn source(&self) -> String {
        if self.name == "paper" {
            "built-in paper scene".to_string()
        } else {
            format!("built-in scene `{}`", self.name)
        }
    }

    /// The text of the file `name` this scene names.
    pub fn file_text(&self, name: &str) -> Result<&'static str, String> {
        self.files
            .iter()
            .find(|(f, _)| *f == name)
            .map(|(_, t)| *t)
            .ok_or_else(|| format!("the built-in scene `{}` has no file `{name}`", self.name))
    }

    /// The validated scene (for the paper: exactly [`Scene::paper`]).
    pub fn load(&self) -> Result<Scene, SceneError> {
        if self.name == "paper" {
            return Scene::paper();
        }
        Scene::from_json(self.json, &self.source(), |name| self.file_text(name).map(str::to_string))
    }

    /// Name, description, DoF, robot and runs, read from the JSON and the URDF.
    pub fn summary(&self) -> Result<Summary, SceneError> {
        let source = self.source();
        let doc: serde_json::Value =
            serde_json::from_str(self.json).map_err(|e| SceneError::new(&source, "(document)", "", e.to_string()))?;
        let text = |key: &str| doc.get(key).and_then(|v| v.as_str()).unwrap_or_default().to_string();
        let urdf = text("urdf");
        let xml = self.file_text(&urdf).map_err(|why| SceneError::new(&source, "urdf", &urdf, why))?;
        let model = Model::from_urdf(xml, &urdf, nalgebra::Vector3::zeros()).map_err(|e| SceneError::new(&source, "urdf", &urdf, e.to_string()))?;
        let runs = doc
            .get("runs")
            .and_then(|r| r.as_array())
            .map(|rs| rs.iter().filter_map(|r| r.get("name").and_then(|n| n.as_str()).map(str::to_string)).collect())
            .unwrap_or_default();
        Ok(Summary { name: text("name"), description: text("description"), dof: model.nv, robot: model.name.clone(), runs, urdf })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_is_named_as_its_scene_and_lists_its_urdf_and_runs() {
        for b in BUILTINS {
            let s = b.summary().unwrap_or_else(|e| panic!("{}: {e}", b.name));
            assert_eq!(s.name, b.name, "the built-in name is the scene's own `name`");
            assert!(!s.description.is_empty() && !s.runs.is_empty(), "{}", b.name);
            assert!(b.file_text(&s.urdf).is_ok(), "{}: its URDF is embedded", b.name);
        }
        let dof: Vec<usize> = BUILTINS.iter().map(|b| b.summary().unwrap().dof).collect();
        assert_eq!(dof, [10, 10, 6, 7, 6]);
        assert_eq!(find("paper-unilateral").unwrap().summary().unwrap().runs, ["two-elbow-unilateral", "one-elbow-unilateral", "whole-table"]);
        assert_eq!(find("panda-like").unwrap().summary().unwrap().runs, ["with-elbow", "free"]);
        assert!(find("no-such-arm").is_none());
    }

    #[test]
    fn the_builtin_paper_is_the_paper_scene() {
        let a = find("paper").unwrap().load().unwrap();
        let b = Scene::paper().unwrap();
        assert_eq!((a.spec(), a.source(), a.urdf_xml()), (b.spec(), b.source(), b.urdf_xml()));
    }
}
