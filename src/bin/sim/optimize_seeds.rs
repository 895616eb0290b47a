//! `sim optimize --seeds N`'s summary: every combination's best design (at the evaluations'
//! tolerance) per seed, the best over the seeds and their spread (max − min), against the
//! tolerance's error bar (`seeds.md`, printed, and `seeds.csv`); each seed's study is
//! `optimize.rs`'s.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;
use cli::{exit, print_out, Verbosity};
use sim::study::state::{Evaluation, State};
use sim::study::Study;

/// The spread over seeds: every combination's best design (at the evaluations' tolerance) per
/// seed, the best over the seeds and their spread, against the tolerance's error bar.
pub fn summary(study: &Study, runs: &[(u64, State)], out: &Path, v: Verbosity) -> Result<u8> {
    let cols = study.columns();
    let name = &study.spec.name;
    let mut md = String::new();
    let mut csv = csv::Writer::from_writer(Vec::new());
    csv.write_record(["combination", "seed", "objective_j"].into_iter().map(String::from).chain(cols.iter().cloned()))?;
    writeln!(md, "# Study `{name}` over {} seeds\n", runs.len())?;
    writeln!(md, "Seeds {}: each a whole study in `seed-<s>/` (its report there). Objectives at the evaluations' tolerance.\n", runs.iter().map(|(s, _)| s.to_string()).collect::<Vec<_>>().join(", "))?;
    writeln!(md, "| combination | best over the seeds [J] | seed | {} | spread (max − min) [J] | per seed [J] |", cols.join(" | "))?;
    writeln!(md, "|---|---|---|{}---|---|", "---|".repeat(cols.len()))?;
    let mut widest = 0.0f64;
    for k in 0..study.settings.combos {
        let mut per: Vec<(u64, &Evaluation)> = Vec::new();
        for (seed, state) in runs {
            let best = state.evaluations.iter().filter(|e| e.point.combo == k && e.objective.is_some()).min_by(|a, b| a.told().total_cmp(&b.told()).then(a.index.cmp(&b.index)));
            if let Some(e) = best {
                csv.write_record([k.to_string(), seed.to_string(), format!("{:e}", e.told())].into_iter().chain(study.cells(&e.point)))?;
                per.push((*seed, e));
            }
        }
        let label = format!("{k}: {}", study.combo_label(k));
        let Some(&(seed, best)) = per.iter().min_by(|a, b| a.1.told().total_cmp(&b.1.told())) else {
            writeln!(md, "| {label} | none feasible | - | {} | - | - |", vec!["-"; cols.len()].join(" | "))?;
            continue;
        };
        let worst = per.iter().map(|(_, e)| e.told()).fold(f64::NEG_INFINITY, f64::max);
        let spread = worst - best.told();
        widest = widest.max(spread);
        let each = per.iter().map(|(s, e)| format!("{s}: {:.4}", e.told())).collect::<Vec<_>>().join("; ");
        writeln!(md, "| {label} | {:.4} | {seed} | {} | {spread:.2e} | {each} |", best.told(), study.cells(&best.point).join(" | "))?;
    }
    if let Some(c) = runs.first().and_then(|(_, s)| s.calibration.as_ref()) {
        writeln!(
            md,
            "\nThe widest spread over the seeds, {widest:.2e} J, is {:.1} × the tolerance's error bar (±{:.2e} J): the optimum is known to {}.",
            widest / c.error_j,
            c.error_j,
            if widest > c.error_j { "the spread over the seeds (the search's resolution), not to the error bar" } else { "within the error bar: every seed found the same optimum" }
        )?;
    }
    cli::write_file(&out.join("seeds.csv"), String::from_utf8(csv.into_inner()?)?)?;
    cli::write_file(&out.join("seeds.md"), &md)?;
    if !v.quiet {
        print_out(&md)?;
    }
    Ok(exit::SUCCESS)
}
