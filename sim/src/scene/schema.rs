//! The JSON Schema of the scene files and of the sweep files, generated from their serde types
//! ([`super::SceneSpec`], [`crate::sweep::SweepSpec`]) with `schemars`, so that an editor
//! completes keys, shows each key's description (unit, default) and marks a misspelt key.
//!
//! The schema follows JSON Schema draft 2020-12 (<https://json-schema.org/draft/2020-12>: Core,
//! and Validation for `type`, `enum`, `const`, `minItems`, `additionalProperties`, …): every
//! object the parser reads with `deny_unknown_fields` has `"additionalProperties": false`; the
//! types read by hand (a per-joint value, `initial.q`, the target) have their schema written
//! by hand below, next to each other, to accept what their `Deserialize` accepts. The top level
//! also allows `"$schema"` (a string), which the parser drops ([`super::schema_key`]).
//! Numbers are plain JSON numbers (schemars' `format: double` and the like are left out: no
//! editor or validator knows them).
//!
//! [`markdown`] renders a schema as the reference pages of the docs (one section per object,
//! a table of its keys). `sim schema` prints both; the committed copies
//! (`sim/scenes/{scene,sweep}.schema.json`, `docs/src/reference/{scene,sweep}-fields.md`) are
//! checked against them by the tests below (`ELBOW_BLESS=1` rewrites them).

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::fmt::Write as _;

use schemars::generate::SchemaSettings;
use schemars::{json_schema, JsonSchema, Schema, SchemaGenerator};
use serde_json::{json, Map, Value};

use super::schema_key::SCHEMA_KEY;
use super::spec::{InitialQ, KindedTarget, PaperTargetSpec, PerJoint, TargetSpec};
use super::SceneSpec;
use crate::sweep::SweepSpec;

/// The two file formats that have a schema.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    /// A scene file (`sim run`, `sim check`).
    Scene,
    /// A sweep file (`sim sweep`).
    Sweep,
    /// A study file (`sim optimize`).
    Study,
}

impl FileKind {
    /// Every kind, scene first.
    pub const ALL: [FileKind; 3] = [FileKind::Scene, FileKind::Sweep, FileKind::Study];

    /// `scene` or `sweep`.
    pub fn name(self) -> &'static str {
        match self {
            FileKind::Scene => "scene",
            FileKind::Sweep => "sweep",
            FileKind::Study => "study",
        }
    }

    /// The schema's file name: `scene.schema.json`, `sweep.schema.json` (the committed ones are
    /// in `sim/scenes/`; `sim export-scene` writes the scene's next to the scene).
    pub fn schema_file(self) -> &'static str {
        match self {
            FileKind::Scene => "scene.schema.json",
            FileKind::Sweep => "sweep.schema.json",
            FileKind::Study => "study.schema.json",
        }
    }

    /// The reference page's file name (in `docs/src/reference/`).
    pub fn fields_page(self) -> &'static str {
        match self {
            FileKind::Scene => "scene-fields.md",
            FileKind::Sweep => "sweep-fields.md",
            FileKind::Study => "study-fields.md",
        }
    }
}

/// The JSON Schema (draft 2020-12) of `kind`'s files, as a JSON value with its keys sorted.
pub fn schema(kind: FileKind) -> Value {
    let generator = SchemaSettings::draft2020_12().into_generator();
    let (root, title) = match kind {
        FileKind::Scene => (generator.into_root_schema_for::<SceneSpec>(), "elbow-sim scene"),
        FileKind::Sweep => (generator.into_root_schema_for::<SweepSpec>(), "elbow-sim sweep"),
        FileKind::Study => (generator.into_root_schema_for::<crate::study::StudySpec>(), "elbow-sim study"),
    };
    let mut v = root.to_value();
    let obj = v.as_object_mut().expect("a struct's schema is an object");
    obj.insert("title".into(), title.into());
    let props = obj.get_mut("properties").and_then(Value::as_object_mut).expect("a struct's schema has properties");
    props.insert(
        SCHEMA_KEY.into(),
        json!({
            "type": "string",
            "description": format!("The path (relative to this file) or URL of this JSON Schema, for editors, e.g. `{}`; sim ignores it.", kind.schema_file()),
        }),
    );
    tidy(&mut v);
    sorted(v)
}

/// [`schema`] as the text `sim schema` prints and the committed file holds: pretty JSON and a
/// final newline.
pub fn schema_text(kind: FileKind) -> String {
    serde_json::to_string_pretty(&schema(kind)).expect("a JSON value serialises") + "\n"
}

/// Drop the numeric `format`s (`double`, `uint64`, …: annotations no editor knows) and join
/// each description's lines within a paragraph (doc comments wrap at 100 columns).
fn tidy(v: &mut Value) {
    match v {
        Value::Object(m) => {
            if m.get("format").and_then(Value::as_str).is_some() && m.get("type").is_some_and(|t| t != "string") {
                m.remove("format");
            }
            if let Some(Value::String(d)) = m.get_mut("description") {
                *d = d.split("\n\n").map(|p| p.lines().map(str::trim).collect::<Vec<_>>().join(" ")).collect::<Vec<_>>().join("\n\n");
            }
            m.values_mut().for_each(tidy);
        }
        Value::Array(a) => a.iter_mut().for_each(tidy),
        _ => {}
    }
}

/// `v` with every object's keys in sorted order, whatever serde_json's map keeps.
fn sorted(v: Value) -> Value {
    match v {
        Value::Object(m) => {
            let b: BTreeMap<String, Value> = m.into_iter().map(|(k, x)| (k, sorted(x))).collect();
            Value::Object(b.into_iter().collect::<Map<_, _>>())
        }
        Value::Array(a) => Value::Array(a.into_iter().map(sorted).collect()),
        x => x,
    }
}

/// `text` (a scene or sweep file) with its top-level `"$schema"` set to `path`: the value of the
/// first `"$schema": "…"` replaced (the shipped files have it as their first key), or the key
/// added after the opening brace; the rest of the text is kept byte for byte.
pub fn with_schema_path(text: &str, path: &str) -> String {
    let key = format!("\"{SCHEMA_KEY}\"");
    if let Some(i) = text.find(&key) {
        let rest = &text[i + key.len()..];
        let open = rest.find('"').map(|j| i + key.len() + j);
        let close = open.and_then(|o| text[o + 1..].find('"').map(|j| o + 1 + j));
        if let (Some(o), Some(c)) = (open, close) {
            return format!("{}\"{path}\"{}", &text[..o], &text[c + 1..]);
        }
    }
    match text.find('{') {
        Some(b) => format!("{}{{\n  {key}: \"{path}\",{}", &text[..b], &text[b + 1..]),
        None => text.to_string(),
    }
}

// --- the schemas of the types read by hand (`spec.rs`), each accepting what its reader accepts

impl JsonSchema for PerJoint {
    fn schema_name() -> Cow<'static, str> {
        "PerJoint".into()
    }
    fn json_schema(_: &mut SchemaGenerator) -> Schema {
        // `PerJoint`'s Deserialize: any JSON number (integers too), or a sequence of numbers
        json_schema!({
            "description": "One number for every joint, or an array with one number per joint (dof order).",
            "anyOf": [
                {"type": "number"},
                {"type": "array", "items": {"type": "number"}}
            ]
        })
    }
}

impl JsonSchema for InitialQ {
    fn schema_name() -> Cow<'static, str> {
        "InitialQ".into()
    }
    fn json_schema(generator: &mut SchemaGenerator) -> Schema {
        // `InitialQ`'s Deserialize: a per-joint value, or exactly the string "from-target"
        let per_joint = generator.subschema_for::<PerJoint>();
        json_schema!({
            "description": "Joint angles, rad (per joint), or \"from-target\": the target's q_d(0).",
            "anyOf": [per_joint, {"type": "string", "const": "from-target"}]
        })
    }
}

impl JsonSchema for TargetSpec {
    fn schema_name() -> Cow<'static, str> {
        "TargetSpec".into()
    }
    fn json_schema(generator: &mut SchemaGenerator) -> Schema {
        // `TargetSpec`'s Deserialize: an object with `kind` is a tagged target, any other the
        // paper's (whose schema has no `kind`, so the two never both match)
        let (paper, kinded) = (generator.subschema_for::<PaperTargetSpec>(), generator.subschema_for::<KindedTarget>());
        json_schema!({
            "description": "The target: the paper's form (`circle` and `ik`, no `kind`), or a form tagged by `kind`.",
            "anyOf": [paper, kinded]
        })
    }
}

// --- the reference page

/// The schema of `kind`'s files as a Markdown reference page: the top-level object first, then each definition in the order the file meets it; per object a table of its keys
/// (type, required or default, description), per tagged union one table per tag value, per
/// enumeration its values.
pub fn markdown(kind: FileKind) -> String {
    let s = schema(kind);
    let defs = s.get("$defs").and_then(Value::as_object).cloned().unwrap_or_default();
    let mut out = String::new();
    let name = kind.name();
    let _ = writeln!(out, "# {} fields\n", capitalise(name));
    let _ = writeln!(
        out,
        "<!-- generated by `sim schema {name} -f markdown` from the code (sim/src/scene/schema.rs); do not edit: a test compares it, ELBOW_BLESS=1 rewrites it -->\n"
    );
    let _ = writeln!(
        out,
        "Every key of a {name} file, from its JSON Schema (draft 2020-12), which `sim schema {name}` prints and `sim/scenes/{}` holds. \
         Give a file `\"$schema\": \"<path to {}>\"` as its first key and an editor completes the keys, shows these descriptions and marks a misspelt key, as `sim` does. \
         Units are SI, angles in radians; \"per joint\" is one number for every joint or an array with one number per joint (dof order).\n",
        kind.schema_file(),
        kind.schema_file()
    );
    // sections in the order the tables name them (breadth first from the top level)
    let mut order: Vec<String> = Vec::new();
    let mut queue: Vec<&Value> = vec![&s];
    while !queue.is_empty() {
        for v in std::mem::take(&mut queue) {
            for r in ordered_refs(v) {
                if !order.contains(&r) {
                    if let Some(d) = defs.get(&r) {
                        queue.push(d);
                    }
                    order.push(r);
                }
            }
        }
    }
    let used_in = used_in(&s, &defs);
    section(&mut out, &format!("The {name} file"), &s, &[]);
    for r in &order {
        if let Some(d) = defs.get(r) {
            section(&mut out, r, d, used_in.get(r).map_or(&[][..], Vec::as_slice));
        }
    }
    out.truncate(out.trim_end().len());
    out.push('\n');
    out
}

fn capitalise(s: &str) -> String {
    let mut c = s.chars();
    c.next().map(|f| f.to_uppercase().collect::<String>() + c.as_str()).unwrap_or_default()
}

/// The definition names `v` refers to (`$ref`), in document order.
fn refs(v: &Value) -> Vec<String> {
    let mut out = Vec::new();
    fn walk(v: &Value, out: &mut Vec<String>) {
        match v {
            Value::Object(m) => {
                if let Some(r) = m.get("$ref").and_then(Value::as_str).and_then(|r| r.strip_prefix("#/$defs/")) {
                    if !out.iter().any(|x| x == r) {
                        out.push(r.to_string());
                    }
                }
                for (k, x) in m {
                    if k != "$defs" {
                        walk(x, out);
                    }
                }
            }
            Value::Array(a) => a.iter().for_each(|x| walk(x, out)),
            _ => {}
        }
    }
    walk(v, &mut out);
    out
}

/// The definitions `v` refers to, in the order its tables show them: its keys (required
/// first), then its variants', then any other reference.
fn ordered_refs(v: &Value) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    let props = v.get("properties").and_then(Value::as_object);
    for k in table_keys(v) {
        out.extend(props.map(|p| refs(&p[k])).unwrap_or_default());
    }
    for a in alternatives(v) {
        out.extend(ordered_refs(a));
    }
    out.extend(refs(v));
    let mut seen = Vec::new();
    out.retain(|r| {
        let new = !seen.contains(r);
        seen.push(r.clone());
        new
    });
    out
}

/// An object's keys in table order: the required ones (as the code declares them), then the
/// others (sorted).
fn table_keys(v: &Value) -> Vec<&str> {
    let required: Vec<&str> = v.get("required").and_then(Value::as_array).map(|r| r.iter().filter_map(Value::as_str).collect()).unwrap_or_default();
    let Some(props) = v.get("properties").and_then(Value::as_object) else { return Vec::new() };
    let mut keys: Vec<&str> = required.iter().copied().filter(|k| props.contains_key(*k)).collect();
    keys.extend(props.keys().map(String::as_str).filter(|k| !required.contains(k)));
    keys
}

/// For each definition, where it is used: "`key` of [Owner](#owner)".
fn used_in(root: &Value, defs: &Map<String, Value>) -> BTreeMap<String, Vec<String>> {
    let mut out: BTreeMap<String, Vec<String>> = BTreeMap::new();
    let owners = std::iter::once((String::new(), root)).chain(defs.iter().map(|(k, v)| (k.clone(), v)));
    for (owner, v) in owners {
        for (key, prop) in properties(v) {
            for r in refs(prop) {
                let place = if owner.is_empty() { format!("`{key}` of the file") } else { format!("`{key}` of {}", link(&owner)) };
                let list = out.entry(r).or_default();
                if !list.contains(&place) {
                    list.push(place);
                }
            }
        }
    }
    out
}

/// The `(key, schema)` pairs of an object schema and of each variant of a tagged union.
fn properties(v: &Value) -> Vec<(&str, &Value)> {
    std::iter::once(v)
        .chain(alternatives(v))
        .filter_map(|o| o.get("properties").and_then(Value::as_object))
        .flat_map(|p| p.iter().map(|(k, x)| (k.as_str(), x)))
        .collect()
}

fn alternatives(v: &Value) -> &[Value] {
    v.get("oneOf").or_else(|| v.get("anyOf")).and_then(Value::as_array).map_or(&[], Vec::as_slice)
}

/// A link to a definition's section (mdBook's heading ids: the name in lower case).
fn link(name: &str) -> String {
    format!("[{name}](#{})", name.to_lowercase())
}

/// Text for a table cell: one line, `|` escaped.
fn cell(s: &str) -> String {
    s.replace('\n', " ").replace('|', "\\|")
}

/// One section: heading, description, where it is used, then its keys or values.
fn section(out: &mut String, name: &str, v: &Value, used: &[String]) {
    let _ = writeln!(out, "## {name}\n");
    if let Some(d) = v.get("description").and_then(Value::as_str) {
        let _ = writeln!(out, "{d}\n");
    }
    if !used.is_empty() {
        let _ = writeln!(out, "Used as: {}.\n", used.join(", "));
    }
    if v.get("properties").is_some() {
        keys_table(out, v, None);
        return;
    }
    let alts = alternatives(v);
    let tag = alts.first().and_then(tag_of).map(|t| t.0).filter(|t0| alts.iter().all(|a| tag_of(a).is_some_and(|(t, _)| t == *t0)));
    if let Some(tag) = tag {
        // a tagged union: one table per tag value
        let _ = writeln!(out, "One of these, chosen by `{tag}`:\n");
        for a in alts {
            let (t, value) = tag_of(a).expect("checked above");
            let _ = writeln!(out, "### `\"{t}\": \"{value}\"`\n");
            if let Some(d) = a.get("description").and_then(Value::as_str) {
                let _ = writeln!(out, "{d}\n");
            }
            keys_table(out, a, Some(t));
        }
        return;
    }
    let values = enum_values(v);
    if !values.is_empty() {
        let _ = writeln!(out, "| value | meaning |\n|---|---|");
        for (value, d) in values {
            let _ = writeln!(out, "| `\"{value}\"` | {} |", cell(&d));
        }
        out.push('\n');
        return;
    }
    let _ = writeln!(out, "Type: {}.\n", type_name(v));
}

/// `(tag key, tag value)` of a tagged union's variant: the property with a `const` that every
/// variant requires first.
fn tag_of(v: &Value) -> Option<(&str, &str)> {
    let first = v.get("required")?.as_array()?.first()?.as_str()?;
    let value = v.get("properties")?.get(first)?.get("const")?.as_str()?;
    Some((first, value))
}

/// An enumeration's values and their descriptions (`enum`, or `oneOf` of `const`s).
fn enum_values(v: &Value) -> Vec<(String, String)> {
    if let Some(e) = v.get("enum").and_then(Value::as_array) {
        return e.iter().filter_map(Value::as_str).map(|s| (s.to_string(), String::new())).collect();
    }
    let alts = alternatives(v);
    let mut out = Vec::new();
    for a in alts {
        let d = a.get("description").and_then(Value::as_str).unwrap_or_default().to_string();
        if let Some(c) = a.get("const").and_then(Value::as_str) {
            out.push((c.to_string(), d));
        } else if let Some(e) = a.get("enum").and_then(Value::as_array) {
            out.extend(e.iter().filter_map(Value::as_str).map(|s| (s.to_string(), d.clone())));
        } else {
            return Vec::new();
        }
    }
    out
}

/// The table of an object's keys (without the tag `skip`, which the heading gives).
fn keys_table(out: &mut String, v: &Value, skip: Option<&str>) {
    let required: Vec<&str> = v.get("required").and_then(Value::as_array).map(|r| r.iter().filter_map(Value::as_str).collect()).unwrap_or_default();
    let Some(props) = v.get("properties").and_then(Value::as_object) else { return };
    let keys = table_keys(v);
    let _ = writeln!(out, "| key | type | required / default | description |\n|---|---|---|---|");
    for k in keys {
        if Some(k) == skip {
            continue;
        }
        let p = &props[k];
        let default = if required.contains(&k) {
            "required".to_string()
        } else {
            match p.get("default") {
                Some(d) => format!("`{}`", serde_json::to_string(d).unwrap_or_default()),
                None => "optional".to_string(),
            }
        };
        let d = p.get("description").and_then(Value::as_str).unwrap_or_default();
        let _ = writeln!(out, "| `{k}` | {} | {} | {} |", cell(&type_name(p)), cell(&default), cell(d));
    }
    out.push('\n');
}

/// A short type for people: `number`, `3 × number`, `array of [MotorSpec](#motorspec)`, …
fn type_name(v: &Value) -> String {
    if v.as_bool() == Some(true) {
        return "any JSON value".into();
    }
    if let Some(r) = v.get("$ref").and_then(Value::as_str).and_then(|r| r.strip_prefix("#/$defs/")) {
        return link(r);
    }
    if let Some(c) = v.get("const") {
        return format!("`{c}`");
    }
    let values = enum_values(v);
    if !values.is_empty() {
        return values.iter().map(|(x, _)| format!("`\"{x}\"`")).collect::<Vec<_>>().join(" or ");
    }
    let alts = alternatives(v);
    if !alts.is_empty() {
        let names: Vec<String> = alts.iter().filter(|a| a.get("type") != Some(&json!("null"))).map(type_name).collect();
        return names.join(" or ");
    }
    let types: Vec<&str> = match v.get("type") {
        Some(Value::String(t)) => vec![t.as_str()],
        Some(Value::Array(ts)) => ts.iter().filter_map(Value::as_str).filter(|t| *t != "null").collect(),
        _ => Vec::new(),
    };
    let one = |t: &str| -> String {
        match t {
            "array" => {
                let item = v.get("items").map_or("any JSON value".to_string(), type_name);
                match (v.get("minItems").and_then(Value::as_u64), v.get("maxItems").and_then(Value::as_u64)) {
                    (Some(a), Some(b)) if a == b => format!("{a} × {item}"),
                    _ => format!("array of {item}"),
                }
            }
            "object" => match v.get("additionalProperties") {
                Some(x) if x.is_object() => format!("map of string to {}", type_name(x)),
                _ => "object".into(),
            },
            "integer" if v.get("minimum").and_then(Value::as_u64) == Some(0) => "integer ≥ 0".into(),
            t => t.into(),
        }
    };
    if types.is_empty() {
        "any JSON value".into()
    } else {
        types.iter().map(|t| one(t)).collect::<Vec<_>>().join(" or ")
    }
}

#[cfg(test)]
mod tests;
