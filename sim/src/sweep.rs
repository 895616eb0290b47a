//! Sweeps: a grid of scene variations (`sim sweep`). A sweep file ([`SweepSpec`], unknown keys
//! rejected) names a base scene and axes; each axis replaces one node of the scene JSON (a dot
//! path such as `controller.kp` or `contacts.0.plane.offset`) by each of its values. The grid is
//! the Cartesian product of the axes in order, the last axis varying fastest; grid point `k` is
//! the variant `<sweep>-<k>` (zero-padded), so file names do not depend on how the grid is
//! split. [`Shard`] `i/n` takes the grid points with `k % n == i`.
//!
//! Everything here is pure (parsing, grid expansion, sharding, replacements, validation into
//! [`Scene`]s); running and printing live in the binary (`sweep_cmd.rs`).

use std::path::{Path, PathBuf};

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::error::SceneError;
use crate::limits::{read_text, MAX_INPUT_BYTES};
use crate::scene::schema_key::{SkipSchemaKey, SCHEMA_KEY};
use crate::scene::{Scene, SceneSpec, PAPER_SCENE_JSON, PAPER_URDF};

/// A sweep file: a base scene and the axes of a grid of its variations (README, "Sweeps").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SweepSpec {
    /// Short name: variants are `<name>-<k>`, files `<name>-<k>-<run>.mcap`.
    pub name: String,
    /// What the sweep is for (default: empty).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub description: String,
    /// Scene file, relative to the sweep file (default: the built-in paper scene).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scene: Option<String>,
    /// The runs of the scene to run for every variant (default: all).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub runs: Option<Vec<String>>,
    /// Simulated time of every run, s (default: the scene's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duration: Option<f64>,
    /// The axes of the grid, slowest first (default: none, the scene as is).
    #[serde(default)]
    pub axes: Vec<AxisSpec>,
}

/// One axis: a dot path into the scene JSON and the values that replace that node.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AxisSpec {
    /// A dot path into the scene JSON: object keys and array indices (`contacts.0.plane.offset`).
    pub field: String,
    /// The values that replace that node, one grid coordinate each (numbers, arrays, objects).
    pub values: Vec<Value>,
}

/// One shard of a grid: the points `k` with `k % count == index`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// The whole grid.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    pub fn contains(&self, k: usize) -> bool {
        k % self.count == self.index
    }

    /// The grid indices of this shard, ascending.
    pub fn indices(&self, grid_size: usize) -> Vec<usize> {
        (self.index..grid_size).step_by(self.count).collect()
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl std::str::FromStr for Shard {
    type Err = String;
    /// `i/n` with `0 <= i < n` (0-based, like `SLURM_ARRAY_TASK_ID` from 0 and
    /// `JOB_COMPLETION_INDEX`).
    fn from_str(s: &str) -> Result<Shard, String> {
        let bad = |why: &str| format!("shard `{s}`: {why}");
        let (i, n) = s.split_once('/').ok_or_else(|| bad("expected INDEX/COUNT, e.g. 0/4"))?;
        let index: usize = i.trim().parse().map_err(|_| bad("the index must be a whole number >= 0"))?;
        let count: usize = n.trim().parse().map_err(|_| bad("the count must be a whole number >= 1"))?;
        if count == 0 {
            return Err(bad("the count must be >= 1"));
        }
        if index >= count {
            return Err(bad(&format!("the index is 0-based and must be below the count (0/{count} … {}/{count})", count - 1)));
        }
        Ok(Shard { index, count })
    }
}

/// Number of grid points: the product of the axes' lengths (1 without axes).
pub fn grid_size(lens: &[usize]) -> Option<usize> {
    lens.iter().try_fold(1usize, |acc, &n| acc.checked_mul(n))
}

/// The value index on each axis of grid point `k` (mixed radix, last axis fastest).
pub fn grid_point(lens: &[usize], mut k: usize) -> Vec<usize> {
    let mut out = vec![0; lens.len()];
    for (a, &n) in lens.iter().enumerate().rev() {
        out[a] = k % n;
        k /= n;
    }
    out
}

/// Replace the node at the dot path `path` of `doc` by `value`. Object keys are names; inside
/// arrays a segment is an index that must exist. A missing object key is created (objects on
/// the way too); whether the scene knows it is for the scene's own validation to say. (Written
/// out rather than with serde_json's JSON pointers, which `analyze summary --param` uses to
/// read: `pointer_mut` cannot create a node, and an axis may set what the base scene leaves to
/// its default, e.g. `integrator.h_max` or `dynamics.stabilization`.)
pub fn set_path(doc: &mut Value, path: &str, value: Value) -> Result<(), String> {
    let segs: Vec<&str> = path.split('.').collect();
    if segs.iter().any(|s| s.is_empty()) {
        return Err("a field is a dot path of keys and array indices, e.g. `contacts.0.plane.offset`".into());
    }
    let mut node = doc;
    for (d, seg) in segs.iter().enumerate() {
        let here = segs[..d].join(".");
        let last = d + 1 == segs.len();
        node = match node {
            Value::Object(m) => {
                if last {
                    m.insert(seg.to_string(), value);
                    return Ok(());
                }
                m.entry(seg.to_string()).or_insert_with(|| Value::Object(Default::default()))
            }
            Value::Array(a) => {
                let len = a.len();
                let i: usize = seg.parse().map_err(|_| {
                    format!("`{}` is an array: `{seg}` must be an index (0 … {})", here, len.saturating_sub(1))
                })?;
                let slot = a.get_mut(i).ok_or_else(|| format!("`{here}` has {len} entries: index {i} is out of range"))?;
                if last {
                    *slot = value;
                    return Ok(());
                }
                slot
            }
            other => {
                let kind = match other {
                    Value::Null => "null",
                    Value::Bool(_) => "a boolean",
                    Value::Number(_) => "a number",
                    Value::String(_) => "a string",
                    _ => unreachable!(),
                };
                return Err(format!("`{here}` is {kind}, not an object or array: `{seg}` cannot be inside it"));
            }
        };
    }
    unreachable!("the loop returns at the last segment")
}

/// Why a replacement does not make a well-formed scene JSON ([`check_replacement`]).
#[derive(Clone, Debug, PartialEq)]
pub enum BadReplacement {
    /// The dot path itself: not in the scene, or not a place a value can go.
    Field(String),
    /// The value, at that path.
    Value(String),
}

/// Whether replacing the node at `field` of the scene JSON `base` by `value` gives a
/// well-formed scene (the keys and types; the numbers are the scene validation's to check).
/// The one check of a sweep's axes and a study's variables.
pub fn check_replacement(base: &Value, field: &str, value: &Value) -> Result<(), BadReplacement> {
    let mut doc = base.clone();
    set_path(&mut doc, field, value.clone()).map_err(BadReplacement::Field)?;
    if let Err(e) = serde_path_to_error::deserialize::<_, SceneSpec>(doc) {
        let at = e.path().to_string().replace('[', ".").replace(']', "");
        let why = e.inner().to_string();
        return Err(if at == field && why.starts_with("unknown field") {
            BadReplacement::Field(format!("no such field in the scene: {why}"))
        } else {
            BadReplacement::Value(format!("not valid at `{at}` of the scene: {why}"))
        });
    }
    Ok(())
}

/// Compact text of a JSON value (for tables and messages).
pub fn compact(v: &Value) -> String {
    serde_json::to_string(v).unwrap_or_default()
}

/// Errors of a sweep: bad input that names the file, the field and the value.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    #[error(transparent)]
    Input(#[from] SceneError),
    /// A variant whose scene does not validate.
    #[error("variant {variant} of sweep {file} ({replacements}): {source}")]
    Variant { file: String, variant: String, replacements: String, source: Box<SceneError> },
}

pub(crate) fn valid_name(s: &str) -> bool {
    !s.is_empty() && s.chars().all(|ch| ch.is_ascii_alphanumeric() || "-_.".contains(ch))
}

/// A grid point with its replacements.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Variant {
    /// Index in the full grid.
    pub index: usize,
    /// `<sweep>-<k>`: the scene name of the variant.
    pub name: String,
    /// `(field, value)` per axis, in axis order.
    pub replacements: Vec<(String, Value)>,
}

impl Variant {
    pub fn describe(&self) -> String {
        if self.replacements.is_empty() {
            return "the scene as is".into();
        }
        self.replacements.iter().map(|(f, v)| format!("{f} = {}", compact(v))).collect::<Vec<_>>().join(", ")
    }
}

/// How the base scene's URDF is found.
#[derive(Clone, Debug)]
enum UrdfSource {
    BuiltIn,
    Dir(PathBuf),
}

/// A parsed and checked sweep, ready to expand.
#[derive(Clone, Debug)]
pub struct Sweep {
    pub spec: SweepSpec,
    /// The sweep file (or a label).
    pub file: String,
    /// The base scene, as given (a path or "built-in paper scene").
    pub scene_source: String,
    /// The base scene JSON, with the duration override applied.
    pub base: Value,
    /// The runs to run for every variant.
    pub runs: Vec<String>,
    /// Length of each axis.
    pub lens: Vec<usize>,
    pub grid_size: usize,
    urdf: UrdfSource,
}

impl Sweep {
    /// Read a sweep file; its `scene` is relative to the file's directory.
    pub fn load(path: &Path) -> Result<Sweep, SweepError> {
        let file = path.display().to_string();
        let text = read_text(path, MAX_INPUT_BYTES).map_err(|e| SceneError::new(&file, "(file)", "", e.to_string()))?;
        let spec: SweepSpec = parse_spec(&text, &file)?;
        Self::from_spec_at(spec, path)
    }

    /// A sweep from its parsed `spec`, read from `path` (its `scene` is relative to the file's
    /// directory): the study (`crate::study`) loads its base scene through this.
    pub fn from_spec_at(spec: SweepSpec, path: &Path) -> Result<Sweep, SweepError> {
        let file = path.display().to_string();
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let (scene_source, scene_text, urdf) = match &spec.scene {
            None => ("built-in paper scene".to_string(), PAPER_SCENE_JSON.to_string(), UrdfSource::BuiltIn),
            Some(s) => {
                let p = dir.join(s);
                let t = read_text(&p, MAX_INPUT_BYTES)
                    .map_err(|e| SceneError::new(&file, "scene", s, format!("cannot read {}: {e}", p.display())))?;
                (p.display().to_string(), t, UrdfSource::Dir(p.parent().map(Path::to_path_buf).unwrap_or_default()))
            }
        };
        Self::build(spec, &file, scene_source, &scene_text, urdf)
    }

    /// A sweep of the built-in paper scene from sweep JSON text (`scene` must be absent).
    pub fn from_json_paper(text: &str, file: &str) -> Result<Sweep, SweepError> {
        let spec: SweepSpec = parse_spec(text, file)?;
        if let Some(s) = &spec.scene {
            return Err(SceneError::new(file, "scene", s, "not available here (only the built-in paper scene)").into());
        }
        Self::build(spec, file, "built-in paper scene".into(), PAPER_SCENE_JSON, UrdfSource::BuiltIn)
    }

    fn build(spec: SweepSpec, file: &str, scene_source: String, scene_text: &str, urdf: UrdfSource) -> Result<Sweep, SweepError> {
        let err = |field: &str, value: &dyn std::fmt::Display, why: String| SceneError::new(file, field, value, why);
        if !valid_name(&spec.name) {
            return Err(err("name", &format!("{:?}", spec.name), "must be non-empty and use only letters, digits, '-', '_' and '.' (it names output files)".into()).into());
        }
        let mut base: Value = serde_json::from_str(scene_text)
            .map_err(|e| err("scene", &scene_source, format!("not valid JSON: {e}")))?;
        let base_spec = SceneSpec::deserialize(SkipSchemaKey(base.clone()))
            .map_err(|e| err("scene", &scene_source, format!("not a valid scene: {e} (run `sim check` on it)")))?;
        // the base scene's "$schema" (a string: just read) is for editors, not for the variants
        if let Value::Object(m) = &mut base {
            m.remove(SCHEMA_KEY);
        }
        if let Some(d) = spec.duration {
            if !(d > 0.0 && d.is_finite()) {
                return Err(err("duration", &d, "must be a positive number of seconds".into()).into());
            }
            set_path(&mut base, "duration", Value::from(d)).expect("a scene is a JSON object");
        }
        let scene_runs: Vec<String> = base_spec.runs.iter().map(|r| r.name.clone()).collect();
        let runs = match &spec.runs {
            None => scene_runs.clone(),
            Some(list) => {
                if list.is_empty() {
                    return Err(err("runs", &"[]", "needs at least one run (or leave it out for all)".into()).into());
                }
                for (i, r) in list.iter().enumerate() {
                    if !scene_runs.contains(r) {
                        return Err(err(&format!("runs[{i}]"), r, format!("no run of that name in the scene (runs: {})", scene_runs.join(", "))).into());
                    }
                    if list[..i].contains(r) {
                        return Err(err(&format!("runs[{i}]"), r, "is listed twice".into()).into());
                    }
                }
                list.clone()
            }
        };
        let mut lens = Vec::with_capacity(spec.axes.len());
        for (a, axis) in spec.axes.iter().enumerate() {
            let f = format!("axes[{a}].field");
            if axis.field == "name" {
                return Err(err(&f, &axis.field, "the sweep names its variants `<sweep>-<k>`; it cannot be an axis".into()).into());
            }
            if let Some(b) = spec.axes[..a].iter().position(|x| x.field == axis.field) {
                return Err(err(&f, &axis.field, format!("is also axis {b}")).into());
            }
            if axis.values.is_empty() {
                return Err(err(&format!("axes[{a}].values"), &"[]", "needs at least one value".into()).into());
            }
            // every value of the axis must make a well-formed scene JSON, checked here (before
            // anything runs); the numbers are validated per variant
            for (j, v) in axis.values.iter().enumerate() {
                check_replacement(&base, &axis.field, v).map_err(|bad| match bad {
                    BadReplacement::Field(why) => err(&f, &axis.field, why),
                    BadReplacement::Value(why) => err(&format!("axes[{a}].values[{j}]"), &compact(v), why),
                })?;
            }
            lens.push(axis.values.len());
        }
        let grid_size = grid_size(&lens).ok_or_else(|| err("axes", &format!("{lens:?}"), "the grid is too large".into()))?;
        Ok(Sweep { spec, file: file.to_string(), scene_source, base, runs, lens, grid_size, urdf })
    }

    /// Digits of the variant index in names (at least 3).
    pub fn index_width(&self) -> usize {
        (self.grid_size.saturating_sub(1)).to_string().len().max(3)
    }

    /// Grid point `k` (`k < grid_size`).
    pub fn variant(&self, k: usize) -> Variant {
        assert!(k < self.grid_size, "grid point {k} of {}", self.grid_size);
        let at = grid_point(&self.lens, k);
        Variant {
            index: k,
            name: format!("{}-{:0w$}", self.spec.name, k, w = self.index_width()),
            replacements: self.spec.axes.iter().zip(&at).map(|(a, &j)| (a.field.clone(), a.values[j].clone())).collect(),
        }
    }

    /// The variants of `shard`, in grid order.
    pub fn variants(&self, shard: Shard) -> Vec<Variant> {
        shard.indices(self.grid_size).into_iter().map(|k| self.variant(k)).collect()
    }

    /// The scene JSON of a variant: the base with its replacements and its name.
    pub fn variant_json(&self, v: &Variant) -> Value {
        let mut doc = self.base.clone();
        for (f, val) in &v.replacements {
            set_path(&mut doc, f, val.clone()).expect("paths checked when the sweep was read");
        }
        set_path(&mut doc, "name", Value::from(v.name.clone())).expect("a scene is a JSON object");
        doc
    }

    /// Validate a variant into a runnable scene; the error names the variant and its values.
    pub fn scene(&self, v: &Variant) -> Result<Scene, SweepError> {
        let text = serde_json::to_string(&self.variant_json(v)).expect("JSON values serialise");
        let source = format!("{} (sweep variant {})", self.scene_source, v.name);
        let read_urdf = |name: &str| self.read_urdf(name);
        // the scene's directory: robot.package_paths are relative to it
        let dir = match &self.urdf {
            UrdfSource::Dir(dir) => Some(dir.as_path()),
            UrdfSource::BuiltIn => None,
        };
        let scene = Scene::from_json_in(&text, &source, dir, read_urdf).map_err(|source| SweepError::Variant {
            file: self.file.clone(),
            variant: v.name.clone(),
            replacements: v.describe(),
            source: Box::new(source),
        })?;
        for r in &self.runs {
            if scene.run(r).is_none() {
                return Err(SweepError::Variant {
                    file: self.file.clone(),
                    variant: v.name.clone(),
                    replacements: v.describe(),
                    source: Box::new(SceneError::new(&source, "runs", r, "the variant has no run of that name")),
                });
            }
        }
        Ok(scene)
    }

    /// The text of the base scene's URDF file `name` (as the scene names it).
    pub fn read_urdf(&self, name: &str) -> Result<String, String> {
        match &self.urdf {
            UrdfSource::BuiltIn if name == "paper_arm.urdf" => Ok(PAPER_URDF.to_string()),
            UrdfSource::BuiltIn => Err(format!("the built-in scene has no file `{name}`")),
            UrdfSource::Dir(dir) => crate::scene::read_urdf_file(dir, name),
        }
    }

    /// The recording file name of `run` of variant `v` (what `sim run` would write).
    pub fn file_name(v: &Variant, run: &str) -> String {
        format!("{}-{run}.mcap", v.name)
    }
}

pub(crate) fn parse_spec<T: serde::de::DeserializeOwned>(text: &str, file: &str) -> Result<T, SceneError> {
    let de = &mut serde_json::Deserializer::from_str(text);
    // a top-level "$schema" (for editors) is dropped
    serde_path_to_error::deserialize(SkipSchemaKey(de)).map_err(|e| {
        let path = e.path().to_string();
        SceneError::new(file, if path == "." { "(document)".into() } else { path }, "", e.inner().to_string())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn paper_sweep(axes: Value) -> Result<Sweep, SweepError> {
        let text = json!({"name": "t", "duration": 0.5, "axes": axes}).to_string();
        Sweep::from_json_paper(&text, "t.json")
    }

    #[test]
    fn grid_is_the_product_with_the_last_axis_fastest() {
        let lens = [3, 2, 2];
        assert_eq!(grid_size(&lens), Some(12));
        assert_eq!(grid_size(&[]), Some(1));
        assert_eq!(grid_size(&[usize::MAX, 2]), None);
        let pts: Vec<_> = (0..12).map(|k| grid_point(&lens, k)).collect();
        assert_eq!(pts[0], [0, 0, 0]);
        assert_eq!(pts[1], [0, 0, 1]);
        assert_eq!(pts[2], [0, 1, 0]);
        assert_eq!(pts[4], [1, 0, 0]);
        assert_eq!(pts[11], [2, 1, 1]);
        let mut sorted = pts.clone();
        sorted.dedup();
        assert_eq!(sorted.len(), 12);
    }

    #[test]
    fn shards_partition_the_grid() {
        for total in [0, 1, 5, 12, 17] {
            for n in 1..=7 {
                let mut seen = vec![0; total];
                for i in 0..n {
                    let sh = Shard { index: i, count: n };
                    for k in sh.indices(total) {
                        assert!(sh.contains(k));
                        seen[k] += 1;
                    }
                }
                assert!(seen.iter().all(|&c| c == 1), "{total} points, {n} shards: {seen:?}");
            }
        }
    }

    #[test]
    fn shard_parsing() {
        assert_eq!("2/3".parse::<Shard>(), Ok(Shard { index: 2, count: 3 }));
        assert_eq!("0/1".parse::<Shard>(), Ok(Shard::ALL));
        for bad in ["3/3", "1/0", "-1/3", "a/3", "3", "1/x", ""] {
            let e = bad.parse::<Shard>().unwrap_err();
            assert!(e.contains(&format!("`{bad}`")), "{e}");
        }
        assert!("3/3".parse::<Shard>().unwrap_err().contains("below the count"));
    }

    #[test]
    fn set_path_replaces_nodes() {
        let mut d = json!({"a": {"b": [1, {"c": 2}]}, "x": 1});
        set_path(&mut d, "a.b.1.c", json!(5)).unwrap();
        set_path(&mut d, "a.b.0", json!([1, 2])).unwrap();
        set_path(&mut d, "a.new", json!("s")).unwrap();
        assert_eq!(d, json!({"a": {"b": [[1, 2], {"c": 5}], "new": "s"}, "x": 1}));
        assert!(set_path(&mut d, "a.b.2", json!(0)).unwrap_err().contains("out of range"));
        assert!(set_path(&mut d, "a.b.q", json!(0)).unwrap_err().contains("must be an index"));
        assert!(set_path(&mut d, "x.y", json!(0)).unwrap_err().contains("`x` is a number"));
        assert!(set_path(&mut d, "a..b", json!(0)).is_err());
    }

    #[test]
    fn variants_are_named_by_grid_index_and_carry_their_values() {
        let s = paper_sweep(json!([
            {"field": "controller.kp", "values": [250, 500, 1000]},
            {"field": "contacts.0.plane.offset", "values": [0.0]},
            {"field": "integrator", "values": [{"method": "rk4", "step": 1e-3}, {"method": "dopri45", "rtol": 1e-6, "atol": 1e-8}]}
        ]))
        .unwrap();
        assert_eq!(s.grid_size, 6);
        assert_eq!(s.runs, ["two-elbow", "one-elbow", "no-elbow"]);
        let v = s.variant(3);
        assert_eq!(v.name, "t-003");
        assert_eq!(v.replacements[0], ("controller.kp".to_string(), json!(500)));
        assert_eq!(v.replacements[2].1["method"], "dopri45");
        let doc = s.variant_json(&v);
        assert_eq!(doc["name"], "t-003");
        assert_eq!(doc["duration"], 0.5);
        assert_eq!(doc["controller"]["kp"], 500);
        let scene = s.scene(&v).unwrap();
        assert_eq!(scene.spec.name, "t-003");
        assert_eq!(scene.gains.kp[0], 500.0);
        assert_eq!(scene.duration, 0.5);
        assert_eq!(s.variants("1/2".parse().unwrap()).iter().map(|v| v.index).collect::<Vec<_>>(), [1, 3, 5]);
    }

    #[test]
    fn bad_input_names_the_field_and_value() {
        let e = paper_sweep(json!([{"field": "controller.kpp", "values": [1]}])).unwrap_err().to_string();
        assert!(e.contains("axes[0].field") && e.contains("controller.kpp") && e.contains("unknown field"), "{e}");
        let e = paper_sweep(json!([{"field": "contacts.9.plane.offset", "values": [1]}])).unwrap_err().to_string();
        assert!(e.contains("axes[0].field") && e.contains("out of range"), "{e}");
        let e = paper_sweep(json!([{"field": "duration.x", "values": [1]}])).unwrap_err().to_string();
        assert!(e.contains("`duration` is a number"), "{e}");
        let e = paper_sweep(json!([{"field": "controller.kp", "values": [1, "high"]}])).unwrap_err().to_string();
        assert!(e.contains("axes[0].values[1]") && e.contains("\"high\""), "{e}");
        let e = paper_sweep(json!([{"field": "controller.kp", "values": []}])).unwrap_err().to_string();
        assert!(e.contains("axes[0].values"), "{e}");
        let e = Sweep::from_json_paper(r#"{"name": "t", "axes": [], "extra": 1}"#, "t.json").unwrap_err().to_string();
        assert!(e.contains("t.json") && e.contains("unknown field `extra`"), "{e}");
        let e = Sweep::from_json_paper(r#"{"name": "t", "runs": ["two-elbow", "three-elbow"]}"#, "t.json").unwrap_err().to_string();
        assert!(e.contains("runs[1]") && e.contains("three-elbow"), "{e}");
        let e = Sweep::from_json_paper(r#"{"name": "a b"}"#, "t.json").unwrap_err().to_string();
        assert!(e.contains("field `name`"), "{e}");
        // a value that parses but does not validate: the error names the variant and its values
        let s = paper_sweep(json!([{"field": "controller.kp", "values": [500, -1]}])).unwrap();
        s.scene(&s.variant(0)).unwrap();
        let e = s.scene(&s.variant(1)).unwrap_err().to_string();
        assert!(e.contains("t-001") && e.contains("controller.kp = -1") && e.contains("must be >= 0"), "{e}");
        // a step budget of 0 (it used to panic in every adaptive integrator when run)
        let s = paper_sweep(json!([{"field": "integrator.max_steps", "values": [100000, 0]}])).unwrap();
        s.scene(&s.variant(0)).unwrap();
        let e = s.scene(&s.variant(1)).unwrap_err().to_string();
        assert!(e.contains("t-001") && e.contains("integrator.max_steps` = 0") && e.contains("must be >= 1"), "{e}");
    }

    #[test]
    fn no_axes_is_one_variant() {
        let s = paper_sweep(json!([])).unwrap();
        assert_eq!(s.grid_size, 1);
        assert_eq!(s.variant(0).name, "t-000");
        assert!(s.variant(0).replacements.is_empty());
    }
}
