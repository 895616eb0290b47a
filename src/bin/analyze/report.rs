//! `analyze report`: each recording read once, for the metrics, the sampled-integral check and
//! the figures; then the comparison, the figures and `report.md`.

use std::path::PathBuf;

use analyze::report::{render_report, FigureLink};
use analyze::Comparison;
use anyhow::{Context, Result};
use cli::Verbosity;

/// The comparison report as one Markdown document: what stands out, the tables (hand error,
/// energy totals and per link with ratios to the baseline, contacts), a contacts section (pull
/// time of bilateral contacts; time in contact, events, losses of unilateral ones), the energy audit
/// (electric energy in; kinetic, potential, magnetic stored; R, D and D_m losses; residual; the
/// integrals rechecked from the samples) and the figures.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Output: DIR/report.md and DIR/figures/ (every figure as SVG and PNG, with index.md).

Examples:
  analyze report out/                           -> out/report/report.md
  analyze report out/ --baseline one-elbow -o review
  analyze report out/paper-no-elbow.mcap out/paper-two-elbow.mcap --no-figures -o r")]
pub struct ReportArgs {
    /// Recordings (.mcap), or directories: every *.mcap directly in them, sorted by name.
    #[arg(required = true, value_name = "FILES_OR_DIRS")]
    pub inputs: Vec<PathBuf>,
    /// The baseline run, by run name, file path or file stem [default: the first run without
    /// contacts, else the first run].
    #[arg(long, value_name = "RUN")]
    pub baseline: Option<String>,
    /// Directory for report.md and its figures/ (created if needed).
    #[arg(short = 'o', long = "out", value_name = "DIR", default_value = "out/report")]
    pub out: PathBuf,
    /// Leave out the figures (faster; the report then has tables only).
    #[arg(long)]
    pub no_figures: bool,
    /// The energy integrals are rechecked from the samples over the whole run and from this
    /// time on, s (after the start-up transient, which is faster than the output step).
    #[arg(long, value_name = "SECONDS", default_value_t = 0.05)]
    pub check_from: f64,
}

pub fn run(a: &ReportArgs, v: Verbosity) -> Result<u8> {
    let paths = cli::inputs::expand(&a.inputs)?;
    let mut metrics = Vec::new();
    let mut info = Vec::new();
    let mut series = Vec::new();
    for p in &paths {
        if v.verbose > 0 {
            eprintln!("analyze: reading {}", p.display());
        }
        // one streamed pass: the metrics, the integrals' check and the figures' series
        let (m, i, s) = analyze::report::read_run(p, a.check_from, !a.no_figures).with_context(|| format!("reporting on {}", p.display()))?;
        metrics.push(m);
        info.push(i);
        series.extend(s);
    }
    let cmp = Comparison::new(&metrics, a.baseline.as_deref())?;
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let mut links = Vec::new();
    if !a.no_figures {
        let dir = a.out.join("figures");
        let figures = analyze::figures::write_all(&series, &paths, &dir)?;
        // in the report: the hand paths, the totals and the signals beyond the paper; the
        // per-link figures 6-25 are on the index page
        for f in figures.iter().filter(|f| f.number.is_none_or(|n| n <= 5)) {
            links.push(FigureLink {
                caption: analyze::figures::markup::html(&f.caption),
                alt: analyze::figures::markup::plain(&f.caption),
                path: format!("figures/{}.png", f.stem),
            });
        }
    }
    let index = (!a.no_figures).then_some("figures/index.md");
    let text = render_report(&cmp, &info, &links, index);
    let path = a.out.join("report.md");
    cli::write_file(&path, &text)?;
    if !v.quiet {
        eprintln!("analyze: report of {} runs in {}", metrics.len(), path.display());
    }
    Ok(crate::compare::status(&metrics, false, v))
}
