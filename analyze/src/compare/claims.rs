//! The paper's claim "more elbows → less electric energy and smaller z error" checked per scene,
//! over the contacts that carried the arm, and how the conclusions change when the table can only
//! push (a bilateral run against the run of another scene with a unilateral or compliant table).
//!
//! - **Contacts that carried the arm** ([`carried`]): every declared bilateral contact (its row is
//!   always active: SCENE.md, the paper's model), and every unilateral or compliant contact with
//!   time in contact > 0 (a rigid unilateral contact carries force only while closed: Pfeiffer &
//!   Glocker 1996, ch. 4). A table under candidate points that never touch does not count them.
//! - **Per scene**: runs of different scenes are not comparable (another arm, another table), so
//!   the claim is checked within each scene with at least two runs. With one scene the sentences
//!   are those of a plain comparison (unchanged for the paper alone).
//! - **Bilateral → unilateral pairs** ([`table_pairs`]): a bilateral run A and a run B with a
//!   unilateral or compliant contact, from different scenes, with the same set of contact names
//!   that carried force and the same duration (|Δt_end| ≤ 1e-9 max(1, t_end) s): electric energy,
//!   saving against a run without contacts of the same duration, hand error, B's time in contact
//!   and A's time with a pulling table.

use super::Measured;
use crate::metrics::RunMetrics;

/// The claim in the "So ..." sentences.
pub(super) const CLAIM: &str = "\"more elbows → less electric energy and smaller z error\"";

pub(super) fn plural(n: usize, one: &str) -> String {
    if n == 1 {
        format!("{n} {one}")
    } else {
        format!("{n} {one}s")
    }
}

/// Whether every contact of `r` is bilateral (no contact state, or model `bilateral`).
pub(super) fn is_bilateral(r: &RunMetrics) -> bool {
    r.contact_states.iter().all(|c| c.model.as_deref() == Some("bilateral"))
}

/// The declared contacts of `r` that carried the arm (module docs), in declaration order.
pub(super) fn carried(r: &RunMetrics) -> Vec<&str> {
    r.contacts
        .iter()
        .filter(|name| match r.contact_states.iter().find(|c| &c.contact == *name) {
            Some(c) if c.model.as_deref() != Some("bilateral") => c.time_in_contact_s > 0.0,
            _ => true,
        })
        .map(String::as_str)
        .collect()
}

/// "2 contacts", or "2 of 9 contacts touched" when fewer carried the arm than were declared.
fn count_label(r: &RunMetrics) -> String {
    let (n, declared) = (carried(r).len(), r.contacts.len());
    if n == declared {
        plural(n, "contact")
    } else {
        format!("{n} of {} touched", plural(declared, "contact"))
    }
}

/// Whether the value falls strictly with more contacts that carried the arm: `Some(holds)` with
/// a sentence, or `None` when every run has the same number.
pub(super) fn trend(
    runs: &[&RunMetrics],
    what: &str,
    value: impl Fn(&RunMetrics) -> f64,
    show: impl Fn(f64) -> String,
) -> (Option<bool>, String) {
    let counts: Vec<usize> = runs.iter().map(|r| carried(r).len()).collect();
    let n = |k: usize| counts[k];
    let mut order: Vec<usize> = (0..runs.len()).collect();
    order.sort_by_key(|&k| n(k));
    if n(order[0]) == n(order[order.len() - 1]) {
        return (
            None,
            format!("More elbows → {what}: cannot be checked, every run has {}.", plural(n(0), "contact")),
        );
    }
    let label = |k: usize| format!("{} ({}) {}", runs[k].run, count_label(runs[k]), show(value(runs[k])));
    let mut broken = Vec::new();
    for &a in &order {
        for &b in order.iter().filter(|&&b| n(b) > n(a)) {
            // a NaN compares as not below, so it breaks the trend
            let below = value(runs[b]).partial_cmp(&value(runs[a])) == Some(std::cmp::Ordering::Less);
            if !below {
                broken.push(format!("{} is not below {}", label(b), label(a)));
            }
        }
    }
    if broken.is_empty() {
        // runs with the same number of contacts are not ordered: listed with ", "
        let mut chain = String::new();
        for (i, &k) in order.iter().enumerate() {
            if i > 0 {
                chain.push_str(if n(k) == n(order[i - 1]) { ", " } else { " > " });
            }
            chain.push_str(&label(k));
        }
        (Some(true), format!("More elbows → {what}: holds ({chain})."))
    } else {
        (Some(false), format!("More elbows → {what}: does not hold: {}.", broken.join("; ")))
    }
}

/// The verdict on [`CLAIM`] from the two trends.
fn verdict(e_ok: Option<bool>, z_ok: Option<bool>) -> &'static str {
    match (e_ok, z_ok) {
        (Some(true), Some(true)) => "holds",
        (Some(_), Some(_)) => "does not hold",
        _ => "cannot be checked",
    }
}

/// The trend sentences, per scene when the runs come from several: `out` gets them, the result
/// is each checked scene's verdict on [`CLAIM`].
pub(super) fn claim_findings(runs: &[RunMetrics], out: &mut Vec<String>) -> Vec<(String, &'static str)> {
    let energy = |g: &[&RunMetrics]| trend(g, "less electric energy", |r| r.e_total(), |x| format!("{} J", super::fixed(x, 3)));
    let z = |g: &[&RunMetrics]| trend(g, "smaller z error", |r| r.hand().z.rms_m, |x| format!("{:.3} mm", x * 1e3));
    let mut scenes: Vec<&str> = Vec::new();
    for r in runs {
        if !scenes.contains(&r.scene.as_str()) {
            scenes.push(&r.scene);
        }
    }
    if scenes.len() == 1 {
        let all: Vec<&RunMetrics> = runs.iter().collect();
        let ((e_ok, e_text), (z_ok, z_text)) = (energy(&all), z(&all));
        out.push(e_text);
        out.push(z_text);
        let v = verdict(e_ok, z_ok);
        out.push(format!("So {CLAIM} {v} across these runs."));
        return vec![(scenes[0].to_string(), v)];
    }
    let mut verdicts = Vec::new();
    for scene in scenes {
        let group: Vec<&RunMetrics> = runs.iter().filter(|r| r.scene == scene).collect();
        if group.len() < 2 {
            continue;
        }
        let ((e_ok, e_text), (z_ok, z_text)) = (energy(&group), z(&group));
        out.push(format!("Scene {scene}: {e_text}"));
        out.push(format!("Scene {scene}: {z_text}"));
        let v = verdict(e_ok, z_ok);
        out.push(format!("So {CLAIM} {v} in scene {scene} ({} runs).", group.len()));
        verdicts.push((scene.to_string(), v));
    }
    if verdicts.is_empty() {
        out.push(format!(
            "So {CLAIM} cannot be checked on these runs: it is checked within a scene, and no scene has two runs."
        ));
    }
    verdicts
}

/// Whether two runs have the same duration (module docs).
fn same_duration(a: &RunMetrics, b: &RunMetrics) -> bool {
    (a.t_end() - b.t_end()).abs() <= 1e-9 * a.t_end().abs().max(b.t_end().abs()).max(1.0)
}

fn sorted(mut v: Vec<&str>) -> Vec<&str> {
    v.sort_unstable();
    v
}

/// The bilateral → unilateral pairs (module docs) as `(bilateral, unilateral)` indices into
/// `runs`, in run order.
pub(super) fn pairs(runs: &[RunMetrics]) -> Vec<(usize, usize)> {
    let mut pairs = Vec::new();
    for (ia, a) in runs.iter().enumerate() {
        if !is_bilateral(a) || a.contacts.is_empty() {
            continue;
        }
        for (ib, b) in runs.iter().enumerate() {
            if is_bilateral(b) || b.scene == a.scene || !same_duration(a, b) {
                continue;
            }
            let touched = carried(b);
            if !touched.is_empty() && sorted(carried(a)) == sorted(touched) {
                pairs.push((ia, ib));
            }
        }
    }
    pairs
}

/// The bilateral → unilateral block (module docs): empty when no pair exists. `base` is the
/// comparison's baseline, preferred for the savings when it has no contacts and the duration.
pub(super) fn table_pairs(runs: &[RunMetrics], base: usize, verdicts: &[(String, &'static str)]) -> Vec<String> {
    let pairs = pairs(runs);
    if pairs.is_empty() {
        return Vec::new();
    }
    let mut out = vec![
        "How the paper's conclusions change when the table can only push: bilateral run → run of another scene with a \
         unilateral or compliant table, paired by the names of the contacts that carried the arm, over the same duration."
            .to_string(),
    ];
    let mm = |x: f64| format!("{:.3} mm", x * 1e3);
    for &(ia, ib) in &pairs {
        let (a, b) = (&runs[ia], &runs[ib]);
        let names = carried(b).join(", ");
        let basis = if carried(b).len() == b.contacts.len() {
            format!("same contacts {names}")
        } else {
            format!("{}: {}, only {names} touched; paired by those", b.run, plural(b.contacts.len(), "candidate contact"))
        };
        let (ea, eb) = (a.e_total(), b.e_total());
        let times = if ea != 0.0 && ea.is_finite() && eb.is_finite() {
            format!(" (× {:.3})", eb / ea)
        } else {
            String::new()
        };
        // the run without contacts to measure savings against: the baseline, else one of A's scene
        let bare = |k: usize| runs[k].contacts.is_empty() && same_duration(&runs[k], a) && runs[k].e_total() != 0.0;
        let zero = std::iter::once(base)
            .chain((0..runs.len()).filter(|&k| runs[k].scene == a.scene))
            .chain(0..runs.len())
            .find(|&k| bare(k));
        let saving = zero.map_or(String::new(), |k| {
            let e0 = runs[k].e_total();
            let s = |e: f64| (1.0 - e / e0) * 100.0;
            format!(", saving against {} {:.1} % → {:.1} %", runs[k].run, s(ea), s(eb))
        });
        let in_contact: Vec<String> = b
            .contact_states
            .iter()
            .filter(|c| c.time_in_contact_s > 0.0)
            .map(|c| format!("{} {:.3} s", c.contact, c.time_in_contact_s))
            .collect();
        let pulls: Vec<String> = a
            .contact_forces
            .iter()
            .filter(|c| c.pull_time_s > 0.0)
            .map(|c| format!("{} for {:.3} s", c.contact, c.pull_time_s))
            .collect();
        let pulled = if pulls.is_empty() {
            format!("{}'s table never pulled", a.run)
        } else {
            format!("{}'s table pulled (f_n < 0) on {}", a.run, pulls.join(", "))
        };
        out.push(format!(
            "{} → {} ({basis}): electric energy {} J → {} J{times}{saving}, z error RMS {} → {}, |e| RMS {} → {}; \
             time in contact ({}): {} of {:.3} s; {pulled}.",
            a.run,
            b.run,
            super::fixed(ea, 3),
            super::fixed(eb, 3),
            mm(a.hand().z.rms_m),
            mm(b.hand().z.rms_m),
            mm(a.hand().norm.rms_m),
            mm(b.hand().norm.rms_m),
            b.run,
            in_contact.join(", "),
            b.t_end(),
        ));
    }
    // the claim in each bilateral scene against each unilateral one of the pairs
    let find = |s: &str| verdicts.iter().find(|(v, _)| v == s).map(|(_, v)| *v);
    let mut scene_pairs: Vec<(&str, &str)> = Vec::new();
    for &(ia, ib) in &pairs {
        let p = (runs[ia].scene.as_str(), runs[ib].scene.as_str());
        if !scene_pairs.contains(&p) {
            scene_pairs.push(p);
        }
    }
    for (sa, sb) in scene_pairs {
        if let (Some(va), Some(vb)) = (find(sa), find(sb)) {
            let still = if va == vb && va == "holds" { "still holds" } else { vb };
            out.push(format!(
                "So with a table that can only push, {CLAIM} {still} in scene {sb} ({va} in scene {sa} with the bilateral table)."
            ));
        }
    }
    out
}
