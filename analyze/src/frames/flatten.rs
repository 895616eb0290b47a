//! Decoded messages ([`Value`] trees) -> named columns, one row per message.
//!
//! The naming rule (a column name is the dotted path of the field, with array entries named by
//! label rather than by index):
//! - struct fields join with `.`: `actual.x`, `header.stamp.sec`;
//! - an array is expanded, one column per entry, named by its *label*: the joint or contact
//!   name for our arrays ([`schemas::topics::array_index`] and the names in the metadata:
//!   `current.joint4`, `normal_force.elbow7`); the entry of the message's own `name` list for
//!   arrays beside one (`sensor_msgs/JointState`: `position.joint4`; since format version 3 also
//!   `/motors`, `/energy` and `/constraints`, whose `name` is the run's joint or contact names in
//!   array order, so a format-2 file without it gets the same columns); the `child_frame_id` of a
//!   list of transforms (`transforms.link4.translation.z`); else the index (`data.0`);
//! - a list that provided labels (the `name` above) is not a column itself;
//! - each column also knows its field (the path without labels: `current`, as
//!   `schemas::units` spells it) and its entry's label, for units and the long layout;
//! - `bytes` fields (a point cloud's packed data) are left out: they are not per-field values.
//!
//! A column first seen at a later message, or missing from one, holds nulls there (a run whose
//! contact set changed, a format that gained a field). A column whose values change kind
//! (integer then float) is widened to float; a mix of text and numbers becomes text.

use std::collections::HashMap;

use schemas::Value;

/// One column's values, `None` where a message did not have the field.
#[derive(Debug, Clone, PartialEq)]
pub enum ColumnData {
    F64(Vec<Option<f64>>),
    I64(Vec<Option<i64>>),
    U64(Vec<Option<u64>>),
    Bool(Vec<Option<bool>>),
    Str(Vec<Option<String>>),
}

impl ColumnData {
    fn len(&self) -> usize {
        match self {
            ColumnData::F64(v) => v.len(),
            ColumnData::I64(v) => v.len(),
            ColumnData::U64(v) => v.len(),
            ColumnData::Bool(v) => v.len(),
            ColumnData::Str(v) => v.len(),
        }
    }

    fn push_null(&mut self) {
        match self {
            ColumnData::F64(v) => v.push(None),
            ColumnData::I64(v) => v.push(None),
            ColumnData::U64(v) => v.push(None),
            ColumnData::Bool(v) => v.push(None),
            ColumnData::Str(v) => v.push(None),
        }
    }

    /// An empty column of `d`'s kind.
    fn empty_like_data(d: &ColumnData) -> ColumnData {
        match d {
            ColumnData::F64(_) => ColumnData::F64(Vec::new()),
            ColumnData::I64(_) => ColumnData::I64(Vec::new()),
            ColumnData::U64(_) => ColumnData::U64(Vec::new()),
            ColumnData::Bool(_) => ColumnData::Bool(Vec::new()),
            ColumnData::Str(_) => ColumnData::Str(Vec::new()),
        }
    }

    fn empty_like(x: &Value, rows: usize) -> Option<ColumnData> {
        Some(match x {
            Value::F64(_) => ColumnData::F64(vec![None; rows]),
            Value::I64(_) => ColumnData::I64(vec![None; rows]),
            Value::U64(_) => ColumnData::U64(vec![None; rows]),
            Value::Bool(_) => ColumnData::Bool(vec![None; rows]),
            Value::String(_) => ColumnData::Str(vec![None; rows]),
            _ => return None,
        })
    }

    /// Appends `x`, widening the column when `x` is of another kind.
    fn push(&mut self, x: &Value) {
        match (&mut *self, x) {
            (ColumnData::F64(v), _) if x.as_f64().is_some() => v.push(x.as_f64()),
            (ColumnData::I64(v), Value::I64(y)) => v.push(Some(*y)),
            (ColumnData::U64(v), Value::U64(y)) => v.push(Some(*y)),
            (ColumnData::Bool(v), Value::Bool(y)) => v.push(Some(*y)),
            (ColumnData::Str(v), _) => v.push(Some(text(x))),
            _ => {
                self.widen(x);
                self.push(x);
            }
        }
    }

    /// To float when both kinds are numbers, else to text.
    fn widen(&mut self, x: &Value) {
        let numeric = x.as_f64().is_some() && !matches!(self, ColumnData::Str(_));
        *self = if numeric {
            ColumnData::F64(match self {
                ColumnData::I64(v) => v.iter().map(|y| y.map(|y| y as f64)).collect(),
                ColumnData::U64(v) => v.iter().map(|y| y.map(|y| y as f64)).collect(),
                ColumnData::Bool(v) => v.iter().map(|y| y.map(f64::from)).collect(),
                ColumnData::F64(v) => std::mem::take(v),
                ColumnData::Str(_) => unreachable!("excluded above"),
            })
        } else {
            let s = |y: Option<String>| y;
            ColumnData::Str(match self {
                ColumnData::F64(v) => v.iter().map(|y| y.map(|y| y.to_string())).collect(),
                ColumnData::I64(v) => v.iter().map(|y| y.map(|y| y.to_string())).collect(),
                ColumnData::U64(v) => v.iter().map(|y| y.map(|y| y.to_string())).collect(),
                ColumnData::Bool(v) => v.iter().map(|y| y.map(|y| y.to_string())).collect(),
                ColumnData::Str(v) => std::mem::take(v).into_iter().map(s).collect(),
            })
        };
    }
}

fn text(x: &Value) -> String {
    match x {
        Value::String(s) => s.clone(),
        Value::F64(y) => y.to_string(),
        Value::I64(y) => y.to_string(),
        Value::U64(y) => y.to_string(),
        Value::Bool(y) => y.to_string(),
        _ => String::new(),
    }
}

/// Labels of the entries of an array at a field path (`None`: label by index).
pub type Labeller<'a> = dyn Fn(&str) -> Option<&'a [String]> + 'a;

/// What a column holds: the message field (its path without array labels, as
/// `schemas::units` spells it: `current`, `actual.x`, `transforms.translation.z`) and the label
/// of the array entry (`joint4`, `elbow7`, `link3`, `0`; several joined with `.` for arrays in
/// arrays), `None` for a field outside any array.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ColumnField {
    pub field: String,
    pub label: Option<String>,
}

/// Columns built row by row, in the order their fields first appear.
#[derive(Debug, Default)]
pub struct Columns {
    names: Vec<String>,
    fields: Vec<ColumnField>,
    index: HashMap<String, usize>,
    data: Vec<ColumnData>,
    rows: usize,
}

/// Where the visit is: the column name, the field path and the labels so far.
#[derive(Default)]
struct Cursor {
    name: String,
    field: String,
    label: String,
}

impl Cursor {
    fn lens(&self) -> (usize, usize, usize) {
        (self.name.len(), self.field.len(), self.label.len())
    }
    fn truncate(&mut self, (a, b, c): (usize, usize, usize)) {
        self.name.truncate(a);
        self.field.truncate(b);
        self.label.truncate(c);
    }
    fn key(&mut self, key: &str) {
        join(&mut self.name, key);
        join(&mut self.field, key);
    }
    fn entry(&mut self, label: &str) {
        join(&mut self.name, label);
        join(&mut self.label, label);
    }
}

impl Columns {
    /// Appends one message as a row; `labels` names the entries of arrays by field path.
    pub fn push_row(&mut self, msg: &Value, labels: &Labeller<'_>) {
        let mut at = Cursor::default();
        self.visit(msg, &mut at, labels);
        self.rows += 1;
        for col in &mut self.data {
            if col.len() < self.rows {
                col.push_null();
            }
        }
    }

    /// Number of rows pushed.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Number of columns so far.
    pub fn width(&self) -> usize {
        self.names.len()
    }

    /// The rows pushed so far as `(name, what it holds, values)`, in first-appearance order;
    /// the columns (names, kinds) stay, empty, for the next rows (a batch of a streamed table).
    pub fn take_rows(&mut self) -> Vec<(String, ColumnField, ColumnData)> {
        self.rows = 0;
        let empty = |d: &ColumnData| ColumnData::empty_like_data(d);
        self.names
            .iter()
            .zip(&self.fields)
            .zip(self.data.iter_mut())
            .map(|((n, f), d)| {
                let next = empty(d);
                (n.clone(), f.clone(), std::mem::replace(d, next))
            })
            .collect()
    }

    /// Columns of `plan`'s names, fields and kinds (those of a first pass over the whole
    /// topic), in its order, without rows: the batches of a second pass then all have every
    /// column, in the order and of the kind the whole topic read at once gives.
    pub fn planned(plan: impl IntoIterator<Item = (String, ColumnField, ColumnData)>) -> Columns {
        let mut c = Columns::default();
        for (name, field, data) in plan {
            c.index.insert(name.clone(), c.data.len());
            c.names.push(name);
            c.fields.push(field);
            c.data.push(ColumnData::empty_like_data(&data));
        }
        c
    }

    /// `(name, what it holds, values)` in first-appearance order.
    pub fn into_columns(self) -> impl Iterator<Item = (String, ColumnField, ColumnData)> {
        self.names.into_iter().zip(self.fields).zip(self.data).map(|((n, f), d)| (n, f, d))
    }

    fn scalar(&mut self, at: &Cursor, x: &Value) {
        let k = match self.index.get(&at.name) {
            Some(&k) => k,
            None => {
                let Some(col) = ColumnData::empty_like(x, self.rows) else {
                    return;
                };
                self.names.push(at.name.clone());
                let label = (!at.label.is_empty()).then(|| at.label.clone());
                self.fields.push(ColumnField { field: at.field.clone(), label });
                self.index.insert(at.name.clone(), self.data.len());
                self.data.push(col);
                self.data.len() - 1
            }
        };
        let col = &mut self.data[k];
        if col.len() > self.rows {
            return; // a duplicate name within one message (e.g. two equal labels): first wins
        }
        col.push(x);
    }

    fn visit(&mut self, v: &Value, at: &mut Cursor, labels: &Labeller<'_>) {
        match v {
            Value::Bytes(_) => {}
            Value::Struct(fields) => {
                // sensor_msgs/JointState, and since format 3 /motors, /energy, /constraints:
                // `name` labels its sibling arrays
                let names: Option<Vec<String>> = fields
                    .iter()
                    .find(|(k, _)| k == schemas::topics::LABEL_LIST_FIELD)
                    .and_then(|(_, v)| v.as_list())
                    .and_then(|l| l.iter().map(|x| x.as_str().map(String::from)).collect());
                let len = at.lens();
                for (key, field) in fields {
                    if key == schemas::topics::LABEL_LIST_FIELD && names.is_some() && field.as_list().is_some() {
                        continue;
                    }
                    at.key(key);
                    match (field, &names) {
                        (Value::List(items), Some(n)) if items.len() == n.len() => {
                            self.list(items, at, Some(n), labels);
                        }
                        _ => self.visit(field, at, labels),
                    }
                    at.truncate(len);
                }
            }
            Value::List(items) => {
                let own = labels(&at.field);
                self.list(items, at, own, labels);
            }
            scalar => self.scalar(at, scalar),
        }
    }

    fn list(&mut self, items: &[Value], at: &mut Cursor, names: Option<&[String]>, labels: &Labeller<'_>) {
        let names = names.filter(|n| n.len() == items.len());
        let len = at.lens();
        for (k, item) in items.iter().enumerate() {
            match (names, schemas::topics::entry_label(item)) {
                (Some(n), _) => at.entry(&n[k]),
                (None, Some(label)) => at.entry(label),
                _ => at.entry(&k.to_string()),
            }
            self.visit(item, at, labels);
            at.truncate(len);
        }
    }
}

fn join(path: &mut String, key: &str) {
    if !path.is_empty() {
        path.push('.');
    }
    path.push_str(key);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(fields: &[(&str, Value)]) -> Value {
        Value::Struct(fields.iter().map(|(k, v)| (k.to_string(), v.clone())).collect())
    }
    fn f(x: &[f64]) -> Value {
        Value::List(x.iter().map(|&y| Value::F64(y)).collect())
    }

    #[test]
    fn arrays_are_named_by_labels_then_by_index() {
        let joints = vec!["joint1".to_string(), "joint2".to_string()];
        let labels = |p: &str| (p == "current").then_some(joints.as_slice());
        let mut c = Columns::default();
        let msg = s(&[
            ("time", Value::F64(0.5)),
            ("current", f(&[1.0, 2.0])),
            ("other", f(&[3.0])),
            ("blob", Value::Bytes(vec![1, 2])),
            ("hand", s(&[("x", Value::F64(4.0))])),
        ]);
        c.push_row(&msg, &labels);
        let cols: Vec<(String, ColumnField, ColumnData)> = c.into_columns().collect();
        let names: Vec<&str> = cols.iter().map(|(n, _, _)| n.as_str()).collect();
        assert_eq!(names, ["time", "current.joint1", "current.joint2", "other.0", "hand.x"]);
        assert_eq!(cols[2].2, ColumnData::F64(vec![Some(2.0)]));
        // the field and the entry of each column, for units and the long layout
        let field = |k: usize| (cols[k].1.field.as_str(), cols[k].1.label.as_deref());
        assert_eq!(field(0), ("time", None));
        assert_eq!(field(2), ("current", Some("joint2")));
        assert_eq!(field(3), ("other", Some("0")));
        assert_eq!(field(4), ("hand.x", None));
    }

    #[test]
    fn joint_state_names_label_their_arrays_and_transforms_their_child_frames() {
        let msg = s(&[
            ("name", Value::List(vec![Value::String("a".into()), Value::String("b".into())])),
            ("position", f(&[1.0, 2.0])),
            (
                "transforms",
                Value::List(vec![s(&[
                    ("child_frame_id", Value::String("link1".into())),
                    ("translation", s(&[("z", Value::F64(0.1))])),
                ])]),
            ),
        ]);
        let mut c = Columns::default();
        c.push_row(&msg, &|_| None);
        let cols: Vec<(String, ColumnField, ColumnData)> = c.into_columns().collect();
        let names: Vec<&str> = cols.iter().map(|(n, _, _)| n.as_str()).collect();
        assert_eq!(
            names,
            ["position.a", "position.b", "transforms.link1.child_frame_id", "transforms.link1.translation.z"]
        );
        assert_eq!(cols[3].1, ColumnField { field: "transforms.translation.z".into(), label: Some("link1".into()) });
        assert_eq!(cols[1].1, ColumnField { field: "position".into(), label: Some("b".into()) });
    }

    /// A field missing from a message is null there; a field appearing late is null before;
    /// integers then floats widen to floats; numbers then text widen to text.
    #[test]
    fn missing_fields_are_null_and_kinds_widen() {
        let mut c = Columns::default();
        let none = |_: &str| None;
        c.push_row(&s(&[("a", Value::I64(1)), ("b", Value::U64(7))]), &none);
        c.push_row(&s(&[("a", Value::F64(2.5)), ("c", Value::Bool(true))]), &none);
        c.push_row(&s(&[("b", Value::String("x".into()))]), &none);
        assert_eq!(c.rows(), 3);
        let cols: HashMap<String, ColumnData> = c.into_columns().map(|(n, _, d)| (n, d)).collect();
        assert_eq!(cols["a"], ColumnData::F64(vec![Some(1.0), Some(2.5), None]));
        assert_eq!(cols["b"], ColumnData::Str(vec![Some("7".into()), None, Some("x".into())]));
        assert_eq!(cols["c"], ColumnData::Bool(vec![None, Some(true), None]));
    }
}
