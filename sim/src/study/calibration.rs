//! The error bar of a study's evaluations, stated before the search (the book: "Find where to
//! brace", cost control). Four rules, in order:
//!
//! 1. **The evaluations' tolerance.** From the study's `tolerance.loose`, the loosest rtol (in
//!    steps of 10) at which the baseline's objective is within 0.1 % of its value at
//!    `tolerance.tight`. A baseline infeasible at either tolerance is kept with its reason, and
//!    the centre of the first discrete combination takes its place.
//! 2. **The calibration designs** ([`Study::calibration_points`]): in every discrete
//!    combination, the centre of the continuous box and the two ends of each continuous
//!    variable (the others at the centre); the centres first, at most
//!    [`MAX_CALIBRATION_DESIGNS`].
//! 3. **A lost design is replaced, never dropped.** A design infeasible at either tolerance (a
//!    run that stops, e.g. on contact chatter) is *lost*: its reasons are kept, and it is
//!    replaced by the midpoint between it and the nearest design of its combination that is
//!    feasible at both tolerances (distance in the unit box; [`replacement`]); a lost
//!    replacement is replaced the same way, at most [`MAX_REPLACEMENTS`] times. A design still
//!    lost then, or a combination with no feasible design, fails the calibration with a message
//!    naming the designs and their reasons: a lost design cannot silently shrink the bar. In a
//!    study without continuous variables a design is its whole combination: lost at both
//!    tolerances, it is an infeasible candidate as well and has no error to bound (kept, not
//!    counted); lost at one only, it fails the calibration.
//! 4. **The bar** is [`ERROR_BAR_FACTOR`] × the largest |loose − tight| over the baseline and
//!    every design feasible at both (the replacements included).
//!
//! The runs themselves are the caller's ([`calibrate`] takes a function that runs a batch of
//! jobs, in parallel if it likes): the binary runs them with rayon.
//!
//! Source of the halving rule: a bisection towards a known feasible design (the same step as
//! the "backtracking to the feasible region" of Nocedal & Wright, *Numerical Optimization*,
//! 2nd ed., 2006, §3.1).

use serde::{Deserialize, Serialize};

use super::optimizer::Point;
use super::Study;
use crate::sweep::Variant;

/// Most designs (besides the baseline and the replacements) the error bar is measured at.
pub const MAX_CALIBRATION_DESIGNS: usize = 24;

/// Most replacements of one lost calibration design (rule 3).
pub const MAX_REPLACEMENTS: usize = 3;

/// The stated error bar is this factor times the largest loose − tight difference measured at
/// the calibration designs: a few designs sample the design space, the factor covers the
/// designs between them (the book: "Find where to brace", cost control).
pub const ERROR_BAR_FACTOR: f64 = 2.0;

/// How the evaluations' tolerance was chosen and their error bar stated.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Calibration {
    /// The rtol the evaluations run at.
    pub loose: f64,
    /// The rtol of the re-runs.
    pub tight: f64,
    /// The design of the ladder when the baseline is infeasible (rule 1; empty: the baseline).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub reference: String,
    /// The reference's objective at each rtol tried, loose to tight: (rtol, objective).
    pub ladder: Vec<(f64, f64)>,
    /// The stated error bar of an evaluation, J: [`ERROR_BAR_FACTOR`] × the largest
    /// |objective(loose) − objective(tight)| over the baseline and the designs that count.
    pub error_j: f64,
    /// The designs the error bar was measured at: the baseline first, then the calibration
    /// designs, then the replacements of the lost ones.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub designs: Vec<CalibrationDesign>,
}

/// One design of the calibration: its objective at the loose and at the tight rtol (none when
/// infeasible there: the design is lost, and `lost` says why).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CalibrationDesign {
    /// What it is: `baseline`, or the design's variables.
    pub design: String,
    pub loose: Option<f64>,
    pub tight: Option<f64>,
    /// Why the design is lost: the reason of each infeasible run (its error names the time).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lost: Option<String>,
    /// A replacement: the index in `designs` of the lost design it stands for.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replaces: Option<usize>,
}

impl CalibrationDesign {
    /// |loose − tight|, when both are feasible.
    pub fn error(&self) -> Option<f64> {
        Some((self.loose? - self.tight?).abs())
    }
}

/// One run the calibration needs: a design at an rtol.
#[derive(Clone, Debug)]
pub struct Job {
    pub variant: Variant,
    pub rtol: f64,
}

/// A job's objective, or why the design is infeasible there.
pub type JobResult = Result<f64, String>;

impl Study {
    /// The designs (besides the baseline) at which the evaluations' error bar is measured: in
    /// every discrete combination, the centre of the continuous box and, for each continuous
    /// variable, its two ends (the others at the centre); the centres of all combinations come
    /// first, then the ends, and at most [`MAX_CALIBRATION_DESIGNS`] are taken.
    pub fn calibration_points(&self) -> Vec<Point> {
        let n = self.continuous.len();
        let combos = self.settings.combos.max(1);
        let mut pts: Vec<Point> = (0..combos).map(|combo| Point { combo, u: vec![0.5; n] }).collect();
        for combo in 0..combos {
            for i in 0..n {
                for end in [0.0, 1.0] {
                    let mut u = vec![0.5; n];
                    u[i] = end;
                    pts.push(Point { combo, u });
                }
            }
        }
        pts.truncate(MAX_CALIBRATION_DESIGNS);
        pts
    }

    /// The design of `p` in words: `column = cell, ...`.
    pub fn design_label(&self, p: &Point) -> String {
        self.columns().iter().zip(self.cells(p)).map(|(c, x)| format!("{c} = {x}")).collect::<Vec<_>>().join(", ")
    }
}

/// The replacement of the lost design `lost` (rule 3): the midpoint between it and the nearest
/// of `feasible` in its combination (ties: the first), or `None` when its combination has none.
pub fn replacement(lost: &Point, feasible: &[&Point]) -> Option<Point> {
    let d2 = |p: &Point| p.u.iter().zip(&lost.u).map(|(a, b)| (a - b) * (a - b)).sum::<f64>();
    let anchor = feasible.iter().filter(|p| p.combo == lost.combo).min_by(|a, b| d2(a).total_cmp(&d2(b)))?;
    Some(Point { combo: lost.combo, u: lost.u.iter().zip(&anchor.u).map(|(a, b)| 0.5 * (a + b)).collect() })
}

/// Why a design at (loose, tight) is lost, or `None` when it counts.
fn lost_reason(loose_rtol: f64, tight_rtol: f64, loose: &JobResult, tight: &JobResult) -> Option<String> {
    let mut why = Vec::new();
    for (r, x) in [(loose_rtol, loose), (tight_rtol, tight)] {
        if let Err(e) = x {
            why.push(format!("at rtol {r:e}: {e}"));
        }
    }
    (!why.is_empty()).then(|| why.join("; "))
}

/// Rules 1–4: the evaluations' rtol and the stated error bar, running the jobs with `run` (one
/// result per job, in order); `Ok(None)` without a `tolerance` in the study; `Err` names what
/// failed (the baseline, or a design lost beyond its replacements).
pub fn calibrate(study: &Study, run: &mut dyn FnMut(&[Job]) -> Vec<JobResult>) -> Result<Option<Calibration>, String> {
    let Some(t) = &study.spec.tolerance else { return Ok(None) };
    // each job named by its rtol: two of them run at once
    let job = |variant: &Variant, rtol: f64| Job { variant: Variant { name: format!("{}-rtol{rtol:e}", variant.name), ..variant.clone() }, rtol };
    // rule 1: the baseline at tight and at loose together, then down the ladder; a baseline
    // infeasible at either is kept with its reason, and the first calibration design feasible
    // at both takes its place in the ladder
    let b = study.baseline();
    let at_b = run(&[job(&b, t.tight), job(&b, t.loose)]);
    let (reference, what, first, baseline_lost) = match (&at_b[0], &at_b[1]) {
        (Ok(_), Ok(_)) => (b, String::new(), at_b, None),
        (tight_b, loose_b) => {
            let why = lost_reason(t.loose, t.tight, loose_b, tight_b);
            let lost = CalibrationDesign { design: "baseline".into(), loose: loose_b.clone().ok(), tight: tight_b.clone().ok(), lost: why.clone(), replaces: None };
            // the calibration designs in order, until one is feasible at both
            let mut found = None;
            let mut tried = Vec::new();
            for (k, p) in study.calibration_points().iter().enumerate() {
                let mut v = study.variant(k, p);
                v.name = format!("{}-reference-{k:02}", study.spec.name);
                let at = run(&[job(&v, t.tight), job(&v, t.loose)]);
                if at[0].is_ok() && at[1].is_ok() {
                    found = Some((v, study.design_label(p), at));
                    break;
                }
                tried.push(format!("`{}` ({})", study.design_label(p), lost_reason(t.loose, t.tight, &at[1], &at[0]).unwrap_or_default()));
            }
            let Some((v, label, at)) = found else {
                return Err(format!(
                    "calibrating the tolerance: the baseline is infeasible ({}), and so is every calibration design that could take its place: {}",
                    why.unwrap_or_default(),
                    tried.join("; ")
                ));
            };
            (v, label, at, Some(lost))
        }
    };
    let name = if what.is_empty() { "the baseline".to_string() } else { format!("the reference design {what} (the baseline is infeasible)") };
    let ladder_err = |r: f64, e: String| format!("calibrating the tolerance: {name} at rtol {r:e}: {e}");
    let tight = first[0].clone().map_err(|e| ladder_err(t.tight, e))?;
    let mut r = t.loose;
    let mut loose_j = first[1].clone().map_err(|e| ladder_err(r, e))?;
    let mut ladder = vec![(r, loose_j)];
    while (loose_j - tight).abs() > 1e-3 * tight.abs() && r / 10.0 > t.tight {
        r /= 10.0;
        loose_j = run(&[job(&reference, r)]).remove(0).map_err(|e| ladder_err(r, e))?;
        ladder.push((r, loose_j));
    }
    ladder.push((t.tight, tight));
    // rule 2, then rule 3 round by round: every pending design at both tolerances, in one batch
    let mut designs = vec![baseline_lost.unwrap_or(CalibrationDesign { design: "baseline".into(), loose: Some(loose_j), tight: Some(tight), lost: None, replaces: None })];
    let mut points: Vec<Point> = Vec::new();
    let mut pending: Vec<(Point, Option<usize>)> = study.calibration_points().into_iter().map(|p| (p, None)).collect();
    let mut originals_ok: Vec<Point> = Vec::new();
    let self_contained = study.continuous.is_empty();
    for round in 0..=MAX_REPLACEMENTS {
        if pending.is_empty() {
            break;
        }
        let jobs: Vec<Job> = pending
            .iter()
            .enumerate()
            .flat_map(|(j, (p, _))| {
                let mut v = study.variant(points.len() + j, p);
                v.name = format!("{}-calibration-{:02}", study.spec.name, points.len() + j);
                [(r, "loose"), (t.tight, "tight")].map(|(rtol, which)| Job { variant: Variant { name: format!("{}-{which}", v.name), ..v.clone() }, rtol })
            })
            .collect();
        let results = run(&jobs);
        // (the lost point, the original lost design it stands for, its own index)
        let mut lost_now: Vec<(Point, usize, usize)> = Vec::new();
        for (j, (p, replaces)) in pending.iter().enumerate() {
            let (lo, ti) = (&results[2 * j], &results[2 * j + 1]);
            let lost = lost_reason(r, t.tight, lo, ti);
            let index = designs.len();
            designs.push(CalibrationDesign { design: study.design_label(p), loose: lo.clone().ok(), tight: ti.clone().ok(), lost: lost.clone(), replaces: *replaces });
            points.push(p.clone());
            match lost {
                None if round == 0 => originals_ok.push(p.clone()),
                None => {}
                // without continuous variables a design is its whole combination: lost at both
                // tolerances, it is an infeasible candidate too, with no error to bound
                Some(_) if self_contained && lo.is_err() && ti.is_err() => {}
                // a replacement stands for the original lost design
                Some(_) => lost_now.push((p.clone(), replaces.unwrap_or(index), index)),
            }
        }
        let anchors: Vec<&Point> = originals_ok.iter().collect();
        let mut next = Vec::new();
        for (p, original, last) in lost_now {
            let what = |k: usize| format!("`{}` ({})", designs[k].design, designs[k].lost.clone().unwrap_or_default());
            if round == MAX_REPLACEMENTS {
                return Err(format!(
                    "calibrating the error bar: the design {} is infeasible, and so are its {MAX_REPLACEMENTS} replacements towards the feasible designs (the last: {}): the error bar cannot be stated over this design space (a lost design is replaced, never dropped: the book, \"Find where to brace\"); narrow the variables' ranges away from it",
                    what(original),
                    what(last)
                ));
            }
            match replacement(&p, &anchors) {
                Some(q) => next.push((q, Some(original))),
                None => {
                    return Err(format!(
                        "calibrating the error bar: every calibration design of combination {} ({}) is infeasible, e.g. {}: no error bar can be stated for it; narrow its variables' ranges or drop the choice",
                        p.combo,
                        study.combo_label(p.combo),
                        what(original)
                    ))
                }
            }
        }
        pending = next;
    }
    // rule 4
    let largest = designs.iter().filter_map(CalibrationDesign::error).fold(0.0, f64::max);
    Ok(Some(Calibration { loose: r, tight: t.tight, reference: what, ladder, error_j: ERROR_BAR_FACTOR * largest, designs }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lost_design_is_replaced_halfway_towards_the_nearest_feasible_design_of_its_combination() {
        let centre = Point { combo: 1, u: vec![0.5, 0.5] };
        let end = Point { combo: 1, u: vec![1.0, 0.5] };
        let other = Point { combo: 0, u: vec![0.0, 0.0] };
        let lost = Point { combo: 1, u: vec![0.0, 0.5] };
        // the other combination's design is nearer but not of its combination
        let q = replacement(&lost, &[&other, &end, &centre]).expect("a replacement");
        assert_eq!(q, Point { combo: 1, u: vec![0.25, 0.5] });
        // halving again goes on towards the same design
        assert_eq!(replacement(&q, &[&other, &end, &centre]), Some(Point { combo: 1, u: vec![0.375, 0.5] }));
        // a lost centre goes towards its nearest end
        assert_eq!(replacement(&centre, &[&end]), Some(Point { combo: 1, u: vec![0.75, 0.5] }));
        // no feasible design in the combination: none
        assert_eq!(replacement(&lost, &[&other]), None);
    }

    /// The small study (kd in [2, 20]) with a model of its evaluations instead of runs: the
    /// objective at (kd, rtol) is kd² + 10³ rtol (30 − kd) (its loose − tight error largest at
    /// small kd), infeasible (with a reason naming a time) where `lost(Some(kd))`; the baseline
    /// (no kd) 50 + 10³ rtol, infeasible where `lost(None)`.
    fn calibrate_with(lost: impl Fn(Option<f64>) -> bool) -> (Result<Option<Calibration>, String>, Vec<f64>) {
        let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/studies/small-kd.json");
        let study = Study::load(&file).expect("the small study");
        let mut seen = Vec::new();
        let mut run = |jobs: &[Job]| -> Vec<JobResult> {
            jobs.iter()
                .map(|j| {
                    let kd = j.variant.replacements.iter().find(|(f, _)| f == "controller.kd").and_then(|(_, v)| v.as_f64());
                    match kd {
                        None if lost(None) => Err("the run stopped at t = 0.3 s: a step-size collapse".into()),
                        None => Ok(50.0 + 1e3 * j.rtol),
                        Some(kd) => {
                            seen.push(kd);
                            if lost(Some(kd)) {
                                Err(format!("the run stopped at t = 0.1{kd} s: the contact modes chatter"))
                            } else {
                                Ok(kd * kd + 1e3 * j.rtol * (30.0 - kd))
                            }
                        }
                    }
                })
                .collect()
        };
        (calibrate(&study, &mut run), seen)
    }

    /// An enumerated study (`which-elbow.json`, 6 single-contact choices): a choice infeasible
    /// at both tolerances is an infeasible candidate, kept and not counted; one infeasible at
    /// one tolerance only fails the calibration (its candidate would have an unbounded error).
    #[test]
    fn in_an_enumerated_study_a_design_lost_at_both_tolerances_needs_no_bar() {
        let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/studies/which-elbow.json");
        let study = Study::load(&file).expect("the joint-point study");
        let model = |bad_tight: &'static str| {
            move |jobs: &[Job]| -> Vec<JobResult> {
                jobs.iter()
                    .map(|j| {
                        let choice = j.variant.replacements.first().map(|(_, v)| v.to_string()).unwrap_or_default();
                        if choice.contains("joint3") || (choice.contains(bad_tight) && j.rtol < 1e-6) {
                            Err("the run stopped at t = 0.2 s: the contact modes chatter".into())
                        } else {
                            Ok(100.0 + 1e3 * j.rtol * (1.0 + choice.len() as f64))
                        }
                    })
                    .collect()
            }
        };
        let c = calibrate(&study, &mut model("no such choice")).unwrap().unwrap();
        assert_eq!(c.designs.len(), 7, "the baseline and 6 choices, no replacement: {c:?}");
        assert!(c.designs[1].design.contains("joint3") && c.designs[1].lost.is_some() && c.designs[1].error().is_none(), "{c:?}");
        assert_eq!(c.designs.iter().filter(|d| d.error().is_some()).count(), 6);
        let e = calibrate(&study, &mut model("joint5")).unwrap_err();
        assert!(e.contains("every calibration design of combination 2 (joint5)"), "{e}");
    }

    #[test]
    fn a_lost_calibration_design_is_replaced_and_its_replacement_counts_towards_the_bar() {
        // nothing lost: the centre and both ends, the bar twice the largest loose − tight
        let (c, _) = calibrate_with(|_| false);
        let c = c.unwrap().unwrap();
        let kds: Vec<&str> = c.designs.iter().map(|d| d.design.as_str()).collect();
        assert_eq!(kds, ["baseline", "controller.kd = 11.0000", "controller.kd = 2.0000", "controller.kd = 20.0000"]);
        let err = |kd: f64| 1e3 * (c.loose - c.tight) * (30.0 - kd);
        assert!((c.error_j - ERROR_BAR_FACTOR * err(2.0)).abs() < 1e-9, "{c:?}");
        // kd < 5 lost: kd = 2 is kept with its reason, replaced by kd = 6.5 (halfway to the
        // centre, its nearest feasible design), whose error sets the bar
        let (c, seen) = calibrate_with(|kd| kd.is_some_and(|kd| kd < 5.0));
        let c = c.unwrap().unwrap();
        assert_eq!(c.designs.len(), 5, "{c:?}");
        let lost = &c.designs[2];
        assert_eq!((lost.design.as_str(), lost.loose, lost.tight), ("controller.kd = 2.0000", None, None));
        let why = lost.lost.as_deref().expect("the reason");
        assert!(why.contains(&format!("at rtol {:e}: the run stopped at t = 0.12 s", c.loose)) && why.contains("at rtol 1e-8"), "{why}");
        let r = &c.designs[4];
        assert_eq!((r.design.as_str(), r.replaces, r.lost.as_deref()), ("controller.kd = 6.5000", Some(2), None));
        assert!((c.error_j - ERROR_BAR_FACTOR * err(6.5)).abs() < 1e-9, "the replacement's error sets the bar: {c:?}");
        assert!(ERROR_BAR_FACTOR * err(11.0) < c.error_j, "without it the bar would shrink");
        assert_eq!(seen.iter().filter(|&&k| k == 6.5).count(), 2, "the replacement at both tolerances");
        // kd < 10.5 lost: 2, then 6.5, 8.75, 9.875 towards kd = 11, all lost: the calibration fails
        let (c, _) = calibrate_with(|kd| kd.is_some_and(|kd| kd < 10.5));
        let e = c.unwrap_err();
        assert!(e.contains("`controller.kd = 2.0000` (at rtol") && e.contains("its 3 replacements") && e.contains("`controller.kd = 9.8750`"), "{e}");
        // every design lost: no feasible design to move towards
        let (c, _) = calibrate_with(|kd| kd.is_some());
        let e = c.unwrap_err();
        assert!(e.contains("every calibration design of combination 0"), "{e}");
        // the baseline lost: kept with its reasons, not counted; the centre (kd = 11) runs the
        // ladder: 10³ rtol · 19 within 0.1 % of 121 J first at rtol 1e-6
        let (c, _) = calibrate_with(|kd| kd.is_none());
        let c = c.unwrap().unwrap();
        assert_eq!(c.reference, "controller.kd = 11.0000");
        assert_eq!((c.designs[0].design.as_str(), c.designs[0].loose, c.designs[0].error()), ("baseline", None, None));
        assert!(c.designs[0].lost.as_deref().is_some_and(|w| w.contains("step-size collapse")), "{c:?}");
        // (the ladder divides by 10: rtols to a relative 1e-12)
        let near = |a: f64, b: f64| (a / b - 1.0).abs() < 1e-12;
        assert!(c.ladder.iter().map(|l| l.0).zip([1e-4, 1e-5, 1e-6, 1e-8]).all(|(a, b)| near(a, b)), "{c:?}");
        assert!(near(c.loose, 1e-6), "{c:?}");
        assert!((c.ladder[2].1 - (121.0 + 1e-3 * 19.0)).abs() < 1e-9, "{c:?}");
        assert!((c.error_j - ERROR_BAR_FACTOR * 1e3 * (1e-6 - 1e-8) * 28.0).abs() < 1e-9, "{c:?}");
        // the baseline and the centre lost: the next calibration design (kd = 2) runs the
        // ladder (10³ rtol · 28 within 0.1 % of 4 J first at rtol 1e-7); the centre is replaced
        let (c, _) = calibrate_with(|kd| kd.is_none_or(|kd| kd == 11.0));
        let c = c.unwrap().unwrap();
        assert_eq!(c.reference, "controller.kd = 2.0000", "{c:?}");
        assert!(near(c.loose, 1e-7), "{c:?}");
        assert_eq!(c.designs.last().map(|d| (d.design.as_str(), d.replaces)), Some(("controller.kd = 6.5000", Some(1))), "{c:?}");
        // nothing feasible to take the baseline's place: the calibration fails, naming each
        let (c, _) = calibrate_with(|_| true);
        let e = c.unwrap_err();
        assert!(e.contains("the baseline is infeasible (at rtol 1e-4: the run stopped at t = 0.3 s") && e.contains("`controller.kd = 20.0000` (at rtol"), "{e}");
    }
}
