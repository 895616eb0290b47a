//! The brief comparison, what `sim` prints by default: the findings that matter first
//! ([`Comparison::headline`], at most [`FINDINGS`], most important first: a reader sees the
//! conclusions before the evidence, as `analyze report` opens with them), then one table with a
//! row per run: the electric energy `E_total_j`, its ratio to the baseline `E_ratio` (the saving), the
//! hand error's RMS and max of |e| (`e_rms_mm`, `e_max_mm`), and per contact what it did (a
//! bilateral table: how long it pulls and its minimum f_n; a unilateral or compliant contact:
//! how long it stays closed and its lift-offs; the contacts that never touched in one line), led
//! by the run's status when it is not a plain `complete`.
//!
//! Every number is printed by the full tables' own formats (`table.rs`), so each one is found
//! there as it is here (the test `every_number_of_the_brief_is_in_the_full_tables`).

use super::table::{f, fo, mm, q, ABSENT};
use super::text::{wrap, TextTable};
use crate::compare::Comparison;
use crate::metrics::{RunMetrics, Status};

/// The most headline findings the brief prints.
pub const FINDINGS: usize = 5;

/// The findings and the table, lines fitted to `width` columns; ends with a newline.
pub(super) fn render(cmp: &Comparison, width: usize) -> String {
    let mut out = String::new();
    let headline = cmp.headline();
    if !headline.is_empty() {
        out.push_str("Findings\n");
        for s in headline.iter().take(FINDINGS) {
            out.push_str(&wrap(s, width, "- ", "  "));
        }
        out.push('\n');
    }
    out.push_str(&wrap(
        "Runs (* = baseline): E = Σ ∫ i v dt, the electric energy at t_end; E_ratio = E / E_base; e = |r − r_d|, the \
         hand error; per contact, how long a bilateral table pulls (f_n < 0) and its minimum f_n, or how long a \
         unilateral or compliant contact stays closed and its lift-offs",
        width,
        "",
        "",
    ));
    out.push_str(&table(cmp).fitted(width));
    // the runs not compared, and why (their rows have no ratio)
    for r in cmp.runs.iter() {
        if let Some(why) = &r.not_compared {
            out.push_str(&wrap(&format!("† {}: not compared with the baseline: {why}.", r.metrics.run), width, "", "  "));
        }
    }
    out
}

/// The table of the runs (module docs).
fn table(cmp: &Comparison) -> TextTable {
    let runs: Vec<&RunMetrics> = cmp.runs.iter().map(|r| &r.metrics).collect();
    let labels = super::run_labels(&runs);
    let mut t = TextTable::new(&["run", "E_total_j", "E_ratio", "e_rms_mm", "e_max_mm", "contacts"]);
    t.notes = true;
    for (k, (r, label)) in cmp.runs.iter().zip(labels).enumerate() {
        let m = &r.metrics;
        let name = if k == cmp.baseline_index {
            format!("{label} *")
        } else if r.not_compared.is_some() {
            format!("{label} †")
        } else {
            label
        };
        let hand = |f: fn(&crate::metrics::HandError) -> f64| m.hand_error.as_ref().map_or(ABSENT.into(), |h| mm(f(h)));
        t.rows.push(vec![
            name,
            fo(m.electric_energy_total_j, 4),
            q(r.to_baseline.electric_energy),
            hand(|h| h.norm.rms_m),
            hand(|h| h.norm.max_abs_m),
            contacts(m),
        ]);
    }
    t
}

/// What the contacts of `r` did, a line per contact (module docs); `-` without contacts.
fn contacts(r: &RunMetrics) -> String {
    let mut lines = Vec::new();
    let status = r.status_text();
    if r.status != Status::Complete || status != "complete" {
        let at = r.error_time_s.map_or(String::new(), |t| format!(" at {t:.3} s"));
        lines.push(format!("{status}{at}"));
    }
    let (mut touched, mut untouched) = (0, 0);
    for name in &r.contacts {
        let force = r.contact_forces.iter().find(|c| &c.contact == name);
        let state = r.contact_states.iter().find(|c| &c.contact == name && c.model.as_deref() != Some("bilateral"));
        match (state, force) {
            (Some(s), _) => {
                let ev = &s.events;
                if s.time_in_contact_s == 0.0 && ev.touch_downs == 0 && ev.impacts == 0 && ev.rests == 0 {
                    untouched += 1;
                    continue;
                }
                touched += 1;
                let lift = if ev.lift_offs == 1 { "lift-off" } else { "lift-offs" };
                lines.push(format!("{name} closed {} s, {} {lift}", f(s.time_in_contact_s, 4), ev.lift_offs));
            }
            (None, Some(c)) if c.pull_time_s > 0.0 => {
                lines.push(format!("{name} pulls {} s, min {} N", f(c.pull_time_s, 3), f(c.min_normal_force_n, 3)));
            }
            (None, Some(c)) => lines.push(format!("{name} pushes, min {} N", f(c.min_normal_force_n, 3))),
            (None, None) => {}
        }
    }
    if untouched > 0 {
        lines.push(if touched > 0 { "others never touched" } else { "never touched" }.into());
    }
    if lines.is_empty() {
        "-".into()
    } else {
        lines.join("\n")
    }
}
