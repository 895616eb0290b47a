//! The comparison report as one Markdown document (`analyze report`): the findings that matter
//! physically first, one sentence each ([`Comparison::headline`]: a table that pulls before
//! anything else), then the details (the comparison's findings, sentences that differ only in
//! the run they name merged into one), then the tables of [`crate::render`] (runs, hand error, energy totals and per link with
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
        fn metadata(&mut self, name: &str, entries: &std::collections::BTreeMap<String, String>) {
            self.metrics.metadata(name, entries);
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
    // a run that failed before its first sample has nothing to draw
    let series = tee.series.filter(|_| metrics.measured()).map(|s| s.into_series(&rec, &stem)).transpose()?;
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

/// What the check of the runs' integrals says, one sentence per kind of result, when something
/// is worth saying: the runs whose samples reproduce the integrals only after the start-up
/// transient in one sentence (the largest difference named), those that do not at all in
/// another.
fn sampled_findings(labels: &[String], info: &[RunInfo]) -> Vec<String> {
    // (run, worst joint's difference J, its text) of the runs in each kind
    let (mut transient, mut wrong) = (Vec::new(), Vec::new());
    let mut dt = None;
    let mut from = None;
    for (name, i) in labels.iter().zip(info) {
        let [Ok(whole), after] = &i.sampled else { continue };
        if whole.agrees() {
            continue;
        }
        dt = Some(whole.dt_s);
        let worst = whole
            .electric
            .iter()
            .zip(&whole.joints)
            .max_by(|a, b| a.0.difference_j().total_cmp(&b.0.difference_j()))
            .map(|(i, j)| (i.difference_j(), format!("E of {j} off by {} J of {} J in {name}", crate::compare::num(i.difference_j()), crate::compare::num(i.recorded_j))))
            .unwrap_or((0.0, String::new()));
        match after {
            Ok(a) if a.agrees() => {
                from = Some(a.from_s);
                transient.push((name.as_str(), worst));
            }
            _ => wrong.push((name.as_str(), worst)),
        }
    }
    let names = |v: &[(&str, (f64, String))]| v.iter().map(|x| x.0).collect::<Vec<_>>().join(", ");
    let largest = |v: &[(&str, (f64, String))]| v.iter().max_by(|a, b| a.1 .0.total_cmp(&b.1 .0)).map(|x| x.1 .1.clone()).unwrap_or_default();
    let dt = dt.map_or(String::new(), |d| format!(" (every {d} s)"));
    let mut out = Vec::new();
    if !transient.is_empty() {
        out.push(format!(
            "{}: the samples{dt} reproduce the energy integrals from t = {} s on, within the \
             trapezoid rule's error, but not over the whole run (largest: {}): the start-up \
             transient is faster than the output step. The recorded integrals (integrated with \
             the motion) are the ones to use.",
            names(&transient),
            from.unwrap_or(0.0),
            largest(&transient)
        ));
    }
    if !wrong.is_empty() {
        out.push(format!(
            "{}: the energy integrals recomputed from the samples{dt} do **not** agree with the \
             recorded ones within the trapezoid rule's estimated error, even after the start \
             (largest: {}). Either the signals change faster than the output step (record at a \
             higher rate to tell) or the recorded integrals are wrong.",
            names(&wrong),
            largest(&wrong)
        ));
    }
    out
}

/// `findings` with the sentences that differ only in the one run they name merged into one
/// naming every such run ("a, b and c: every normal force stays >= 0 ..."), in the order of
/// their first appearance.
fn merge_by_run(findings: &[String], runs: &[String]) -> Vec<String> {
    // longest names first, so "two-elbow" does not match inside "two-elbow-unilateral"
    let mut names: Vec<&str> = runs.iter().map(String::as_str).collect();
    names.sort_by_key(|n| std::cmp::Reverse(n.len()));
    let boundary = |c: Option<char>| c.is_none_or(|c| !(c.is_alphanumeric() || c == '-' || c == '_'));
    let template = |f: &str| -> Option<(String, String)> {
        let mut found: Option<(usize, &str)> = None;
        let mut masked = f.to_string();
        for n in &names {
            let mut at = 0;
            while let Some(k) = masked[at..].find(n).map(|k| k + at) {
                let (before, after) = (masked[..k].chars().next_back(), masked[k + n.len()..].chars().next());
                if boundary(before) && boundary(after) {
                    if found.is_some_and(|(_, m)| m != *n) {
                        return None; // two runs named: not merged
                    }
                    found = Some((k, n));
                    masked.replace_range(k..k + n.len(), "\u{0}");
                    at = k + 1;
                } else {
                    at = k + n.len();
                }
            }
        }
        found.map(|(_, n)| (masked, n.to_string()))
    };
    let mut groups: Vec<(Option<String>, Vec<String>, String)> = Vec::new();
    for f in findings {
        match template(f) {
            Some((t, run)) => match groups.iter_mut().find(|g| g.0.as_deref() == Some(t.as_str())) {
                Some(g) => g.1.push(run),
                None => groups.push((Some(t), vec![run], f.clone())),
            },
            None => groups.push((None, Vec::new(), f.clone())),
        }
    }
    groups
        .into_iter()
        .map(|(t, runs, original)| match (t, runs.len()) {
            (Some(t), n) if n > 1 => {
                let joined = format!("{} and {}", runs[..n - 1].join(", "), runs[n - 1]);
                t.replace('\u{0}', &joined)
            }
            _ => original,
        })
        .collect()
}

/// A figure to show: caption and the path of its image relative to the report.
#[derive(Debug, Clone)]
pub struct FigureLink {
    /// Markdown (inline HTML for sub/superscripts).
    pub caption: String,
    /// The caption as plain text, for the image's alternative text.
    pub alt: String,
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

    out.push_str("## Findings\n\n");
    for f in cmp.headline() {
        let _ = writeln!(out, "- {f}");
    }
    out.push_str("\n## Details\n\n");
    let names: Vec<String> = runs.iter().map(|r| r.run.clone()).collect();
    for f in merge_by_run(&cmp.findings, &names) {
        let _ = writeln!(out, "- {f}");
    }
    for f in sampled_findings(&labels, info) {
        let _ = writeln!(out, "- {f}");
    }
    out.push('\n');

    out.push_str("## Recordings\n\n| run | file | tool | format | integrator | samples | t_end [s] |\n");
    out.push_str("|:--|:--|:--|--:|:--|--:|--:|\n");
    for ((r, i), name) in runs.iter().zip(info).zip(&labels) {
        let dash = |s: &Option<String>| s.clone().unwrap_or_else(|| "-".into());
        let _ = writeln!(
            out,
            "| {} | `{}` | {} | {} | {} | {} | {} |",
            name,
            r.file,
            dash(&i.tool),
            i.format_version.map_or("-".into(), |v| v.to_string()),
            dash(&i.integrator),
            r.samples,
            r.t_end_s.map_or("—".into(), |t| format!("{t:.3}"))
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
            let _ = writeln!(out, "**{}**\n\n![{}]({})\n", f.caption, f.alt, f.path);
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
                None => format!("bilateral | {:.4} | {:.4} | {:.3} | - | - | - | - | -", r.t_end_s.unwrap_or_default(), c.pull_time_s, c.min_normal_force_n),
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
        // a run that failed before its first sample has no balance: its row says so
        let Some(a) = &r.energy else {
            let _ = writeln!(out, "| {name} | — | — | — | — | — | — | — | — | — |");
            continue;
        };
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
                        r.t_end_s.unwrap_or_default(),
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
