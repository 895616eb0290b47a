//! `analyze summary` and `analyze export`: the commands built on polars.

use std::path::PathBuf;

use analyze::frames::{self, ExportFormat};
use analyze::summary::{self, Query};
use analyze::Format;
use anyhow::{bail, Context, Result};

use super::{emit, expand_inputs};
use crate::cli::{ExportArgs, SummaryArgs};

/// Files as given, directories as their `*.mcap` files, glob patterns (`*`, `?`, `[`) as the
/// files they match; sorted by path, each once. A pattern that matches nothing is an error.
pub fn expand_patterns(inputs: &[String]) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for input in inputs {
        if input.contains(['*', '?', '[']) && !std::path::Path::new(input).exists() {
            let mut found = Vec::new();
            for entry in glob::glob(input).with_context(|| format!("glob pattern {input:?}"))? {
                let path = entry.with_context(|| format!("listing the matches of {input:?}"))?;
                if path.is_file() {
                    found.push(path);
                }
            }
            if found.is_empty() {
                bail!("{input:?}: the pattern matches no files");
            }
            out.extend(found);
        } else {
            out.extend(expand_inputs(&[PathBuf::from(input)])?);
        }
    }
    out.sort();
    out.dedup();
    Ok(out)
}

/// A progress bar on stderr when there is enough to wait for (hidden when not a terminal).
fn progress(len: usize, what: &str) -> indicatif::ProgressBar {
    if len < 8 {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(len as u64);
    let style = indicatif::ProgressStyle::with_template(
        "{prefix} [{elapsed_precise}] {wide_bar} {pos}/{len} ({per_sec}, eta {eta})",
    )
    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
    bar.set_style(style);
    bar.set_prefix(what.to_string());
    bar
}

/// `analyze summary`.
pub fn summary(a: &SummaryArgs) -> Result<()> {
    let paths = expand_patterns(&a.inputs)?;
    let bar = progress(paths.len(), "reading");
    let results = summary::read_rows(&paths, &a.params, a.jobs, &|| bar.inc(1));
    bar.finish_and_clear();
    let mut rows = Vec::with_capacity(results.len());
    let mut bad = 0;
    for (path, r) in paths.iter().zip(results) {
        match r {
            Ok(row) => rows.push(row),
            Err(e) if a.skip_bad => {
                bad += 1;
                eprintln!("analyze: skipped {}: {e}", path.display());
            }
            Err(e) => {
                return Err(anyhow::Error::new(e)
                    .context(format!("analyzing {} (--skip-bad leaves such files out)", path.display())))
            }
        }
    }
    let df = summary::summary_frame(&rows, &a.params).context("building the summary table")?;
    let columns = if a.columns.is_empty() && a.output.format == Format::Table {
        let mut c: Vec<String> = summary::DEFAULT_TABLE_COLUMNS.iter().map(|s| s.to_string()).collect();
        c.extend(a.params.iter().map(|p| format!("p.{p}")));
        c
    } else {
        a.columns.clone()
    };
    let query = Query {
        filters: a.filters.clone(),
        sort: a.sort.clone(),
        descending: a.desc,
        columns,
        limit: a.limit,
    };
    let mut out = query.run(df).map_err(|e| anyhow::anyhow!("summary: {e}"))?;
    emit(&a.output, &summary::render_frame(&mut out, a.output.format).context("rendering the summary")?)?;
    if bad > 0 {
        bail!("{bad} of {} recordings could not be read (named above)", paths.len());
    }
    Ok(())
}

/// `analyze export`.
pub fn export(a: &ExportArgs) -> Result<()> {
    let paths = expand_inputs(&a.inputs)?;
    let format = match a.format {
        crate::cli::ExportFormat::Parquet => ExportFormat::Parquet,
        crate::cli::ExportFormat::Csv => ExportFormat::Csv,
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
                a.output.join(stem(path)).display()
            );
        }
    }
    for path in &paths {
        let stem = stem(path);
        let mut f = frames::read_frames(path, (!topics.is_empty()).then_some(&topics[..]))
            .with_context(|| format!("exporting {}", path.display()))?;
        for t in &topics {
            if f.get(t).is_none() {
                let why = f.skipped.iter().find(|(s, _)| s == t).map(|(_, w)| w.clone());
                let why = why.filter(|w| w != schemas::NOT_SELECTED).unwrap_or_else(|| {
                    let have: Vec<&str> = f.skipped.iter().map(|(s, _)| s.as_str()).collect();
                    format!("no such topic with messages (the recording has: {})", have.join(", "))
                });
                bail!("{}: topic {t}: {why}", path.display());
            }
        }
        let dir = a.output.join(&stem);
        let files = frames::export(&mut f, &dir, format)?;
        let rows: usize = f.topics.iter().map(|(_, df)| df.height()).sum();
        eprintln!(
            "analyze: {} -> {} ({} tables, {rows} rows{})",
            path.display(),
            dir.display(),
            files.len() - 1,
            if f.skipped.is_empty() { String::new() } else { format!(", {} topics not decoded: see metadata.json", f.skipped.len()) }
        );
    }
    Ok(())
}
