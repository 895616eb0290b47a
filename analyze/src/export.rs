//! `analyze export` as one call: a recording's topics as Parquet or CSV tables
//! ([`crate::frames`], feature `tables`), so that a caller needs no polars type and a build
//! without the feature says what is missing.

use std::path::Path;

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
        let files = frames::export(&mut f, dir, format)?;
        let rows = f.topics.iter().map(|(_, df)| df.height()).sum();
        Ok(Exported { tables: files.len() - 1, rows, skipped: f.skipped.len() })
    }
    #[cfg(not(feature = "tables"))]
    {
        let _ = (path, dir, format, topics);
        Err(Error::TablesUnavailable)
    }
}
