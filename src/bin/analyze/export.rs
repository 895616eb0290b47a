//! `analyze export`: the topics of recordings as Parquet or CSV tables, wide or long, with
//! their units (`analyze::frames`, `analyze::export`).

use std::path::PathBuf;

use analyze::export::{export_file, ExportFormat, ExportOptions, Layout};
use anyhow::{bail, Context, Result};
use cli::{exit, Verbosity};

/// The topics of recordings as tables for Python and spreadsheets: one Parquet or CSV file per
/// topic (one time column `time` in s; one column per field, arrays expanded per joint or
/// contact name; or, with --layout long, one row per sample and signal) with each column's unit,
/// and metadata.json (the recording's metadata, typed), in OUT/<recording name>/.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Output: DIR/<recording stem>/<topic>.parquet (or .csv) and metadata.json; a line per recording on
stderr. Units: Parquet field metadata `unit`; CSV headers `name [unit]` (`current.joint4 [A]`);
long layout: a `unit` column. Left out unless asked for (--include or --topics): the viewers'
layout topics (/tf, /hand_points, /scene, /contact_markers: any foxglove.* schema).

Examples:
  analyze export out/paper-two-elbow.mcap -o tables/       -> tables/paper-two-elbow/*.parquet
  analyze export out/ -f csv -o tables/                    every recording, CSV
  analyze export out/paper-two-elbow.mcap --layout long    time, topic, signal, name, unit, value
  analyze export out/paper-two-elbow.mcap --topics /motors,/energy -o t/   only these topics
  analyze export out/paper-two-elbow.mcap --include tf,hand_points         the transforms too

In Python:
  import pandas, pyarrow.parquet as pq
  m = pandas.read_parquet('tables/paper-two-elbow/motors.parquet')
  unit = pq.read_schema('tables/paper-two-elbow/motors.parquet').field('current.joint4').metadata[b'unit']")]
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
    /// Only these topics (comma-separated, e.g. /motors,/energy), viewer layouts too [default:
    /// every decoded topic but the viewers' layout topics].
    #[arg(long, value_name = "TOPICS", value_delimiter = ',')]
    pub topics: Vec<String>,
    /// Also export these viewer-layout topics (comma-separated, `/` optional: tf,hand_points,
    /// scene,contact_markers, or all); those a recording does not have are ignored.
    #[arg(long, value_name = "TOPICS", value_delimiter = ',', conflicts_with = "topics")]
    pub include: Vec<String>,
    /// Table shape: wide (a row per sample, a column per signal) or long (a row per sample and
    /// signal: time, topic, signal, name, unit, value).
    #[arg(long, value_name = "LAYOUT", value_enum, default_value = "wide")]
    pub layout: TableLayout,
}

/// Table shape of `analyze export`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TableLayout {
    Wide,
    Long,
}

/// File format of `analyze export`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TableFile {
    Parquet,
    Csv,
}

/// `analyze export`.
pub fn run(a: &ExportArgs, v: Verbosity) -> Result<u8> {
    let expanded = cli::inputs::expand_all(&a.inputs)?;
    expanded.warn_skipped();
    let paths = expanded.files.clone();
    let format = match a.format {
        TableFile::Parquet => ExportFormat::Parquet,
        TableFile::Csv => ExportFormat::Csv,
    };
    let topics: Vec<&str> = a.topics.iter().map(String::as_str).collect();
    let include: Vec<&str> = a.include.iter().map(String::as_str).collect();
    let layout = match a.layout {
        TableLayout::Wide => Layout::Wide,
        TableLayout::Long => Layout::Long,
    };
    let options = ExportOptions { format, layout, topics: &topics, include: &include };
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
    // each recording on its own: one that fails is reported and the others go on (exit 1)
    let (done, failed) = cli::inputs::each_file(&paths, |path| {
        let dir = a.out.join(stem(&path.to_path_buf()));
        let e = export_file(path, &dir, &options).with_context(|| format!("exporting {}", path.display()))?;
        if !v.quiet {
            let skipped = if e.skipped == 0 { String::new() } else { format!(", {} topics not exported: see metadata.json", e.skipped) };
            eprintln!("analyze: {} -> {} ({} tables, {} rows{skipped})", path.display(), dir.display(), e.tables, e.rows);
        }
        Ok(cli::inputs::failed_run_note(path, e.result.as_ref()))
    })?;
    let (done, failed) = (done, failed);
    let mut failed_runs = 0;
    for note in done.iter().filter_map(|(_, note)| note.as_ref()) {
        eprintln!("analyze: {note} (its tables hold what it recorded)");
        failed_runs += 1;
    }
    let failed = failed + failed_runs;
    Ok(if failed > 0 || !expanded.skipped.is_empty() { exit::FAILED } else { exit::SUCCESS })
}
