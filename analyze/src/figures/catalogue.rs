//! Which figures there are, with their captions, and the lines each one draws.

use plotters::prelude::SeriesLabelPosition;
use plotters::style::RGBColor;

use super::draw::{Line, Panel, Plot, COLORS};
use super::{Figure, RunSeries, Series};

const SIZE: (u32, u32) = (1000, 700);
const T_DESC: &str = "time t [s]";
const TARGET: RGBColor = RGBColor(0, 0, 0);
const ORDINALS: [&str; 10] = [
    "first", "second", "third", "fourth", "fifth", "sixth", "seventh", "eighth", "ninth", "tenth",
];

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

fn plot(fig: &Figure, panels: Vec<Panel>) -> Plot {
    Plot {
        title: fig.caption.clone(),
        panels,
        size: SIZE,
        legend_strip: Vec::new(),
        share_y: false,
    }
}

/// Every figure for `runs`, in the order of the index page.
pub(super) fn plots(runs: &[RunSeries]) -> Vec<(Figure, Plot)> {
    let mut out = Vec::new();
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
                 r_d(t) (black, dashed); a dot marks where each path starts. Both axes have the \
                 same scale."
            ),
        );
        let p = plot(&fig, vec![path_panel(runs, a, b, pa, pb)]);
        out.push((fig, p));
    }

    let fig = figure(
        Some(4),
        "fig04_work_total".into(),
        "Fig. 4: All link work (∫ τ·q' dt)".into(),
        "W(t) = Σ_j ∫_0^t τ_j q'_j dt, the work all motors have done on their links up to time t.",
    );
    let p = plot(
        &fig,
        vec![time_panel(runs, |r| &r.work_total, 0, "W = Σ_j W_j [J]")],
    );
    out.push((fig, p));
    let fig = figure(
        Some(5),
        "fig05_electric_total".into(),
        "Fig. 5: All electric energy (∫ i·v dt)".into(),
        "E(t) = Σ_j ∫_0^t i_j v_j dt, the electric energy all motors have drawn up to time t.",
    );
    let p = plot(
        &fig,
        vec![time_panel(
            runs,
            |r| &r.electric_total,
            0,
            "E = Σ_j E_j [J]",
        )],
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
        let fig = figure(
            Some(nw),
            format!("fig{nw:02}_work_link{l:02}"),
            format!("Fig. {nw}: Link work of the {ord} link (W_{l} = ∫ τ_{l}·q'_{l} dt)"),
            &format!("W_{l}(t), the work motor {l} has done on link {l} up to time t."),
        );
        let p = plot(
            &fig,
            vec![time_panel(runs, |r| &r.work, j, &format!("W_{l} [J]"))],
        );
        out.push((fig, p));
        let fig = figure(
            Some(ne),
            format!("fig{ne:02}_electric_link{l:02}"),
            format!("Fig. {ne}: Electric energy of the {ord} link (E_{l} = ∫ i_{l}·v_{l} dt)"),
            &format!("E_{l}(t), the electric energy motor {l} has drawn up to time t."),
        );
        let p = plot(
            &fig,
            vec![time_panel(runs, |r| &r.electric, j, &format!("E_{l} [J]"))],
        );
        out.push((fig, p));
    }

    let fig = figure(
        None,
        "extra_currents".into(),
        "Motor currents i_j(t)".into(),
        "The armature current of every motor, one panel per run (all on the same scale), one \
         colour per joint (the same in every panel).",
    );
    let p = per_joint_plot(&fig, runs, |r| &r.current, "current i_j [A]");
    out.push((fig, p));
    let fig = figure(
        None,
        "extra_voltages".into(),
        "Motor voltages v_j(t)".into(),
        "The terminal voltage of every motor, one panel per run (all on the same scale), one \
         colour per joint.",
    );
    let p = per_joint_plot(&fig, runs, |r| &r.voltage, "voltage v_j [V]");
    out.push((fig, p));
    let fig = figure(
        None,
        "extra_normal_forces".into(),
        "Elbow normal forces f_n(t) (below 0: the table pulls)".into(),
        "The table's force on each elbow, positive upwards, in the colour of its run (a second \
         elbow dashed); the upper panel shows the whole run, the lower one from 0.1 s on (after \
         the start transient). The contacts are \
         bilateral, as in the paper: where f_n < 0 the table pulls the arm down, which a real \
         table cannot do. Runs without elbows have no line.",
    );
    let p = plot(&fig, normal_force_panels(runs));
    out.push((
        fig,
        Plot {
            size: (1000, 900),
            ..p
        },
    ));
    let fig = figure(
        None,
        "extra_hand_error".into(),
        "Hand error |r - r_d| over time".into(),
        "The distance between the hand and the target, mm, on a common time axis.",
    );
    let mut panel = time_panel(runs, |r| &r.error_norm, 0, "|r - r_d| [mm]");
    for line in &mut panel.lines {
        line.points.iter_mut().for_each(|p| p.1 *= 1e3);
    }
    panel.legend = SeriesLabelPosition::UpperRight;
    let p = plot(&fig, vec![panel]);
    out.push((fig, p));
    out
}

/// Line widths 4, 3, 2, 2, ...: the first runs wider, so lines on top of each other show.
fn width(k: usize, n: usize) -> u32 {
    2 + (n.saturating_sub(k + 1)).min(2) as u32
}

/// Column `j` of `pick(run)` against time, one line per run.
fn time_panel(
    runs: &[RunSeries],
    pick: impl Fn(&RunSeries) -> &Series,
    j: usize,
    y: &str,
) -> Panel {
    let lines = runs
        .iter()
        .enumerate()
        .filter_map(|(k, r)| {
            let s = pick(r);
            let col = s.cols.get(j)?;
            let line = Line::series(r.name.clone(), color(k), &s.t, col);
            Some(Line {
                width: width(k, runs.len()),
                ..line
            })
        })
        .collect();
    Panel::new(T_DESC, y, lines)
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
            label: "target r_d".into(),
            color: TARGET,
            dashed: true,
            path: true,
            start_dot: false,
            width: 2,
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
                width: 2,
                points: pts(&r.actual),
            });
        }
    }
    let mut p = Panel::new(&format!("{na} [m]"), &format!("{nb} [m]"), lines);
    p.equal_aspect = true;
    p.legend = SeriesLabelPosition::UpperRight;
    p
}

/// One panel per run on the same scale, one line per column (joint) of `pick(run)`, the joints
/// named in a legend strip under the title.
fn per_joint_plot(
    fig: &Figure,
    runs: &[RunSeries],
    pick: impl Fn(&RunSeries) -> &Series,
    y: &str,
) -> Plot {
    let joints = runs.iter().map(|r| pick(r).cols.len()).max().unwrap_or(0);
    let panels = runs
        .iter()
        .map(|r| {
            let s = pick(r);
            let lines = s
                .cols
                .iter()
                .enumerate()
                .map(|(j, col)| Line::series(format!("joint {}", j + 1), color(j), &s.t, col))
                .collect();
            let mut p = Panel::new(T_DESC, y, lines);
            p.subtitle = Some(r.name.clone());
            p.no_legend = true;
            p
        })
        .collect();
    Plot {
        legend_strip: (0..joints)
            .map(|j| (format!("joint {}", j + 1), color(j)))
            .collect(),
        share_y: true,
        size: (SIZE.0, (110 + 300 * runs.len().max(1) as u32).max(SIZE.1)),
        ..plot(fig, panels)
    }
}

/// All contacts of all runs in one panel, and the same from 0.1 s on.
fn normal_force_panels(runs: &[RunSeries]) -> Vec<Panel> {
    let mut lines = Vec::new();
    for (k, r) in runs.iter().enumerate() {
        for (c, col) in r.normal_force.cols.iter().enumerate() {
            let contact = r
                .contacts
                .get(c)
                .cloned()
                .unwrap_or_else(|| format!("contact {}", c + 1));
            let line = Line::series(
                format!("{}, {contact}", r.name),
                color(k),
                &r.normal_force.t,
                col,
            );
            lines.push(Line {
                dashed: c % 2 == 1,
                ..line
            });
        }
    }
    let late = |l: &Line| Line {
        label: l.label.clone(),
        points: l.points.iter().copied().filter(|p| p.0 >= 0.1).collect(),
        dashed: l.dashed,
        ..Line::series(String::new(), l.color, &[], &[])
    };
    let late_lines = lines.iter().map(late).collect();
    let y = "normal force f_n [N]";
    let mut all = Panel::new(T_DESC, y, lines);
    all.subtitle = Some("whole run".into());
    let mut tail = Panel::new(T_DESC, y, late_lines);
    tail.subtitle = Some("from t = 0.1 s".into());
    for p in [&mut all, &mut tail] {
        p.zero_line = Some("f_n = 0 (below: the table pulls)".into());
        p.legend = SeriesLabelPosition::UpperRight;
        p.top_pad = 0.45;
    }
    vec![all, tail]
}
