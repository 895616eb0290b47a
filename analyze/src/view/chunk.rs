//! A Rerun chunk as an Arrow record batch: one entity, some rows, one list column per component.
//!
//! The layout is Rerun's "sorbet" chunk schema (`re_sorbet` in <https://github.com/rerun-io/rerun>,
//! version `0.1.4`, the one the 0.41 SDK writes; checked against its files with pyarrow):
//! - schema metadata `rerun:entity_path`, `rerun:id` (the chunk id) and `sorbet:version`;
//! - a non-null `FixedSizeBinary(16)` column `rerun.controls.RowId` (Arrow extension
//!   `rerun.datatypes.TUID`), sorted;
//! - one column per timeline (`rerun:kind = index`): here `sim_time`, `Duration(ns)`, so that the
//!   viewer shows durations from t = 0, not 1970 dates; the blueprint's chunks use the sequence
//!   timeline `blueprint`; a static chunk has none;
//! - one `List<…>` column per component (`rerun:kind = data`), named `Archetype:field`, with
//!   `rerun:archetype`, `rerun:component` and `rerun:component_type`: each row holds the
//!   instances of that component at that time (one scalar, N points, …).
//!
//! Datatypes of the components used here (`rerun.components.*` / `rerun.datatypes.*`):
//! colours are `u32` `0xRRGGBBAA`; positions, vectors, half sizes and translations
//! `FixedSizeList<f32, 3>`; quaternions `FixedSizeList<f32, 4>` `[x, y, z, w]`; radii, lengths and
//! widths `f32`; scalars `f64`; enums (`FillMode`, `ContainerKind`, …) `u8`; texts UTF-8.

use std::collections::HashMap;
use std::sync::Arc;

use arrow_array::builder::{FixedSizeBinaryBuilder, FixedSizeListBuilder, Float32Builder, UInt8Builder};
use arrow_array::{
    Array, ArrayRef, BooleanArray, DurationNanosecondArray, Float32Array, Float64Array, Int64Array, ListArray, RecordBatch,
    RecordBatchOptions, StringArray, UInt32Array, UInt8Array,
};
use arrow_buffer::OffsetBuffer;
use arrow_schema::{ArrowError, DataType, Field, Schema, TimeUnit};

use super::rrd::Tuid;

/// The `sorbet:version` of the chunks written.
pub const SORBET_VERSION: &str = "0.1.4";
/// The timeline of every recorded sample: simulated time from t = 0.
pub const SIM_TIME: &str = "sim_time";

/// Which timeline a chunk's rows are on.
#[derive(Debug, Clone, PartialEq)]
pub enum Index {
    /// Static data: valid at every time (geometry, series styles).
    Static,
    /// `sim_time`, ns from the start of the run.
    SimTime(Vec<i64>),
    /// The blueprint's sequence timeline (`blueprint`), one row at 0.
    Blueprint,
}

/// One component column: `Archetype:field`, its full archetype and component type names.
#[derive(Debug, Clone)]
pub struct Column {
    pub archetype: &'static str,
    pub field: &'static str,
    pub component_type: &'static str,
    pub values: ArrayRef,
}

/// A chunk of one entity, ready to be encoded.
#[derive(Debug, Clone)]
pub struct Chunk {
    pub entity_path: String,
    pub index: Index,
    pub rows: usize,
    pub columns: Vec<Column>,
}

impl Chunk {
    /// A chunk of `rows` rows on `index` (for [`Index::SimTime`], `rows` is its length).
    pub fn new(entity_path: impl Into<String>, index: Index) -> Self {
        let rows = match &index {
            Index::SimTime(t) => t.len(),
            Index::Static | Index::Blueprint => 1,
        };
        Chunk { entity_path: entity_path.into(), index, rows, columns: Vec::new() }
    }

    /// Adds a component column of `archetype` (full name, e.g. `rerun.archetypes.Points3D`):
    /// `field` (e.g. `positions`) of type `component_type`; `values` has one list per row.
    pub fn with(mut self, archetype: &'static str, field: &'static str, component_type: &'static str, values: ArrayRef) -> Self {
        assert_eq!(values.len(), self.rows, "{}: component {field}: one list per row", self.entity_path);
        self.columns.push(Column { archetype, field, component_type, values });
        self
    }

    pub fn is_static(&self) -> bool {
        self.index == Index::Static
    }

    /// The Arrow IPC stream of this chunk as one record batch, rows numbered from `first_row`
    /// (row `k` gets [`Tuid`] `(first_row.time_ns + k, first_row.inc)`).
    pub fn to_ipc(&self, chunk_id: Tuid, first_row: Tuid) -> Result<Vec<u8>, ArrowError> {
        let batch = self.to_record_batch(chunk_id, first_row)?;
        let mut out = Vec::new();
        let mut w = arrow_ipc::writer::StreamWriter::try_new(&mut out, batch.schema_ref())?;
        w.write(&batch)?;
        w.finish()?;
        drop(w);
        Ok(out)
    }

    /// The record batch of [`Chunk::to_ipc`].
    pub fn to_record_batch(&self, chunk_id: Tuid, first_row: Tuid) -> Result<RecordBatch, ArrowError> {
        let meta = |pairs: &[(&str, &str)]| -> HashMap<String, String> {
            pairs.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()
        };
        let mut fields = Vec::with_capacity(self.columns.len() + 2);
        let mut arrays: Vec<ArrayRef> = Vec::with_capacity(self.columns.len() + 2);

        // row ids
        let mut rows = FixedSizeBinaryBuilder::with_capacity(self.rows, 16);
        let t0 = first_row.time_ns.unwrap_or(0);
        for k in 0..self.rows {
            rows.append_value(Tuid::new(t0 + k as u64, first_row.inc.unwrap_or(0)).bytes())?;
        }
        fields.push(Field::new("rerun.controls.RowId", DataType::FixedSizeBinary(16), false).with_metadata(meta(&[
            ("ARROW:extension:name", "rerun.datatypes.TUID"),
            ("ARROW:extension:metadata", r#"{"namespace":"row"}"#),
            ("rerun:is_sorted", "true"),
            ("rerun:kind", "control"),
        ])));
        arrays.push(Arc::new(rows.finish()));

        // the timeline
        let index_meta = |name: &str| meta(&[("rerun:index_name", name), ("rerun:is_sorted", "true"), ("rerun:kind", "index")]);
        match &self.index {
            Index::Static => {}
            Index::SimTime(t) => {
                fields.push(Field::new(SIM_TIME, DataType::Duration(TimeUnit::Nanosecond), true).with_metadata(index_meta(SIM_TIME)));
                arrays.push(Arc::new(DurationNanosecondArray::from(t.clone())));
            }
            Index::Blueprint => {
                fields.push(Field::new("blueprint", DataType::Int64, true).with_metadata(index_meta("blueprint")));
                arrays.push(Arc::new(Int64Array::from(vec![0i64; self.rows])));
            }
        }

        // the components
        for c in &self.columns {
            let short = c.archetype.rsplit('.').next().unwrap_or(c.archetype);
            let name = format!("{short}:{}", c.field);
            fields.push(Field::new(&name, c.values.data_type().clone(), true).with_metadata(meta(&[
                ("rerun:archetype", c.archetype),
                ("rerun:component", &name),
                ("rerun:component_type", c.component_type),
                ("rerun:kind", "data"),
            ])));
            arrays.push(c.values.clone());
        }

        let chunk_name = chunk_id.chunk_name();
        let schema = Schema::new(fields).with_metadata(meta(&[
            ("rerun:entity_path", &self.entity_path),
            ("rerun:id", &chunk_name),
            ("sorbet:version", SORBET_VERSION),
        ]));
        RecordBatch::try_new_with_options(Arc::new(schema), arrays, &RecordBatchOptions::new().with_row_count(Some(self.rows)))
    }
}

// ---- component columns: one list of instances per row ----

fn list(values: ArrayRef, lens: impl IntoIterator<Item = usize>, item_nullable: bool) -> ArrayRef {
    let field = Arc::new(Field::new("item", values.data_type().clone(), item_nullable));
    Arc::new(ListArray::new(field, OffsetBuffer::from_lengths(lens), values, None))
}

/// `List<f64>`: one list per row.
pub fn f64_lists(rows: &[Vec<f64>]) -> ArrayRef {
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    list(Arc::new(Float64Array::from(flat)), rows.iter().map(Vec::len), true)
}

/// `List<f64>` with one value per row (a time series of scalars).
pub fn f64_each(values: &[f64]) -> ArrayRef {
    list(Arc::new(Float64Array::from(values.to_vec())), values.iter().map(|_| 1), true)
}

/// `List<f32>`: one list per row.
pub fn f32_lists(rows: &[Vec<f32>]) -> ArrayRef {
    let flat: Vec<f32> = rows.iter().flatten().copied().collect();
    list(Arc::new(Float32Array::from(flat)), rows.iter().map(Vec::len), true)
}

/// `List<u32>`: one list per row (colours `0xRRGGBBAA`).
pub fn u32_lists(rows: &[Vec<u32>]) -> ArrayRef {
    let flat: Vec<u32> = rows.iter().flatten().copied().collect();
    list(Arc::new(UInt32Array::from(flat)), rows.iter().map(Vec::len), true)
}

/// `List<u8>`: one list per row (enums).
pub fn u8_lists(rows: &[Vec<u8>]) -> ArrayRef {
    let flat: Vec<u8> = rows.iter().flatten().copied().collect();
    list(Arc::new(UInt8Array::from(flat)), rows.iter().map(Vec::len), true)
}

/// `List<bool>`: one list per row.
pub fn bool_lists(rows: &[Vec<bool>]) -> ArrayRef {
    let flat: Vec<bool> = rows.iter().flatten().copied().collect();
    list(Arc::new(BooleanArray::from(flat)), rows.iter().map(Vec::len), true)
}

/// `List<Utf8>`: one list per row.
pub fn str_lists(rows: &[Vec<String>]) -> ArrayRef {
    let flat: Vec<&str> = rows.iter().flatten().map(String::as_str).collect();
    list(Arc::new(StringArray::from(flat)), rows.iter().map(Vec::len), true)
}

fn fixed_f32<const N: usize>(items: impl Iterator<Item = [f32; N]>, capacity: usize) -> ArrayRef {
    let mut b = FixedSizeListBuilder::with_capacity(Float32Builder::with_capacity(capacity * N), N as i32, capacity)
        .with_field(Arc::new(Field::new("item", DataType::Float32, false)));
    for item in items {
        b.values().append_slice(&item);
        b.append(true);
    }
    Arc::new(b.finish())
}

/// `List<FixedSizeList<f32, 3>>`: N 3-vectors per row (positions, vectors, half sizes).
pub fn vec3_lists(rows: &[Vec<[f32; 3]>]) -> ArrayRef {
    let n = rows.iter().map(Vec::len).sum();
    list(fixed_f32(rows.iter().flatten().copied(), n), rows.iter().map(Vec::len), true)
}

/// `List<FixedSizeList<f32, 4>>`: N quaternions `[x, y, z, w]` per row.
pub fn quat_lists(rows: &[Vec<[f32; 4]>]) -> ArrayRef {
    let n = rows.iter().map(Vec::len).sum();
    list(fixed_f32(rows.iter().flatten().copied(), n), rows.iter().map(Vec::len), true)
}

/// `List<FixedSizeList<u32, 3>>`: N triangles (vertex indices) per row (`TriangleIndices`).
pub fn tri_lists(rows: &[Vec<[u32; 3]>]) -> ArrayRef {
    use arrow_array::builder::UInt32Builder;
    let n: usize = rows.iter().map(Vec::len).sum();
    let mut b = FixedSizeListBuilder::with_capacity(UInt32Builder::with_capacity(n * 3), 3, n)
        .with_field(Arc::new(Field::new("item", DataType::UInt32, false)));
    for t in rows.iter().flatten() {
        b.values().append_slice(t);
        b.append(true);
    }
    list(Arc::new(b.finish()), rows.iter().map(Vec::len), true)
}

/// `List<List<FixedSizeList<f32, 3>>>`: N line strips per row.
pub fn strip_lists(rows: &[Vec<Vec<[f32; 3]>>]) -> ArrayRef {
    let strips: Vec<&Vec<[f32; 3]>> = rows.iter().flatten().collect();
    let n = strips.iter().map(|s| s.len()).sum();
    let points = fixed_f32(strips.iter().flat_map(|s| s.iter().copied()), n);
    let inner = list(points, strips.iter().map(|s| s.len()), false);
    list(inner, rows.iter().map(Vec::len), true)
}

/// `List<FixedSizeList<u8, 16>>`: N UUIDs per row (the blueprint's root container).
pub fn uuid_lists(rows: &[Vec<[u8; 16]>]) -> ArrayRef {
    let n: usize = rows.iter().map(Vec::len).sum();
    let mut b = FixedSizeListBuilder::with_capacity(UInt8Builder::with_capacity(n * 16), 16, n)
        .with_field(Arc::new(Field::new("item", DataType::UInt8, false)));
    for id in rows.iter().flatten() {
        b.values().append_slice(id);
        b.append(true);
    }
    list(Arc::new(b.finish()), rows.iter().map(Vec::len), true)
}

/// `List<FixedSizeList<f64, 2>>` with one range `[lo, hi]` (`Range1D`).
pub fn range_lists(lo: f64, hi: f64) -> ArrayRef {
    use arrow_array::builder::Float64Builder;
    let mut b = FixedSizeListBuilder::new(Float64Builder::new(), 2).with_field(Arc::new(Field::new("item", DataType::Float64, false)));
    b.values().append_slice(&[lo, hi]);
    b.append(true);
    list(Arc::new(b.finish()), [1], true)
}

/// A colour `0xRRGGBBAA` from its components.
pub const fn rgba(r: u8, g: u8, b: u8, a: u8) -> u32 {
    (r as u32) << 24 | (g as u32) << 16 | (b as u32) << 8 | a as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_chunk_has_the_sorbet_layout() {
        let c = Chunk::new("/a/b", Index::SimTime(vec![0, 10, 20]))
            .with("rerun.archetypes.Scalars", "scalars", "rerun.components.Scalar", f64_each(&[1.0, 2.0, 3.0]));
        let b = c.to_record_batch(Tuid::new(7, 9), Tuid::new(100, 9)).unwrap();
        assert_eq!(b.num_rows(), 3);
        let s = b.schema();
        assert_eq!(s.metadata()["rerun:entity_path"], "/a/b");
        assert_eq!(s.metadata()["rerun:id"], "chunk_00000000000000070000000000000009");
        let names: Vec<&str> = s.fields().iter().map(|f| f.name().as_str()).collect();
        assert_eq!(names, ["rerun.controls.RowId", "sim_time", "Scalars:scalars"]);
        assert_eq!(s.field(2).metadata()["rerun:component_type"], "rerun.components.Scalar");
        assert_eq!(rgba(255, 0, 0, 255), 4278190335);
    }
}
