//! The comparison report as one Markdown document (`analyze report`): what stands out first,
//! then the tables of [`crate::render`] (runs, hand error, energy totals and per link with
//! ratios to the baseline, contacts), then the energy audit (the balance term by term, and the
//! integrals checked against the samples, [`crate::integrals`]), then the figures.
//!
//! The energy balance audited (SCENE.md "Energy balance"; the paper's eqs. 9-12 and 21):
//!
//! ```text
//! Σ_j E_j = ΔT + ΔV + Δ(Σ ½ L i²) + ∫ Σ R i² dt + ∫ Σ D q'² dt + ∫ Σ D_m q'² dt + residual
//!  (electric energy in = kinetic + potential + magnetic stored + winding, joint and gear losses)
//! ```

use std::fmt::Write as _;

use std::path::Path;

use crate::integrals::{IntegralSamples, SampledIntegral, SampledIntegrals, AGREEMENT_FACTOR, AGREEMENT_FLOOR, INTEGRAL_TOPICS};
use crate::metrics::{Reductions, METRIC_TOPICS};
use crate::{Comparison, Error, RunMetrics};

/// One recording as the report needs it, read in one streamed pass: its metrics, what it says
/// about itself and its integrals, and (with `series`) what the figures draw.
#[cfg(feature = "figures")]
pub fn read_run(path: &Path, check_from: f64, series: bool) -> Result<(RunMetrics, RunInfo, Option<crate::figures::RunSeries>), Error> {
    /// Each message to every reader that wants it.
    struct Tee {
        metrics: Reductions,
        samples: IntegralSamples,
        series: Option<crate::figures::SeriesCollect>,
    }
    impl schemas::Visitor for Tee {
        fn message(&mut self, m: schemas::DecodedMessage<'_>) -> Result<(), schemas::Error> {
            if let Some(s) = self.series.as_mut().filter(|_| crate::figures::FIGURE_TOPICS.contains(&m.topic)) {
                s.message(m.clone())?;
            }
            if INTEGRAL_TOPICS.contains(&m.topic) {
                self.samples.message(m.clone())?;
            }
            if METRIC_TOPICS.contains(&m.topic) {
                self.metrics.message(m)?;
            }
            Ok(())
        }
    }
    let topics: Vec<&str> = METRIC_TOPICS.iter().chain(&INTEGRAL_TOPICS).copied().collect();
    let mut tee = Tee { metrics: Reductions::default(), samples: IntegralSamples::default(), series: series.then(Default::default) };
    let rec = schemas::stream_recording(path, Some(&topics), &mut tee).map_err(|e| tee.metrics.take_error(e))?;
    let metrics = tee.metrics.finish(&rec, None)?;
    let info = RunInfo {
        tool: rec.info().ok().and_then(|i| i.tool),
        format_version: rec.format_version(),
        integrator: rec.run().ok().and_then(|r| r.setup).map(|s| s.integrator.phrase()),
        sampled: [0.0, check_from].map(|from| tee.samples.integrals(&rec, from).map_err(|e| e.to_string())),
    };
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let series = tee.series.map(|s| s.into_series(&rec, &stem)).transpose()?;
    Ok((metrics, info, series))
}

/// What the report says about one recording beyond its metrics.
#[derive(Debug, Clone)]
pub struct RunInfo {
    /// Metadata `recording.tool`, if present.
    pub tool: Option<String>,
    /// Metadata `recording.format_version`.
    pub format_version: Option<u32>,
    /// Metadata `run.integrator` and its settings (`integrator.rtol` ...), as one phrase.
    pub integrator: Option<String>,
    /// `E_j` and `W_j` recomputed from the samples over the whole run, then from
    /// `t >= from_s` (after a start-up transient); the error when they cannot be (e.g. a
    /// recording without `/joint_states`).
    pub sampled: [Result<SampledIntegrals, String>; 2],
}

/// What the check of a run's integrals says, in one sentence, when something is worth saying.
fn sampled_finding(name: &str, s: &[Result<SampledIntegrals, String>; 2]) -> Option<String> {
    let [Ok(whole), after] = s else { return None };
    if whole.agrees() {
        return None;
    }
    let worst = whole
        .electric
        .iter()
        .zip(&whole.joints)
        .max_by(|a, b| a.0.difference_j().total_cmp(&b.0.difference_j()))
        .map(|(i, j)| format!("E of {j} off by {:.3} J of {:.3} J", i.difference_j(), i.recorded_j))
        .unwrap_or_default();
    Some(match after {
        Ok(a) if a.agrees() => format!(
            "{name}: the samples (every {} s) reproduce the energy integrals from t = {} s on, \
             within the trapezoid rule's error, but not over the whole run ({worst}): the \
             start-up transient is faster than the output step. The recorded integrals \
             (integrated with the motion) are the ones to use.",
            whole.dt_s, a.from_s
        ),
        _ => format!(
            "{name}: the energy integrals recomputed from the samples (every {} s) do **not** \
             agree with the recorded ones within the trapezoid rule's estimated error, even \
             after the start ({worst}). Either the signals change faster than the output step \
             (record at a higher rate to tell) or the recorded integrals are wrong.",
            whole.dt_s
        ),
    })
}


/// A figure to show: caption and the path of its image relative to the report.
#[derive(Debug, Clone)]
pub struct FigureLink {
    pub caption: String,
    pub path: String,
}

/// The whole document.
pub fn render_report(
    cmp: &Comparison,
    info: &[RunInfo],
    figures: &[FigureLink],
    figures_index: Option<&str>,
) -> String {
    let runs: Vec<&RunMetrics> = cmp.runs.iter().map(|r| &r.metrics).collect();
    let labels = crate::render::run_labels(&runs);
    let mut scenes: Vec<&str> = Vec::new();
    for r in &runs {
        if !scenes.contains(&r.scene.as_str()) {
            scenes.push(&r.scene);
        }
    }
    let mut out = String::new();
    let _ = writeln!(out, "# Comparison report: {}\n", scenes.join(", "));
    let _ = writeln!(
        out,
        "{} runs; baseline **{}** (ratios are run / baseline). Units SI; hand error in mm. \
         Written by `analyze report` ({} {}).\n",
        runs.len(),
        cmp.baseline,
        env!("CARGO_PKG_NAME"),
        env!("CARGO_PKG_VERSION")
    );

    out.push_str("## What stands out\n\n");
    for f in &cmp.findings {
        let _ = writeln!(out, "- {f}");
    }
    for (name, i) in labels.iter().zip(info) {
        if let Some(f) = sampled_finding(name, &i.sampled) {
            let _ = writeln!(out, "- {f}");
        }
    }
    out.push('\n');

    out.push_str("## Recordings\n\n| run | file | tool | format | integrator | samples | t_end [s] |\n");
    out.push_str("|:--|:--|:--|--:|:--|--:|--:|\n");
    for ((r, i), name) in runs.iter().zip(info).zip(&labels) {
        let dash = |s: &Option<String>| s.clone().unwrap_or_else(|| "-".into());
        let _ = writeln!(
            out,
            "| {} | `{}` | {} | {} | {} | {} | {:.3} |",
            name,
            r.file,
            dash(&i.tool),
            i.format_version.map_or("-".into(), |v| v.to_string()),
            dash(&i.integrator),
            r.samples,
            r.t_end_s
        );
    }
    out.push('\n');

    out.push_str("## Tables\n\n");
    out.push_str(&crate::render::render_comparison_markdown(cmp));
    out.push('\n');

    contacts(&mut out, &runs, &labels);
    audit(&mut out, &runs, &labels, info);

    if !figures.is_empty() {
        out.push_str("## Figures\n\n");
        if let Some(index) = figures_index {
            let _ = writeln!(out, "Every figure, with notes on how to read it: [{index}]({index}).\n");
        }
        for f in figures {
            let _ = writeln!(out, "**{}**\n\n![{}]({})\n", f.caption, f.caption, f.path);
        }
    }
    while out.ends_with("\n\n") {
        out.pop();
    }
    out
}

/// Section "Contacts": what the table did at each contact, for the runs that have contacts.
/// Bilateral contacts (the paper's) hold the point on the table with a force of either sign: the
/// time they pull (`f_n < 0`) is what a real table could not do. Unilateral (rigid, with impacts
/// and Coulomb friction, Pfeiffer & Glocker 1996) and compliant contacts only push: their time
/// in contact, events, losses and the friction they needed to stick.
fn contacts(out: &mut String, runs: &[&RunMetrics], labels: &[String]) {
    if runs.iter().all(|r| r.contacts.is_empty()) {
        return;
    }
    out.push_str(
        "## Contacts

         A bilateral contact (the paper's) holds its point on the table with a force of either          sign; where f_n < 0 the table pulls, which a real table cannot. Unilateral contacts          (rigid: impacts with restitution, Coulomb friction) and compliant ones (spring-damper)          only push; for them: the time in contact, the events, the energy lost in impacts and          to friction, and the friction coefficient each needed to stick (max |f_t|/f_n).

",
    );
    out.push_str("| run | contact | model | in contact [s] | f_n < 0 [s] | min f_n [N] | lift-offs | impacts | impact loss [J] | friction work [J] | μ to stick |\n");
    out.push_str("|:--|:--|:--|--:|--:|--:|--:|--:|--:|--:|--:|\n");
    for (r, name) in runs.iter().zip(labels) {
        for c in &r.contact_forces {
            let state = r.contact_states.iter().find(|s| s.contact == c.contact);
            let row = match state {
                Some(s) => format!(
                    "{} | {:.4} | {:.4} | {:.3} | {} | {} | {:.3e} | {:.3e} | {}",
                    s.model.as_deref().unwrap_or("-"),
                    s.time_in_contact_s,
                    c.pull_time_s,
                    c.min_normal_force_n,
                    s.events.lift_offs,
                    s.events.impacts,
                    s.impact_loss_j,
                    s.friction_work_j,
                    s.stick_friction_needed.map_or("-".into(), |x| format!("{x:.3}")),
                ),
                None => format!("bilateral | {:.4} | {:.4} | {:.3} | - | - | - | - | -", r.t_end_s, c.pull_time_s, c.min_normal_force_n),
            };
            let _ = writeln!(out, "| {name} | {} | {row} |", c.contact);
        }
    }
    out.push('\n');
}

fn audit(out: &mut String, runs: &[&RunMetrics], labels: &[String], info: &[RunInfo]) {
    out.push_str(
        "## Energy audit\n\n\
         Where the electric energy went, at the end of each run (J):\n\n\
         `Σ E_j = ΔT + ΔV + Δ(½ L i²) + R loss + D loss + D_m loss + residual`\n\n\
         electric energy in = kinetic, potential and magnetic energy stored + losses in the \
         windings (R i²), the joints' viscous friction (D q'²) and the gears' (D_m q'²). The \
         simulator integrates every term with the motion, so the residual measures its \
         integration error.\n\n",
    );
    out.push_str("| run | E in | ΔT | ΔV | Δ(½Li²) | R loss | D loss | D_m loss | residual | max \\|residual\\| / E |\n");
    out.push_str("|:--|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n");
    for (r, name) in runs.iter().zip(labels) {
        let a = &r.energy;
        let split = |x: Option<f64>| x.map_or("-".to_string(), |x| format!("{x:.4}"));
        let (d, dm) = match a.gear_friction_loss_j {
            Some(g) => (split(Some(a.friction_loss_j - g)), split(Some(g))),
            None => (format!("{:.4} (D + D_m)", a.friction_loss_j), "-".into()),
        };
        let _ = writeln!(
            out,
            "| {} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {d} | {dm} | {:.2e} | {} |",
            name,
            a.electric_j,
            a.kinetic_change_j,
            a.potential_change_j,
            a.magnetic_change_j,
            a.resistive_loss_j,
            a.residual_j,
            a.max_abs_residual_rel.map_or("-".into(), |x| format!("{x:.2e}")),
        );
    }
    out.push_str(&format!(
        "\n### The integrals checked against the samples\n\n\
         `E_j = ∫ i_j v_j dt` and `W_j = ∫ τ_j q'_j dt` recomputed from the recorded samples by the \
         trapezoid rule, against the simulator's (`/energy`), over the whole run and after the \
         start. The trapezoid rule's own error is O(h²); its estimate is Richardson's \
         `(I_h − I_2h)/3` from every second sample. They agree when every difference is within \
         {AGREEMENT_FACTOR} estimates (or {AGREEMENT_FLOOR:e} of the run's total). Largest over \
         the joints:\n\n"
    ));
    out.push_str("| run | window [s] | output step [s] | max \\|ΔE_j\\| [J] | its estimate [J] | max \\|ΔW_j\\| [J] | its estimate [J] | agree |\n");
    out.push_str("|:--|:--|--:|--:|--:|--:|--:|:--|\n");
    for ((name, i), r) in labels.iter().zip(info).zip(runs) {
        for s in &i.sampled {
            match s {
                Ok(s) => {
                    let worst = |v: &[SampledIntegral]| {
                        v.iter()
                            .zip(&s.joints)
                            .max_by(|a, b| a.0.difference_j().total_cmp(&b.0.difference_j()))
                            .map_or(("-".into(), "-".into()), |(x, j)| {
                                (format!("{:.2e} ({j})", x.difference_j()), format!("{:.2e}", x.sampling_error_j.abs()))
                            })
                    };
                    let (de, ee) = worst(&s.electric);
                    let (dw, ew) = worst(&s.work);
                    let _ = writeln!(
                        out,
                        "| {name} | {}–{:.3} | {} | {de} | {ee} | {dw} | {ew} | {} |",
                        s.from_s,
                        r.t_end_s,
                        s.dt_s,
                        if s.agrees() { "yes" } else { "**no**" }
                    );
                }
                Err(why) => {
                    let _ = writeln!(out, "| {name} | - | - | - | - | - | - | not checked: {} |", why.replace('|', "\\|"));
                }
            }
        }
    }
    out.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The section "Contacts": a bilateral run's rows give the pull time; the unilateral run's
    /// its model, time in contact (exact to its events, 0.596 s), events and friction needed.
    #[test]
    fn the_report_has_a_contacts_section() {
        let dir = tempfile::tempdir().unwrap();
        let (s, _) = schemas::synth::unilateral();
        let uni = crate::metrics::read_run_metrics(&s.write_in(dir.path())).unwrap();
        let mut runs = crate::compare::tests::paper_runs();
        runs[0].contact_forces[1].pull_time_s = 0.31;
        runs.push(uni);
        let cmp = Comparison::new(&runs, None).unwrap();
        let info: Vec<RunInfo> = runs
            .iter()
            .map(|_| RunInfo { tool: None, format_version: Some(2), integrator: None, sampled: [Err("none".into()), Err("none".into())] })
            .collect();
        let text = render_report(&cmp, &info, &[], None);
        let section = &text[text.find("## Contacts").unwrap_or_else(|| panic!("{text}"))..];
        let section = &section[..section.find("## Energy audit").unwrap()];
        assert!(section.contains("| two-elbow | elbow7 | bilateral | 5.0000 | 0.3100 |"), "{section}");
        assert!(section.contains("| unilateral | elbow4 | unilateral | 0.5960 | 0.0000 | 0.000 | 1 | 1 | 6.000e-2 | 6.000e-3 | 0.300 |"), "{section}");
        assert!(!section.contains("no-elbow"), "no contacts, no rows: {section}");
    }
}
