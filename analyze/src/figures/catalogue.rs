//! Which figures there are, with their captions, and the lines each one draws.
//!
//! The paper's figures keep its numbers and titles (Fig. 1-25); symbols follow it: W for link
//! work, E for electric energy, τ motor torque, q̇ joint speed, i current, v voltage, r the hand
//! and r_d its target, f_n the table's normal force (positive upwards), j the joint or link.

use super::draw::{Key, Line, Panel, Plot, COLORS};
use super::markup::sub;
use super::{Figure, RunSeries, Series};
use plotters::style::RGBColor;

const SIZE: (u32, u32) = (1000, 700);
const T_DESC: &str = "time t [s]";
const TARGET: RGBColor = RGBColor(0, 0, 0);
const ORDINALS: [&str; 10] = [
    "first", "second", "third", "fourth", "fifth", "sixth", "seventh", "eighth", "ninth", "tenth",
];

/// The colour of run `k` (its place in the list of runs), the same in every figure.
fn color(k: usize) -> RGBColor {
    COLORS[k % COLORS.len()]
}

fn figure(number: Option<u32>, stem: String, caption: String, note: &str) -> Figure {
    Figure {
        number,
        stem,
        caption,
        note: note.into(),
    }
}

/// The legend entries of the runs that have a line in `panels`, in run order.
fn run_keys(runs: &[RunSeries], has: impl Fn(&RunSeries) -> bool) -> Vec<Key> {
    runs.iter()
        .enumerate()
        .filter(|(_, r)| has(r))
        .map(|(k, r)| Key::line(r.name.clone(), color(k)))
        .collect()
}

fn plot(fig: &Figure, panels: Vec<Panel>, legend: Vec<Key>) -> Plot {
    Plot {
        title: fig.caption.clone(),
        panels,
        size: SIZE,
        legend,
        cols: 1,
    }
}

/// Symbol with a subscript: `sym(W, 3)` is W₃.
fn sym(s: &str, j: impl std::fmt::Display) -> String {
    format!("{s}{}", sub(j))
}

/// Every figure for `runs`, in the order of the index page.
pub(super) fn plots(runs: &[RunSeries]) -> Vec<(Figure, Plot)> {
    let mut out = Vec::new();
    let r_d = sym("r", "d");
    let planes = [("xy", 0, 1), ("xz", 0, 2), ("yz", 1, 2)];
    for (k, (plane, a, b)) in planes.into_iter().enumerate() {
        let n = k as u32 + 1;
        let (pa, pb) = (&plane[..1], &plane[1..]);
        let fig = figure(
            Some(n),
            format!("fig{n:02}_{plane}"),
            format!("Fig. {n}: Trajectory tracking of circle on {pa}-{pb} plane"),
            &format!(
                "The hand path r(t) of each run projected on the {pa}-{pb} plane, over the target \
                 {r_d}(t) (black, dashed); a dot marks where each path starts. Both axes have the \
                 same scale."
            ),
        );
        let mut legend = vec![Key { dashed: true, ..Key::line(format!("target {r_d}"), TARGET) }];
        legend.extend(run_keys(runs, |r| !r.actual.is_empty()));
        let p = plot(&fig, vec![path_panel(runs, a, b, pa, pb)], legend);
        out.push((fig, p));
    }

    let log_note = " The y axis is logarithmic when the runs differ by more than a factor 10, so \
                    the smallest curve is not flattened against the largest.";
    let fig = figure(
        Some(4),
        "fig04_work_total".into(),
        "Fig. 4: All link work, W = Σ ∫ τ q̇ dt".into(),
        &format!(
            "W(t) = Σ{j} ∫{o}{t} τ{j} q̇{j} dt, the work all motors have done on their links up to time t.{log_note}",
            j = sub("j"),
            o = sub(0),
            t = super::markup::sup("t")
        ),
    );
    let p = plot(
        &fig,
        vec![time_panel(runs, |r| &r.work_total, 0, "W [J]", true)],
        run_keys(runs, |r| !r.work_total.is_empty()),
    );
    out.push((fig, p));
    let fig = figure(
        Some(5),
        "fig05_electric_total".into(),
        "Fig. 5: All electric energy, E = Σ ∫ i v dt".into(),
        &format!(
            "E(t) = Σ{j} ∫{o}{t} i{j} v{j} dt, the electric energy all motors have drawn up to time t.{log_note}",
            j = sub("j"),
            o = sub(0),
            t = super::markup::sup("t")
        ),
    );
    let p = plot(
        &fig,
        vec![time_panel(runs, |r| &r.electric_total, 0, "E [J]", true)],
        run_keys(runs, |r| !r.electric_total.is_empty()),
    );
    out.push((fig, p));

    let links = runs
        .iter()
        .map(|r| r.work.cols.len().max(r.electric.cols.len()))
        .max()
        .unwrap_or(0);
    for j in 0..links {
        let ord = ORDINALS
            .get(j)
            .map_or_else(|| format!("{}th", j + 1), |s| s.to_string());
        let (nw, ne) = (6 + 2 * j as u32, 7 + 2 * j as u32);
        let l = j + 1;
        let joint = runs
            .iter()
            .find_map(|r| r.joints.get(j))
            .map_or_else(String::new, |name| format!(" (joint {name})"));
        let fig = figure(
            Some(nw),
            format!("fig{nw:02}_work_link{l:02}"),
            format!(
                "Fig. {nw}: Link work of the {ord} link, {} = ∫ {} {} dt",
                sym("W", l),
                sym("τ", l),
                sym("q̇", l)
            ),
            &format!("{}(t), the work motor {l}{joint} has done on link {l} up to time t.", sym("W", l)),
        );
        let p = plot(
            &fig,
            vec![time_panel(runs, |r| &r.work, j, &format!("{} [J]", sym("W", l)), true)],
            run_keys(runs, |r| r.work.cols.len() > j),
        );
        out.push((fig, p));
        let fig = figure(
            Some(ne),
            format!("fig{ne:02}_electric_link{l:02}"),
            format!(
                "Fig. {ne}: Electric energy of the {ord} link, {} = ∫ {} {} dt",
                sym("E", l),
                sym("i", l),
                sym("v", l)
            ),
            &format!("{}(t), the electric energy motor {l}{joint} has drawn up to time t.", sym("E", l)),
        );
        let p = plot(
            &fig,
            vec![time_panel(runs, |r| &r.electric, j, &format!("{} [J]", sym("E", l)), true)],
            run_keys(runs, |r| r.electric.cols.len() > j),
        );
        out.push((fig, p));
    }

    let spike_note = "The y range of each panel leaves out the first milliseconds' spike (it covers \
                      the 1st to 99th percentile of the samples); the spike's extreme value is \
                      written in the panel.";
    let fig = figure(
        None,
        "extra_currents".into(),
        "Motor currents".into(),
        &format!("The armature current i of every motor, one panel per joint, every run in its colour. {spike_note}"),
    );
    let p = per_joint_plot(&fig, runs, |r| &r.current, "i [A]", "A");
    out.push((fig, p));
    let fig = figure(
        None,
        "extra_voltages".into(),
        "Motor voltages".into(),
        &format!("The terminal voltage v of every motor, one panel per joint, every run in its colour. {spike_note}"),
    );
    let p = per_joint_plot(&fig, runs, |r| &r.voltage, "v [V]", "V");
    out.push((fig, p));
    let f_n = sym("f", "n");
    let fig = figure(
        None,
        "extra_normal_forces".into(),
        format!("Table's normal force on each contact, {f_n} (below 0: the table pulls)"),
        &format!(
            "The table's force on each contact point, positive upwards, one panel per contact, \
             every run that has it in its colour. A bilateral contact (the paper's) holds its point \
             with a force of either sign: where {f_n} < 0 the table pulls the arm down, which a \
             real table cannot do; a unilateral table only pushes ({f_n} ≥ 0, 0 when the contact \
             is open). Runs without contacts have no line. {spike_note}"
        ),
    );
    let p = normal_force_plot(&fig, runs);
    out.push((fig, p));
    let fig = figure(
        None,
        "extra_hand_error".into(),
        format!("Hand error |r − {r_d}| over time"),
        "The distance between the hand and the target, mm, on a log axis when the runs differ by \
         more than a factor 10.",
    );
    let mut panel = time_panel(runs, |r| &r.error_norm, 0, &format!("|r − {r_d}| [mm]"), true);
    for line in &mut panel.lines {
        line.points.iter_mut().for_each(|p| p.1 *= 1e3);
    }
    let p = plot(&fig, vec![panel], run_keys(runs, |r| !r.error_norm.is_empty()));
    out.push((fig, p));
    for (_, p) in &mut out {
        mark_hidden(p);
    }
    out
}

/// Line `a` lies under line `b` (drawn later) on a y axis `span` (from [`super::draw::y_span`]):
/// the same times and y within 0.2 % of the axis everywhere (under 1 px at the panels' heights),
/// measured in decades on a log axis.
fn hidden_under(a: &Line, b: &Line, span: (f64, f64, bool)) -> bool {
    let (lo, hi, log) = span;
    let y = |v: f64| if log { v.max(lo).log10() } else { v };
    let tol = 2e-3 * (y(hi) - y(lo));
    a.points.len() == b.points.len()
        && a.points.iter().zip(&b.points).all(|(p, q)| {
            p.0 == q.0 && (p.1 == q.1 || (y(p.1) - y(q.1)).abs() <= tol || (p.1.is_nan() && q.1.is_nan()))
        })
}

/// Says in the legend which run's line is hidden under a later run's in every panel where both
/// are drawn ("two-elbow-unilateral (under whole-table)"), so no run seems to be missing.
fn mark_hidden(plot: &mut Plot) {
    let labels: Vec<String> = plot.legend.iter().map(|k| k.label.clone()).collect();
    for key in &mut plot.legend {
        let later = labels.iter().skip_while(|l| **l != key.label).skip(1);
        let mut under = None;
        for other in later {
            let mut shared = 0;
            let all = plot.panels.iter().all(|p| {
                let find = |l: &str| p.lines.iter().find(|x| x.label == l);
                match (find(&key.label), find(other)) {
                    (Some(a), Some(b)) => {
                        shared += 1;
                        super::draw::y_span(p).is_some_and(|span| hidden_under(a, b, span))
                    }
                    _ => true,
                }
            });
            if all && shared > 0 {
                under = Some(other.clone());
            }
        }
        if let Some(b) = under {
            key.label = format!("{} (under {b})", key.label);
        }
    }
}

/// Column `j` of `pick(run)` against time, one line per run.
fn time_panel(runs: &[RunSeries], pick: impl Fn(&RunSeries) -> &Series, j: usize, y: &str, log: bool) -> Panel {
    let lines = runs
        .iter()
        .enumerate()
        .filter_map(|(k, r)| {
            let s = pick(r);
            let col = s.cols.get(j)?;
            Some(Line::series(r.name.clone(), color(k), &s.t, col))
        })
        .collect();
    let mut p = Panel::new(T_DESC, y, lines);
    p.log_allowed = log;
    p
}

/// The hand paths of all runs in the plane of axes `a`, `b`, over the first run's target.
fn path_panel(runs: &[RunSeries], a: usize, b: usize, na: &str, nb: &str) -> Panel {
    let pts = |s: &Series| -> Vec<(f64, f64)> {
        match (s.cols.get(a), s.cols.get(b)) {
            (Some(u), Some(v)) => u.iter().copied().zip(v.iter().copied()).collect(),
            _ => Vec::new(),
        }
    };
    let mut lines = Vec::new();
    if let Some(r) = runs.iter().find(|r| !r.desired.is_empty()) {
        lines.push(Line {
            label: format!("target {}", sym("r", "d")),
            color: TARGET,
            dashed: true,
            path: true,
            start_dot: false,
            points: pts(&r.desired),
        });
    }
    for (k, r) in runs.iter().enumerate() {
        if !r.actual.is_empty() {
            lines.push(Line {
                label: r.name.clone(),
                color: color(k),
                dashed: false,
                path: true,
                start_dot: true,
                points: pts(&r.actual),
            });
        }
    }
    let mut p = Panel::new(&format!("{na} [m]"), &format!("{nb} [m]"), lines);
    p.equal_aspect = true;
    p
}

/// Columns of a grid of `n` panels: one up to 3, else two.
fn grid_cols(n: usize) -> usize {
    if n <= 3 {
        1
    } else {
        2
    }
}

/// A figure of small multiples: `panels` in a grid, the height growing with the rows.
fn grid_plot(fig: &Figure, panels: Vec<Panel>, legend: Vec<Key>) -> Plot {
    let cols = grid_cols(panels.len());
    let rows = panels.len().div_ceil(cols).max(1) as u32;
    let strip = 26 * (1 + legend.len() as u32 / 6) + 6;
    Plot {
        size: (SIZE.0, (60 + strip + 230 * rows).max(SIZE.1)),
        cols,
        ..plot(fig, panels, legend)
    }
}

/// One panel per joint (named from the recordings' `joint_names`), one line per run with that
/// joint, on a robust y range ([`super::scale::robust_range`]).
fn per_joint_plot(fig: &Figure, runs: &[RunSeries], pick: impl Fn(&RunSeries) -> &Series, y: &str, unit: &str) -> Plot {
    let joints = runs.iter().map(|r| pick(r).cols.len()).max().unwrap_or(0);
    let mut panels: Vec<Panel> = (0..joints)
        .map(|j| {
            let lines = runs
                .iter()
                .enumerate()
                .filter_map(|(k, r)| {
                    let s = pick(r);
                    Some(Line::series(r.name.clone(), color(k), &s.t, s.cols.get(j)?))
                })
                .collect();
            let mut p = Panel::new(T_DESC, y, lines);
            let name = runs.iter().find_map(|r| r.joints.get(j)).cloned();
            p.subtitle = Some(match name {
                Some(n) if n != format!("joint{}", j + 1) => format!("joint {}: {n}", j + 1),
                _ => format!("joint {}", j + 1),
            });
            p.robust_unit = Some(unit.into());
            p
        })
        .collect();
    if panels.is_empty() {
        let mut p = Panel::new(T_DESC, y, Vec::new());
        p.subtitle = Some("the motors".into());
        panels.push(p);
    }
    grid_plot(fig, panels, run_keys(runs, |r| !pick(r).is_empty()))
}

/// One panel per contact name (over all runs, in order of first appearance), one line per run
/// with that contact, a zero line.
fn normal_force_plot(fig: &Figure, runs: &[RunSeries]) -> Plot {
    let name = |r: &RunSeries, c: usize| r.contacts.get(c).cloned().unwrap_or_else(|| format!("contact {}", c + 1));
    let mut contacts: Vec<String> = Vec::new();
    for r in runs {
        for c in 0..r.normal_force.cols.len() {
            let n = name(r, c);
            if !contacts.contains(&n) {
                contacts.push(n);
            }
        }
    }
    // a contact whose force is 0 in every run that has it never touched the table: no panel
    let touched = |contact: &String| {
        runs.iter().any(|r| {
            (0..r.normal_force.cols.len())
                .filter(|&c| &name(r, c) == contact)
                .any(|c| r.normal_force.cols[c].iter().any(|f| f.is_finite() && *f != 0.0))
        })
    };
    let (contacts, untouched): (Vec<String>, Vec<String>) = contacts.into_iter().partition(touched);
    let y = format!("{} [N]", sym("f", "n"));
    let mut panels: Vec<Panel> = contacts
        .iter()
        .map(|contact| {
            let lines = runs
                .iter()
                .enumerate()
                .filter_map(|(k, r)| {
                    let c = (0..r.normal_force.cols.len()).find(|&c| &name(r, c) == contact)?;
                    Some(Line::series(r.name.clone(), color(k), &r.normal_force.t, &r.normal_force.cols[c]))
                })
                .collect();
            let mut p = Panel::new(T_DESC, &y, lines);
            p.subtitle = Some(contact.clone());
            p.zero_line = true;
            p.robust_unit = Some("N".into());
            p
        })
        .collect();
    if panels.is_empty() {
        let mut p = Panel::new(T_DESC, &y, Vec::new());
        p.subtitle = Some("contacts".into());
        panels.push(p);
    }
    let mut legend = run_keys(runs, |r| !r.normal_force.is_empty());
    legend.push(Key { thin: true, ..Key::line(format!("{} = 0 (below: the table pulls)", sym("f", "n")), TARGET) });
    if !untouched.is_empty() {
        legend.push(Key { text_only: true, ..Key::line(format!("never in contact in any run (no panel): {}", untouched.join(", ")), TARGET) });
    }
    grid_plot(fig, panels, legend)
}
