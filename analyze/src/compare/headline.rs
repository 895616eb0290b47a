//! The findings that matter physically, one sentence each, most important first
//! ([`Comparison::headline`]): what the report opens with.
//!
//! Built from the same checks as the detailed findings ([`super::claims`]: the contacts that
//! carried the arm, the per-scene verdict on the paper's claim, the bilateral → unilateral
//! pairs) and the runs' metrics, in this order:
//!
//! 0. **Runs not compared** ([`super::RunComparison::not_compared`]): a run that failed
//!    before its first sample, or covers another interval than the baseline; the sentences
//!    below are over the runs compared.
//! 1. **A table that pulls** (SCENE.md "Physics checks": f_n < 0 is a force a real table
//!    cannot apply): per bilateral run whose table pulls for at least [`LONG_PULL`] of the run,
//!    which contacts, for what share of the run and how hard; the brief pulls of the other runs
//!    (a start transient) in one sentence.
//! 2. **What a real table does**: per bilateral → unilateral pair, the time each contact stays
//!    closed and the change of electric energy and hand error; pairs with the same numbers
//!    (the same arm over another candidate set that touched at the same contacts) in one.
//! 3. **The paper's claim** per scene: the verdict with the energies and z errors in order of
//!    contacts.
//! 4. **The energy balance**: the largest residual, relative to the electric energy.
//!
//! Numbers: values of 100 and more whole, smaller ones to three significant digits, shares of
//! a run in whole per cent.

use super::{claims, Comparison, Measured};
use crate::metrics::RunMetrics;

/// A bilateral table that pulls for at least this share of the run gets its own sentence.
pub const LONG_PULL: f64 = 0.1;

/// `x` for a sentence: whole from 100 on, else three significant digits.
pub(crate) fn num(x: f64) -> String {
    if !x.is_finite() || x == 0.0 {
        return format!("{x}");
    }
    if x.abs() >= 100.0 {
        return format!("{x:.0}");
    }
    let d = (2 - x.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.d$}");
    s.replace('-', "−")
}

fn percent(part: f64, whole: f64) -> String {
    let p = 100.0 * part / whole;
    if p > 0.0 && p < 1.0 {
        "under 1 %".into()
    } else if p >= 99.5 && p < 100.0 {
        // rounding would say "100 %" of a run the table did not pull for throughout
        "over 99 %".into()
    } else {
        format!("{p:.0} %")
    }
}

fn join(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

impl Comparison {
    /// The findings that matter physically, one sentence each (module docs).
    pub fn headline(&self) -> Vec<String> {
        // first, the runs left out of the comparison and why (their numbers are not ranked)
        let mut out: Vec<String> = self
            .runs
            .iter()
            .filter_map(|r| r.not_compared.as_ref().map(|why| format!("{} is not compared with the baseline: {why}.", r.metrics.run)))
            .collect();
        let (runs, _) = self.compared();
        pulling(&runs, &mut out);
        real_table(&runs, &mut out);
        let mut scratch = Vec::new();
        let verdicts = claims::claim_findings(&runs, &mut scratch);
        for (scene, verdict) in &verdicts {
            let group: Vec<&RunMetrics> = runs.iter().filter(|r| &r.scene == scene).collect();
            out.push(claim(scene, verdict, &group, verdicts.len() > 1));
        }
        let worst = runs
            .iter()
            .filter_map(|r| r.audit_rel().map(|x| (r, x)))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((r, x)) = worst {
            out.push(if x < 1e-6 {
                format!("The energy balance closes in every run: the largest residual is {x:.1e} of the electric energy ({}).", r.run)
            } else {
                format!("The energy balance does not close: the residual reaches {x:.1e} of the electric energy in {}.", r.run)
            });
        }
        out
    }
}

/// Sentence 1 (module docs).
fn pulling(runs: &[RunMetrics], out: &mut Vec<String>) {
    let mut brief = Vec::new();
    for r in runs.iter().filter(|r| claims::is_bilateral(r)) {
        let pulls: Vec<_> = r.contact_forces.iter().filter(|c| c.pull_time_s > 0.0).collect();
        let (long, short): (Vec<&&crate::metrics::ContactMetrics>, Vec<_>) = pulls.iter().partition(|c| c.pull_time_s >= LONG_PULL * r.t_end());
        brief.extend(short.iter().map(|c| format!("{} {} for {} s", r.run, c.contact, num(c.pull_time_s))));
        if long.is_empty() {
            continue;
        }
        let parts: Vec<String> = long
            .iter()
            .map(|c| format!("{} down for {} of the run ({} of {} s, up to {} N)", c.contact, percent(c.pull_time_s, r.t_end()), num(c.pull_time_s), num(r.t_end()), num(-c.min_normal_force_n)))
            .collect();
        out.push(format!(
            "In {}, the bilateral table pulls {}: a real table cannot pull, so this run relies on a force no table provides.",
            r.run,
            join(&parts)
        ));
    }
    if !brief.is_empty() {
        let lead = if out.is_empty() { "The bilateral table pulls (f_n < 0) only briefly" } else { "Elsewhere it pulls only briefly" };
        out.push(format!("{lead}: {}.", join(&brief)));
    }
}

/// Sentence 2 (module docs).
fn real_table(runs: &[RunMetrics], out: &mut Vec<String>) {
    let pairs = claims::pairs(runs);
    // the same numbers as printed: one sentence naming every unilateral run of the group
    let key = |(a, b): (usize, usize)| {
        let b = &runs[b];
        let contact: Vec<String> = b.contact_states.iter().filter(|c| c.time_in_contact_s > 0.0).map(|c| format!("{} {}", c.contact, num(c.time_in_contact_s))).collect();
        (a, num(b.e_total()), num(b.hand().norm.rms_m * 1e3), contact)
    };
    let mut groups: Vec<(usize, usize, Vec<&str>)> = Vec::new();
    let mut seen = Vec::new();
    for &p in &pairs {
        let k = key(p);
        match seen.iter().position(|s| s == &k) {
            Some(g) => groups[g].2.push(&runs[p.1].run),
            None => {
                seen.push(k);
                groups.push((p.0, p.1, vec![&runs[p.1].run]));
            }
        }
    }
    for (ia, ib, names) in groups {
        let (a, b) = (&runs[ia], &runs[ib]);
        let closed: Vec<String> = b
            .contact_states
            .iter()
            .filter(|c| c.time_in_contact_s > 0.0)
            .map(|c| format!("{} for {} s", c.contact, num(c.time_in_contact_s)))
            .collect();
        let who = if names.len() == 1 { names[0].to_string() } else { format!("{}, with the same numbers", join(&names.iter().map(|s| s.to_string()).collect::<Vec<_>>())) };
        out.push(format!(
            "On a table that only pushes ({who}), the arm of {} keeps {} of {} s on the table and draws {} J instead of {} J (× {}), with a hand error RMS of {} mm instead of {} mm.",
            a.run,
            join(&closed),
            num(b.t_end()),
            num(b.e_total()),
            num(a.e_total()),
            num(b.e_total() / a.e_total()),
            num(b.hand().norm.rms_m * 1e3),
            num(a.hand().norm.rms_m * 1e3),
        ));
    }
}

/// Sentence 3 (module docs): the runs of one scene in order of contacts that carried the arm.
fn claim(scene: &str, verdict: &str, group: &[&RunMetrics], name_scene: bool) -> String {
    let mut order: Vec<&RunMetrics> = group.to_vec();
    order.sort_by_key(|r| claims::carried(r).len());
    let chain = |f: &dyn Fn(&RunMetrics) -> String| order.iter().map(|r| f(r)).collect::<Vec<_>>().join(" → ");
    let counts = chain(&|r| claims::carried(r).len().to_string());
    let energy = chain(&|r| num(r.e_total()));
    let z = chain(&|r| num(r.hand().z.rms_m * 1e3));
    let wher = if name_scene { format!(" in scene {scene}") } else { String::new() };
    format!(
        "The paper's claim {} {verdict}{wher}: with {counts} contacts the electric energy is {energy} J and the z error RMS {z} mm.",
        claims::CLAIM
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_have_sensible_precision() {
        let got: Vec<String> = [3194.536, 113.99, 13.758, 0.019, -6.905, 1.0].map(num).to_vec();
        assert_eq!(got, ["3195", "114", "13.8", "0.0190", "−6.91", "1.00"]);
        assert_eq!(percent(4.964, 5.0), "99 %");
        assert_eq!(percent(4.999, 5.0), "over 99 %");
        assert_eq!(percent(5.0, 5.0), "100 %");
        assert_eq!(percent(0.001, 5.0), "under 1 %");
    }

    /// A table that pulls for most of a run is the first sentence; a brief pull is one
    /// sentence after it; the claim and the balance follow.
    #[test]
    fn a_pulling_table_comes_first() {
        let mut runs = super::super::tests::paper_runs();
        let t_end = runs[0].t_end();
        runs[0].contact_forces[0].pull_time_s = 0.99 * t_end;
        runs[0].contact_forces[0].min_normal_force_n = -6.9;
        runs[1].contact_forces[0].pull_time_s = 0.019;
        let h = Comparison::new(&runs, None).unwrap().headline();
        assert!(h[0].starts_with("In two-elbow, the bilateral table pulls elbow4 down for 99 % of the run"), "{h:#?}");
        assert!(h[1].starts_with("Elsewhere it pulls only briefly: one-elbow elbow4 for 0.0190 s"), "{h:#?}");
        assert_eq!(h.iter().filter(|s| s.contains("pulls")).count(), 2, "{h:#?}");
        assert!(h.iter().any(|s| s.starts_with("The paper's claim") && s.contains("holds")), "{h:#?}");
        let no_pull = Comparison::new(&super::super::tests::paper_runs(), None).unwrap().headline();
        assert!(!no_pull.iter().any(|s| s.contains("pulls")), "{no_pull:#?}");
    }
}
