//! `analyze export` as one call: a recording's topics ([`crate::frames`], feature `tables`) as
//! Parquet or CSV tables and `metadata.json`, so that a caller needs no polars type and a build
//! without the feature says what is missing. Every file goes through `schemas::atomic` (a lock on
//! the final name, a temporary name of its own, a rename), so neither a killed export nor a
//! second one at the same time ever leaves a half-written table under its final name.

use std::path::Path;
#[cfg(feature = "tables")]
use std::path::PathBuf;

#[cfg(feature = "tables")]
use polars::prelude::*;

#[cfg(feature = "tables")]
use crate::frames::RecordingFrames;
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

/// What [`export_file`] wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Exported {
    /// Topic tables written (besides `metadata.json`).
    pub tables: usize,
    /// Rows over all tables.
    pub rows: usize,
    /// Topics not decoded (their reasons are in `metadata.json`).
    pub skipped: usize,
}

/// Writes the topics of the recording at `path` (all, or `topics`) into `dir`. A topic asked
/// for that the recording does not have (with messages) is an error naming it.
pub fn export_file(path: &Path, dir: &Path, format: ExportFormat, topics: &[&str]) -> Result<Exported, Error> {
    #[cfg(feature = "tables")]
    {
        use crate::frames;
        let file = || path.display().to_string();
        let mut f = frames::read_frames(path, (!topics.is_empty()).then_some(topics))?;
        for t in topics {
            if f.get(t).is_none() {
                let why = f.skipped.iter().find(|(s, _)| s == t).map(|(_, w)| w.clone());
                let why = why.filter(|w| w != schemas::NOT_SELECTED).unwrap_or_else(|| {
                    let have: Vec<&str> = f.skipped.iter().map(|(s, _)| s.as_str()).collect();
                    format!("no such topic with messages (the recording has: {})", have.join(", "))
                });
                return Err(Error::Table { file: file(), detail: format!("topic {t}: {why}") });
            }
        }
        let files = write_tables(&mut f, dir, format)?;
        let rows = f.topics.iter().map(|(_, df)| df.height()).sum();
        Ok(Exported { tables: files.len() - 1, rows, skipped: f.skipped.len() })
    }
    #[cfg(not(feature = "tables"))]
    {
        let _ = (path, dir, format, topics);
        Err(Error::TablesUnavailable)
    }
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
fn file_names(frames: &RecordingFrames, format: ExportFormat) -> Vec<String> {
    let mut used = std::collections::BTreeSet::new();
    frames
        .topics
        .iter()
        .map(|(t, _)| {
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

/// Writes one file per topic into `dir` (created if needed) plus `metadata.json` (the
/// metadata records, and the topics skipped with the reason); returns the files written.
#[cfg(feature = "tables")]
pub fn write_tables(frames: &mut RecordingFrames, dir: &Path, format: ExportFormat) -> Result<Vec<PathBuf>, Error> {
    std::fs::create_dir_all(dir).map_err(|source| Error::Io {
        file: dir.display().to_string(),
        op: "creating",
        source,
    })?;
    let mut written = Vec::new();
    let files = file_names(frames, format);
    for ((_, df), name) in frames.topics.iter_mut().zip(&files) {
        let path = dir.join(name);
        write_atomic(&path, |f| match format {
            ExportFormat::Parquet => ParquetWriter::new(f).finish(df).map(drop),
            ExportFormat::Csv => CsvWriter::new(f).include_header(true).finish(df),
        })?;
        written.push(path);
    }
    let meta = serde_json::json!({
        "source": frames.source,
        "metadata": frames.metadata,
        "topics": frames.topics.iter().zip(&files).map(|((t, df), file)| serde_json::json!({
            "topic": t,
            "file": file,
            "rows": df.height(),
            "columns": df.get_column_names().iter().map(|c| c.as_str()).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
        "skipped": frames.skipped.iter().map(|(t, why)| serde_json::json!({"topic": t, "reason": why})).collect::<Vec<_>>(),
    });
    let path = dir.join("metadata.json");
    let text = serde_json::to_string_pretty(&meta).unwrap_or_default() + "\n";
    schemas::atomic::write_file(&path, text)?;
    written.push(path);
    Ok(written)
}

/// Writes `path` with `write` atomically and exclusively (`schemas::atomic`); errors name the
/// file.
#[cfg(feature = "tables")]
fn write_atomic(path: &Path, write: impl FnOnce(&mut std::fs::File) -> PolarsResult<()>) -> Result<(), Error> {
    schemas::atomic::write_with(path, |f| {
        write(f).map_err(|e| Error::Table { file: path.display().to_string(), detail: format!("writing the table: {e}") })
    })?;
    Ok(())
}
