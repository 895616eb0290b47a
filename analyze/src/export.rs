//! `analyze export` as one call: a recording's topics ([`crate::frames`], feature `tables`) as
//! Parquet or CSV tables and `metadata.json`, so that a caller needs no polars type and a build
//! without the feature says what is missing. Every file goes through a temporary name and a
//! rename, so a killed export never leaves a half-written table under its final name.

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
        })
        .map_err(|e| e.into_error(&path))?;
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
    write_atomic(&path, |f| {
        use std::io::Write;
        f.write_all(text.as_bytes()).map_err(PolarsError::from)
    })
    .map_err(|e| e.into_error(&path))?;
    written.push(path);
    Ok(written)
}

#[cfg(feature = "tables")]
enum WriteError {
    Io(std::io::Error),
    Polars(PolarsError),
}

#[cfg(feature = "tables")]
impl WriteError {
    /// The library's error, naming the file being written.
    fn into_error(self, path: &Path) -> Error {
        let file = path.display().to_string();
        match self {
            WriteError::Io(source) => Error::Io { file, op: "writing", source },
            WriteError::Polars(e) => Error::Table { file, detail: format!("writing the table: {e}") },
        }
    }
}

/// Writes through `.NAME.partial` in the same directory, then renames over `path`.
#[cfg(feature = "tables")]
fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut std::fs::File) -> PolarsResult<()>,
) -> Result<(), WriteError> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.partial"));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp).map_err(WriteError::Io)?;
        write(&mut f).map_err(WriteError::Polars)?;
        f.sync_all().map_err(WriteError::Io)?;
        std::fs::rename(&tmp, path).map_err(WriteError::Io)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
