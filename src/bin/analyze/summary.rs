//! `analyze summary`: many recordings, one polars table (`analyze::summary`).

use analyze::summary::{self, Query};
use analyze::Format;
use anyhow::{bail, Result};
use cli::{exit, print_out, Jobs, TableFormat, Verbosity};

/// One table of many runs (hundreds of recordings, read in parallel): one row per recording
/// with its hand error, energy totals, per-link E_j and W_j, peak current, contact forces,
/// energy residual and chosen scene parameters; filter, sort and pick columns (polars). Merges
/// the shards of a sweep.
#[derive(Debug, clap::Args)]
#[command(after_help = SUMMARY_HELP)]
pub struct SummaryArgs {
    /// Recordings (.mcap), directories (every *.mcap directly in them) or glob patterns
    /// (quote them: 'results/**/*.mcap'); sorted by path, duplicates removed.
    #[arg(required = true, value_name = "FILES_DIRS_OR_GLOBS")]
    pub inputs: Vec<String>,
    /// Add the scene parameter at this path of the scene JSON stored in each recording as a
    /// column `p.<PATH>`: a dot path (controller.kp, contacts.0.plane.offset) or a JSON pointer
    /// (/controller/kp); repeatable. A path that no recording has is an error.
    #[arg(long = "param", value_name = "PATH")]
    pub params: Vec<String>,
    /// Keep rows where COLUMN OP VALUE holds, OP one of = != < <= > >= (numbers compare as
    /// numbers); repeatable, all must hold. E.g. 'err_z_rms_m<0.02', run=two-elbow.
    #[arg(long = "filter", value_name = "COND", value_parser = parse_filter)]
    pub filters: Vec<analyze::filter::Filter>,
    /// Sort by these columns (comma-separated), ascending unless --desc [default: by file].
    #[arg(long, value_name = "COLUMNS", value_delimiter = ',')]
    pub sort: Vec<String>,
    /// Sort descending.
    #[arg(long)]
    pub desc: bool,
    /// Show only these columns, in this order (comma-separated) [default: all for json and
    /// csv; a readable subset for the table].
    #[arg(long, value_name = "COLUMNS", value_delimiter = ',')]
    pub columns: Vec<String>,
    /// Show at most N rows (after filtering and sorting).
    #[arg(long, value_name = "N")]
    pub limit: Option<usize>,
    #[command(flatten)]
    pub jobs: Jobs,
    /// Leave out recordings that cannot be read (each is named on stderr) instead of stopping
    /// at the first; the exit status is then 1 if any was left out.
    #[arg(long)]
    pub skip_bad: bool,
    #[command(flatten)]
    pub format: TableFormat,
}

const SUMMARY_HELP: &str = "\
Output: one row per recording. Columns (SI units, the unit as a lower-case suffix): file scene
run status contacts n_contacts integrator t_end_s samples err_norm_rms_m err_norm_max_m
err_z_rms_m err_z_max_m E_total_j W_total_j peak_current_a peak_current_joint fn_min_n
pull_max_s residual_max_rel error bytes, E.<joint>_j and W.<joint>_j per link; per contact
with a contact model (unilateral or compliant: the recording has /contacts) in_contact.<c>_s
lift_offs.<c> impacts.<c> impact_loss.<c>_j friction_work.<c>_j damping_loss.<c>_j
mu_stick.<c>_ratio; p.<path> per --param. The table shows a readable subset unless --columns is given; -f json and -f csv every
column.

Examples:
  analyze summary out/                                every out/*.mcap
  analyze summary 'out/**/*.mcap' -j 8                a quoted glob, 8 reader threads
  analyze summary out/ --param controller.kp --param controller.kd --sort E_total_j
  analyze summary out/ --filter 'err_z_rms_m<0.02' --filter run=two-elbow --sort E_total_j --desc
  analyze summary out/ --columns file,run,E_total_j,err_z_rms_m --limit 10
  analyze summary out/ -f csv > runs.csv              every column (per link too)";

fn parse_filter(s: &str) -> Result<analyze::filter::Filter, String> {
    s.parse()
}

/// `analyze summary`.
pub fn run(a: &SummaryArgs, v: Verbosity) -> Result<u8> {
    let paths = cli::inputs::expand_patterns(&a.inputs)?;
    let bar = cli::progress::count(paths.len(), "reading", "recordings", v.quiet || paths.len() < 8);
    let results = summary::read_rows(&paths, &a.params, a.jobs.threads(paths.len()), &|| bar.inc(1));
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
    for (k, p) in a.params.iter().enumerate() {
        if !rows.is_empty() && rows.iter().all(|r| r.params[k].is_none()) {
            bail!(
                "--param {p}: no recording's scene has this path (JSON pointer {}); the scene JSON is in each recording (`sim check -f json` describes a scene)",
                summary::json_pointer(p)
            );
        }
    }
    let columns = if a.columns.is_empty() && a.format.format == Format::Table {
        let mut c: Vec<String> = summary::DEFAULT_TABLE_COLUMNS.iter().map(|s| s.to_string()).collect();
        c.extend(a.params.iter().map(|p| format!("p.{p}")));
        c
    } else {
        a.columns.clone()
    };
    let query = Query { filters: a.filters.clone(), sort: a.sort.clone(), descending: a.desc, columns, limit: a.limit };
    let mut text = summary::render(&rows, &a.params, &query, a.format.format)?;
    // runs over different intervals: their totals are not comparable, and sorting ranks them
    // anyway; say so (in the table's text, else on stderr: JSON and CSV stay data)
    if let Some(note) = summary::duration_note(&rows) {
        match a.format.format {
            Format::Table => text = format!("{text}\n{}", analyze::render::wrap(&note, cli::TEXT_WIDTH, "", "")),
            _ => eprintln!("analyze: {note}"),
        }
    }
    print_out(&text)?;
    let metrics: Vec<analyze::RunMetrics> = rows.into_iter().map(|r| r.metrics).collect();
    let code = crate::compare::status(&metrics, false, v);
    if bad > 0 {
        eprintln!("analyze: {bad} of {} recordings could not be read (named above) and are left out", paths.len());
        return Ok(exit::FAILED);
    }
    Ok(code)
}

