//! `analyze export`: every topic of recordings as Parquet or CSV tables (`analyze::frames`).

use std::path::PathBuf;

use analyze::export::{export_file, ExportFormat};
use anyhow::{bail, Context, Result};
use cli::{exit, Verbosity};

/// Every topic of recordings as tables for Python and spreadsheets: one Parquet or CSV file per
/// topic (time column `t` in s, one column per field, arrays expanded per joint or contact
/// name) and metadata.json, in OUT/<recording name>/.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Output: DIR/<recording stem>/<topic>.parquet (or .csv) and metadata.json; a line per recording on
stderr.

Examples:
  analyze export out/paper-two-elbow.mcap -o tables/       -> tables/paper-two-elbow/*.parquet
  analyze export out/ -f csv -o tables/                    every recording, CSV
  analyze export out/paper-two-elbow.mcap --topics /motors,/energy -o t/   only these topics

In Python: pandas.read_parquet('tables/paper-two-elbow/motors.parquet')")]
pub struct ExportArgs {
    /// Recordings (.mcap), or directories: every *.mcap directly in them, sorted by name.
    #[arg(required = true, value_name = "FILES_OR_DIRS")]
    pub inputs: Vec<PathBuf>,
    /// Output directory; each recording goes to DIR/<its file stem>/.
    #[arg(short = 'o', long = "out", value_name = "DIR", default_value = "out/tables")]
    pub out: PathBuf,
    /// File format of the tables.
    #[arg(short = 'f', long = "format", value_name = "FORMAT", value_enum, default_value = "parquet")]
    pub format: TableFile,
    /// Only these topics (comma-separated, e.g. /motors,/energy) [default: every decoded topic].
    #[arg(long, value_name = "TOPICS", value_delimiter = ',')]
    pub topics: Vec<String>,
}

/// File format of `analyze export`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TableFile {
    Parquet,
    Csv,
}

/// `analyze export`.
pub fn run(a: &ExportArgs, v: Verbosity) -> Result<u8> {
    let paths = cli::inputs::expand(&a.inputs)?;
    let format = match a.format {
        TableFile::Parquet => ExportFormat::Parquet,
        TableFile::Csv => ExportFormat::Csv,
    };
    let topics: Vec<&str> = a.topics.iter().map(String::as_str).collect();
    let stem = |p: &PathBuf| p.file_stem().map_or_else(|| "recording".into(), |s| s.to_string_lossy().into_owned());
    // every output directory is distinct before anything is written
    let mut stems = std::collections::BTreeMap::new();
    for path in &paths {
        if let Some(first) = stems.insert(stem(path), path) {
            bail!(
                "{} and {} would both export to {}: export them to different directories",
                first.display(),
                path.display(),
                a.out.join(stem(path)).display()
            );
        }
    }
    for path in &paths {
        let dir = a.out.join(stem(path));
        let e = export_file(path, &dir, format, &topics).with_context(|| format!("exporting {}", path.display()))?;
        if !v.quiet {
            let skipped = if e.skipped == 0 { String::new() } else { format!(", {} topics not decoded: see metadata.json", e.skipped) };
            eprintln!("analyze: {} -> {} ({} tables, {} rows{skipped})", path.display(), dir.display(), e.tables, e.rows);
        }
    }
    Ok(exit::SUCCESS)
}
