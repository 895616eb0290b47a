//! `analyze export` as one call: a recording's topics ([`crate::frames`], feature `tables`) as
//! Parquet or CSV tables, wide or long, and `metadata.json`, so that a caller needs no polars
//! type and a build without the feature says what is missing. Every file goes through
//! `schemas::atomic` (a lock on the final name, a temporary name of its own, a rename), so
//! neither a killed export nor a second one at the same time ever leaves a half-written table
//! under its final name. The directory of one recording's tables is marked while it is written:
//! a file [`INCOMPLETE`] comes first and goes last, so a killed or disk-full export leaves a
//! directory that says it is incomplete, never tables that look finished without their
//! `metadata.json` (issue 29).
//!
//! Units (`schemas::units`, the one table) travel with the tables:
//! - Parquet: each column's Arrow field metadata `unit` (`current.joint4` → `A`), which is how
//!   Arrow carries per-column metadata into Parquet (the `ARROW:schema` key of the file's
//!   key-value metadata, <https://arrow.apache.org/docs/format/Columnar.html#custom-application-metadata>
//!   and the Parquet format's `FileMetaData.key_value_metadata`): pyarrow reads it as
//!   `schema.field(name).metadata[b"unit"]`, polars (Rust) as the Arrow schema's field metadata.
//!   polars' `ParquetWriter` builds the Arrow schema from the frame's dtypes alone (polars 0.55
//!   fields have no metadata), so the key is written here, from the same dtypes with the units
//!   added, through the writer's key-value metadata (which then takes the place of its own).
//!   The file also has a key `units`: a JSON object column → unit, for readers that show only
//!   the file's key-value metadata (`polars.read_parquet_metadata` in Python);
//! - CSV: in the header, `name [unit]` (`current.joint4 [A]`, `time [s]`); a column without a
//!   unit is its bare name. `re.fullmatch(r"(.*) \[(.*)\]", header)` splits them.
//! - long layout: a `unit` column beside `value`.

use std::path::Path;
#[cfg(feature = "tables")]
use std::path::PathBuf;

#[cfg(feature = "tables")]
use polars::io::parquet::write::BatchedWriter;
#[cfg(feature = "tables")]
use polars::prelude::*;

#[cfg(feature = "tables")]
use crate::frames::{self, streamed::Streamed, TopicFrame};
use crate::Error;

/// File format of the tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExportFormat {
    Parquet,
    Csv,
}

impl ExportFormat {
    pub fn extension(self) -> &'static str {
        match self {
            ExportFormat::Parquet => "parquet",
            ExportFormat::Csv => "csv",
        }
    }
}

/// Shape of the tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Layout {
    /// One row per sample, one column per signal (`current.joint4`).
    #[default]
    Wide,
    /// One row per sample and signal: `time, topic, signal, name, unit, value`
    /// (`crate::frames::long`).
    Long,
}

impl Layout {
    pub fn as_str(self) -> &'static str {
        match self {
            Layout::Wide => "wide",
            Layout::Long => "long",
        }
    }
}

/// What to export and how.
#[derive(Debug, Clone, Copy)]
pub struct ExportOptions<'a> {
    pub format: ExportFormat,
    pub layout: Layout,
    /// Only these topics (viewer layouts too); empty: the default set (every decoded topic but
    /// viewer layouts, `crate::frames::is_viewer_layout`).
    pub topics: &'a [&'a str],
    /// Viewer-layout topics to add to the default set (`tf`, `/hand_points`, `all`).
    pub include: &'a [&'a str],
}

impl Default for ExportOptions<'_> {
    fn default() -> Self {
        Self { format: ExportFormat::Parquet, layout: Layout::Wide, topics: &[], include: &[] }
    }
}

/// What [`export_file`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct Exported {
    /// Topic tables written (besides `metadata.json`).
    pub tables: usize,
    /// Rows over all tables.
    pub rows: usize,
    /// Topics not exported (their reasons are in `metadata.json`).
    pub skipped: usize,
    /// The run's status and reason (record `result`), when the recording has one.
    pub result: Option<schemas::RunResult>,
}

/// Writes the topics of the recording at `path` into `dir`. A topic asked for (`topics`) that
/// the recording does not have (with messages) is an error naming it.
pub fn export_file(path: &Path, dir: &Path, options: &ExportOptions<'_>) -> Result<Exported, Error> {
    #[cfg(feature = "tables")]
    {
        let file = || path.display().to_string();
        let topics = options.topics;
        let select = frames::Selection { only: (!topics.is_empty()).then_some(topics), include: options.include };
        let mut f = frames::streamed::plan(path, select)?;
        for t in topics {
            if !f.topics.iter().any(|p| p.topic == *t) {
                let why = f.skipped.iter().find(|(s, _)| s == t).map(|(_, w)| w.clone());
                let why = why.filter(|w| w != schemas::NOT_SELECTED).unwrap_or_else(|| {
                    let have: Vec<&str> = f.skipped.iter().map(|(s, _)| s.as_str()).collect();
                    format!("no such topic with messages (the recording has: {})", have.join(", "))
                });
                return Err(Error::Table { file: file(), detail: format!("topic {t}: {why}") });
            }
        }
        let (rows, tables) = write_marked(dir, path, |dir| {
            let w = write_streamed(&mut f, dir, options.format, options.layout)?;
            Ok((w.rows, w.tables.len()))
        })?;
        let result = match f.metadata.get(<schemas::RunResult as schemas::MetadataRecord>::NAME) {
            Some(fields) => Some(
                serde_json::to_value(fields)
                    .and_then(serde_json::from_value::<schemas::RunResult>)
                    .map_err(|e| Error::Table { file: file(), detail: format!("metadata record `result`: {e}") })?,
            ),
            None => None,
        };
        Ok(Exported { tables, rows, skipped: f.skipped.len(), result })
    }
    #[cfg(not(feature = "tables"))]
    {
        let _ = (path, dir, options);
        Err(Error::TablesUnavailable)
    }
}

/// The marker file of an export directory that is being written: `INCOMPLETE`.
pub const INCOMPLETE: &str = "INCOMPLETE";

/// Writes into `dir` with `write`, marked incomplete meanwhile: [`INCOMPLETE`] is written (and
/// synced) before anything else and removed only after `write` has succeeded, so a killed or
/// disk-full export leaves the marker beside whatever it wrote (an earlier export's tables of
/// the other format stay, as before). A directory without the marker is a finished export.
#[cfg(feature = "tables")]
fn write_marked<T>(dir: &Path, source: &Path, write: impl FnOnce(&Path) -> Result<T, Error>) -> Result<T, Error> {
    let io = |p: &Path, op: &'static str| {
        let file = p.display().to_string();
        move |source| Error::Io { file, op, source }
    };
    std::fs::create_dir_all(dir).map_err(io(dir, "creating"))?;
    let marker = dir.join(INCOMPLETE);
    let text = format!(
        "analyze export of {} did not finish (killed, or an error it reported): the tables here may be partial or stale; run it again\n",
        source.display()
    );
    {
        use std::io::Write;
        let mut f = std::fs::File::create(&marker).map_err(io(&marker, "creating"))?;
        f.write_all(text.as_bytes()).and_then(|()| f.sync_all()).map_err(io(&marker, "writing"))?;
    }
    let out = write(dir)?;
    std::fs::remove_file(&marker).map_err(io(&marker, "removing"))?;
    Ok(out)
}

#[cfg(feature = "tables")]
/// The file name of a topic's table: `/joint_states` -> `joint_states.parquet`.
pub fn topic_file_name(topic: &str, format: ExportFormat) -> String {
    let stem: String = topic
        .trim_start_matches('/')
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' })
        .collect();
    let stem = if stem.is_empty() { "topic".into() } else { stem };
    format!("{stem}.{}", format.extension())
}

#[cfg(feature = "tables")]
/// The file of each topic: [`topic_file_name`], with `_2`, `_3` ... before the extension when
/// two topics map to one name (`/a/b` and `/a_b`).
fn file_names<'a>(topics: impl Iterator<Item = &'a str>, format: ExportFormat) -> Vec<String> {
    let mut used = std::collections::BTreeSet::new();
    topics
        .map(|t| {
            let base = topic_file_name(t, format);
            let mut name = base.clone();
            let mut k = 2;
            while !used.insert(name.clone()) {
                let stem = base.trim_end_matches(&format!(".{}", format.extension()));
                name = format!("{stem}_{k}.{}", format.extension());
                k += 1;
            }
            name
        })
        .collect()
}

/// What [`write_streamed`] wrote.
#[cfg(feature = "tables")]
#[derive(Debug, Clone)]
pub struct Written {
    /// The topic tables.
    pub tables: Vec<PathBuf>,
    /// Rows over all of them.
    pub rows: usize,
    /// `metadata.json`.
    pub metadata: PathBuf,
}

/// The `time` column's description in `metadata.json`.
#[cfg(feature = "tables")]
const TIME_DOC: &str = "the sample's simulated time in s from the start of the run (the MCAP log time, whole ns); \
     the only time column: every topic's times are equal where their samples are";

/// What the first batch says of a table: its columns, their units, the text columns left out.
#[cfg(feature = "tables")]
type TableHead = (Vec<String>, Vec<(String, &'static str)>, Vec<String>);

/// Writes one file per topic into `dir` (created if needed), in `layout`, plus `metadata.json`
/// (the metadata records typed, each table's columns and units, and the topics not exported
/// with the reason), for a recording read in batches ([`frames::streamed`]): each topic's table
/// is written batch by batch as the file is read again (Parquet: one row group per batch; CSV:
/// the header, then the rows of each batch), so memory is bounded by a batch, not the file. The
/// tables have the columns and values of the frames read whole (module docs of
/// `frames::streamed`).
#[cfg(feature = "tables")]
pub fn write_streamed(frames: &mut Streamed, dir: &Path, format: ExportFormat, layout: Layout) -> Result<Written, Error> {
    std::fs::create_dir_all(dir).map_err(|source| Error::Io {
        file: dir.display().to_string(),
        op: "creating",
        source,
    })?;
    let files = file_names(frames.topics.iter().map(|t| t.topic.as_str()), format);
    let mut tables = Vec::new();
    let mut rows = 0;
    let mut listed = Vec::new();
    for (k, name) in files.iter().enumerate() {
        let path = dir.join(name);
        let table_err = |e: PolarsError| Error::Table { file: path.display().to_string(), detail: format!("building the table: {e}") };
        let write_err = |e: PolarsError| Error::Table { file: path.display().to_string(), detail: format!("writing the table: {e}") };
        // what the first batch says of the table: columns, units, text columns left out
        let mut first: Option<TableHead> = None;
        let mut height = 0;
        schemas::atomic::write_with(&path, |f: &mut std::fs::File| -> Result<(), Error> {
            let mut parquet: Option<BatchedWriter<&mut std::fs::File>> = None;
            // the file, until the Parquet writer takes it at the first batch
            let mut file = Some(f);
            // the long layout makes a row of six columns of each value: smaller batches
            let cells = match layout {
                Layout::Wide => frames::streamed::MAX_CELLS,
                Layout::Long => frames::streamed::MAX_CELLS / 8,
            };
            frames.batches(k, cells, |t| {
                let (mut df, units, text) = match layout {
                    Layout::Wide => (t.frame.clone(), wide_units(&t), Vec::new()),
                    Layout::Long => {
                        let (df, text) = frames::long::long_frame(&t).map_err(table_err)?;
                        (df, vec![(frames::TIME_COLUMN.to_string(), frames::TIME_UNIT)], text)
                    }
                };
                let head = first.is_none();
                if head {
                    let columns = df.get_column_names().iter().map(|c| c.to_string()).collect();
                    first = Some((columns, wide_units(&t), text));
                }
                height += df.height();
                match format {
                    ExportFormat::Parquet => {
                        if let Some(file) = file.take() {
                            let kv = parquet_metadata(&df, &units);
                            parquet = Some(ParquetWriter::new(file).with_key_value_metadata(Some(kv)).batched(df.schema()).map_err(write_err)?);
                        }
                        if let Some(w) = parquet.as_mut() {
                            w.write_batch(&df).map_err(write_err)?;
                        }
                    }
                    ExportFormat::Csv => {
                        if head {
                            df.set_column_names(csv_header(&df, &units).as_slice()).map_err(write_err)?;
                        }
                        if let Some(file) = file.as_deref_mut() {
                            CsvWriter::new(file).include_header(head).finish(&mut df).map_err(write_err)?;
                        }
                    }
                }
                Ok(())
            })?;
            if let Some(w) = parquet {
                w.finish().map_err(write_err)?;
            }
            Ok(())
        })?;
        rows += height;
        let t = &frames.topics[k];
        let (columns, units, text) = first.unwrap_or_default();
        let mut entry = serde_json::json!({
            "topic": t.topic,
            "schema": t.schema_name,
            "file": name,
            "rows": height,
            "columns": columns,
            "units": units.into_iter().map(|(c, u)| (c, serde_json::Value::from(u))).collect::<serde_json::Map<_, _>>(),
        });
        if !text.is_empty() {
            entry["text_columns_left_out"] = serde_json::json!(text);
        }
        listed.push(entry);
        tables.push(path);
    }
    write_metadata(dir, &frames.source, &frames.metadata, &frames.skipped, format, layout, listed, tables, rows)
}

/// Writes `metadata.json` into `dir`: the recording's metadata records typed, the tables
/// `listed`, the topics skipped with the reason.
#[cfg(feature = "tables")]
#[allow(clippy::too_many_arguments)]
fn write_metadata(
    dir: &Path,
    source: &str,
    metadata: &std::collections::BTreeMap<String, std::collections::BTreeMap<String, String>>,
    skipped: &[(String, String)],
    format: ExportFormat,
    layout: Layout,
    listed: Vec<serde_json::Value>,
    tables: Vec<PathBuf>,
    rows: usize,
) -> Result<Written, Error> {
    let meta = serde_json::json!({
        "source": source,
        "format": format.extension(),
        "layout": layout.as_str(),
        "time": {"column": frames::TIME_COLUMN, "unit": frames::TIME_UNIT, "doc": TIME_DOC},
        "units": "Parquet: each column's field metadata `unit` (and the file's key `units`); CSV: `name [unit]` in the header; long layout: the `unit` column; here: `topics[].units`",
        "metadata": schemas::meta::typed_records(metadata),
        "topics": listed,
        "skipped": skipped.iter().map(|(t, why)| serde_json::json!({"topic": t, "reason": why})).collect::<Vec<_>>(),
    });
    let path = dir.join("metadata.json");
    let text = serde_json::to_string_pretty(&meta).unwrap_or_default() + "\n";
    schemas::atomic::write_file(&path, text)?;
    Ok(Written { tables, rows, metadata: path })
}

/// `(column, unit)` of the wide table's columns that have a unit.
#[cfg(feature = "tables")]
fn wide_units(t: &TopicFrame) -> Vec<(String, &'static str)> {
    t.columns.iter().filter_map(|c| Some((c.name.clone(), c.unit?))).collect()
}

#[cfg(feature = "tables")]
fn unit_of(units: &[(String, &'static str)], column: &str) -> Option<&'static str> {
    units.iter().find(|(n, _)| n == column).map(|(_, u)| *u)
}

/// The CSV header: `name [unit]` where the column has a unit.
#[cfg(feature = "tables")]
pub fn csv_header(df: &DataFrame, units: &[(String, &'static str)]) -> Vec<String> {
    df.get_column_names()
        .iter()
        .map(|c| match unit_of(units, c.as_str()) {
            Some(u) => format!("{c} [{u}]"),
            None => c.to_string(),
        })
        .collect()
}

/// The Parquet field-metadata key of a column's unit.
#[cfg(feature = "tables")]
pub const PARQUET_UNIT_KEY: &str = "unit";

/// The file's key-value metadata: `ARROW:schema` (the Arrow schema polars' writer would
/// write, built the same way from the frame's dtypes, with each column's unit as field
/// metadata [`PARQUET_UNIT_KEY`]) and `units` (JSON: column → unit).
#[cfg(feature = "tables")]
fn parquet_metadata(df: &DataFrame, units: &[(String, &'static str)]) -> KeyValueMetadata {
    let schema: ArrowSchema = df
        .schema()
        .to_arrow(CompatLevel::newest())
        .into_iter()
        .map(|(name, field)| {
            let field = match unit_of(units, &name) {
                Some(u) => field.with_metadata([(PlSmallStr::from_static(PARQUET_UNIT_KEY), PlSmallStr::from_static(u))].into()),
                None => field,
            };
            (name, field)
        })
        .collect();
    let arrow = polars_parquet::write::schema_to_metadata_key(&schema);
    let json: serde_json::Map<String, serde_json::Value> = units.iter().map(|(c, u)| (c.clone(), (*u).into())).collect();
    let mut kv = vec![("units".to_string(), serde_json::Value::Object(json).to_string())];
    if let Some(value) = arrow.value {
        kv.insert(0, (arrow.key, value));
    }
    KeyValueMetadata::from_static(kv)
}
