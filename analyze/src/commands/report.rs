//! `analyze report`: each recording read once, for the metrics, the sampled-integral check and
//! the figures; then the comparison, the figures and `report.md`.

use analyze::report::{render_report, FigureLink, RunInfo};
use analyze::{run_metrics, Comparison};
use anyhow::{Context, Result};

use super::{expand_inputs, write_file};
use crate::cli::ReportArgs;

/// The integrator phrase of a recording: `dopri45 rtol 1e-10 atol 1e-12 h_max 1e-3`.
fn integrator(rec: &schemas::Recording) -> Option<String> {
    let run = rec.metadata.get("run")?;
    let name = run.get("integrator")?;
    let settings: Vec<String> = run
        .iter()
        .filter_map(|(k, v)| k.strip_prefix("integrator.").map(|s| format!("{s} {v}")))
        .filter(|s| !s.starts_with("max_steps"))
        .collect();
    Some(std::iter::once(name.clone()).chain(settings).collect::<Vec<_>>().join(" "))
}

pub fn report(a: &ReportArgs) -> Result<()> {
    let paths = expand_inputs(&a.inputs)?;
    let mut metrics = Vec::new();
    let mut info = Vec::new();
    let mut series = Vec::new();
    for p in &paths {
        let ctx = || format!("reporting on {}", p.display());
        let rec = schemas::read_recording(p).with_context(ctx)?;
        metrics.push(run_metrics(&rec).with_context(ctx)?);
        info.push(RunInfo {
            tool: rec.metadata_value("recording", "tool").map(String::from),
            format_version: rec.format_version(),
            integrator: integrator(&rec),
            sampled: [0.0, a.check_from].map(|from| {
                analyze::integrals::sampled_integrals_from(&rec, from).map_err(|e| e.to_string())
            }),
        });
        if !a.no_figures {
            let stem = p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
            series.push(analyze::figures::load_run(&rec, &stem).with_context(ctx)?);
        }
    }
    let cmp = Comparison::new(&metrics, a.baseline.as_deref())?;
    std::fs::create_dir_all(&a.output).with_context(|| format!("creating {}", a.output.display()))?;
    let mut links = Vec::new();
    if !a.no_figures {
        let dir = a.output.join("figures");
        let figures = analyze::figures::write_all(&series, &paths, &dir)?;
        // in the report: the hand paths, the totals and the signals beyond the paper; the
        // per-link figures 6-25 are on the index page
        for f in figures.iter().filter(|f| f.number.is_none_or(|n| n <= 5)) {
            links.push(FigureLink {
                caption: f.caption.clone(),
                path: format!("figures/{}.png", f.stem),
            });
        }
    }
    let index = (!a.no_figures).then_some("figures/index.md");
    let text = render_report(&cmp, &info, &links, index);
    let path = a.output.join("report.md");
    write_file(&path, &text)?;
    eprintln!("analyze: report of {} runs in {}", metrics.len(), path.display());
    Ok(())
}
