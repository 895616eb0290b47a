//! The blueprint of a converted recording: which views, where, with which cameras.
//!
//! One run (issue 27: readable at 1440×900 and 1920×1080, at most three plots to a tab, short
//! titles, legends in the corner the data leaves empty, [`legend_corner`]): tabs
//! - "arm": the arm in 3D from the side (the table edge-on, so that an elbow below it shows),
//!   beside a close-up of the hand above the contact normal forces;
//! - "motors": currents above voltages, per joint;
//! - "slip / stick" (runs with unilateral or compliant contacts): slip speed `|v_t|`,
//!   `|f_t|/(μ f_n)` (1 = on the friction cone) and the mode per contact;
//! - "friction, events" (same runs): the friction forces above the contact events table, full
//!   width (the events also mark the time panel);
//! - "energy": the totals above E_j (electric, per motor) and W_j (link work, per joint);
//! - "balance": the balance residual alone, on a y range fitted to it ([`residual_range`]).
//!
//! Several runs: one 3D view per run side by side, and below them tabs that overlay the energy
//! totals and the residual of every run (coloured by run), then one tab per signal with a plot
//! per run side by side.

use super::blueprint::{ContainerKind, Corner, Eye, Node, View, ViewClass};
use super::entities::{signal, Bounds, Paths};
use super::run::{escape, Envelope, Run};

fn center(min: [f64; 3], max: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| 0.5 * (min[i] + max[i]))
}

fn extent(min: [f64; 3], max: [f64; 3]) -> f64 {
    [0, 1, 2].map(|i| max[i] - min[i]).iter().fold(0.0f64, |a, b| a.max(*b))
}

/// The horizontal direction to look from for a side view: perpendicular to the line from the
/// arm's base to its hand path (so the arm lies across the picture), on the −y side; −y when
/// the hand is above the base.
fn side_direction(b: &Bounds) -> [f64; 3] {
    let h = center(b.hand_min, b.hand_max);
    let (ux, uy) = (h[0] - b.base[0], h[1] - b.base[1]);
    let n = (ux * ux + uy * uy).sqrt();
    if n < 1e-3 {
        return [0.0, -1.0, 0.0];
    }
    let (px, py) = (-uy / n, ux / n);
    if py > 0.0 {
        [-px, -py, 0.0]
    } else {
        [px, py, 0.0]
    }
}

/// A side view of the arm: across its reach, a little above the table, looking at the middle
/// of everything it sweeps.
pub fn side_eye(b: &Bounds) -> Eye {
    let c = center(b.arm_min, b.arm_max);
    // far enough that the whole arm, base to hand, fits a 3D view about as wide as high (the
    // arm tab at 1440×900: 1.05 cut the base and the hand off)
    let d = 1.5 * extent(b.arm_min, b.arm_max) + 0.2;
    let s = side_direction(b);
    Eye { position: [c[0] + d * s[0], c[1] + d * s[1], c[2] + 0.15 * d], look_target: c, up: [0.0, 0.0, 1.0] }
}

/// Whether the arm sweeps a flat band (its height less than half its width, as the paper's arm
/// lying over its table): then the side view is drawn wide and short, across the whole tab.
pub fn is_flat(b: &Bounds) -> bool {
    let w = (b.arm_max[0] - b.arm_min[0]).max(b.arm_max[1] - b.arm_min[1]);
    b.arm_max[2] - b.arm_min[2] < 0.5 * w
}

/// The side view of a flat arm in a wide, short view (about 3:1 at 1440×900 and 3.5:1 at
/// 1920×1080; Rerun's vertical field of view is 55°, so the view's width is about 3 × 2 tan
/// 27.5° ≈ 3.1 × the distance): near enough that the arm's width fills about three quarters
/// of it and its height at most 60 % of the view's, from the same side and height as [`side_eye`]
/// (the 1.05 × extent side view of a square view left its upper half empty).
pub fn wide_side_eye(b: &Bounds) -> Eye {
    let c = center(b.arm_min, b.arm_max);
    let s = side_direction(b);
    // the bounds' extents across the view and along it (the camera stands in front of the
    // nearest part, not of the middle)
    let (dx, dy) = (b.arm_max[0] - b.arm_min[0], b.arm_max[1] - b.arm_min[1]);
    let (across, depth) = (s[1].abs() * dx + s[0].abs() * dy, s[0].abs() * dx + s[1].abs() * dy);
    let h = b.arm_max[2] - b.arm_min[2];
    // (the depth counted 0.3: half the bounding box's depth left the paper arm, which lies
    // across the view, a third of the view's width in the 1440×900 screenshot; a tenth cut off
    // the nearest body of the contact-shapes demo, whose bodies stand apart in depth)
    let d = (0.4 * across).max(1.6 * h) + 0.3 * depth + 0.1;
    Eye { position: [c[0] + d * s[0], c[1] + d * s[1], c[2] + 0.15 * d], look_target: c, up: [0.0, 0.0, 1.0] }
}

/// A close-up of the hand path, from the same side and a little above.
pub fn hand_eye(b: &Bounds) -> Eye {
    let c = center(b.hand_min, b.hand_max);
    let d = (1.6 * extent(b.hand_min, b.hand_max)).max(0.25);
    let s = side_direction(b);
    Eye { position: [c[0] + d * s[0], c[1] + d * s[1], c[2] + 0.6 * d], look_target: c, up: [0.0, 0.0, 1.0] }
}

fn plot(name: &str, origin: String) -> Node {
    Node::View(View::new(ViewClass::TimeSeries, name, origin))
}

pub use super::run::range_after_transient;

/// The corner of a plot whose legend covers the fewest samples: each corner's box (a third of
/// the time axis, the top or bottom third of the y range shown, `y_range` or the envelope's)
/// counts the columns of the [`Envelope`] with a sample in it; the first of left top, right
/// top, left bottom, right bottom with the fewest wins.
pub fn legend_corner(envelope: &Envelope, y_range: Option<[f64; 2]>) -> Corner {
    let Some([lo, hi]) = y_range.or_else(|| envelope.range()) else { return Corner::LeftTop };
    if hi.is_nan() || lo.is_nan() || hi <= lo {
        return Corner::LeftTop;
    }
    let n = envelope.columns.len() as f64;
    let mut counts = [0usize; 4];
    for (k, [c_lo, c_hi]) in envelope.columns.iter().enumerate().filter(|(_, c)| c[0] <= c[1]) {
        let x = (k as f64 + 0.5) / n;
        let (left, right) = (x <= 1.0 / 3.0, x >= 2.0 / 3.0);
        // a sample in the top (bottom) third: the column's highest (lowest) one is
        let top = (c_hi - lo) / (hi - lo) >= 2.0 / 3.0;
        let bottom = (c_lo - lo) / (hi - lo) <= 1.0 / 3.0;
        for (i, hit) in [left && top, right && top, left && bottom, right && bottom].into_iter().enumerate() {
            counts[i] += usize::from(hit);
        }
    }
    let best = (0..4).min_by_key(|&k| counts[k]).unwrap_or(0);
    [Corner::LeftTop, Corner::RightTop, Corner::LeftBottom, Corner::RightBottom][best]
}

/// The y range of the balance residual whose largest magnitude is `max_abs`, J: symmetric
/// about 0, 1.2 times it (so the line is drawn across the plot even when it is 1e-12 J),
/// `[-1, 1]` J when it is 0.
pub fn residual_range(max_abs: f64) -> [f64; 2] {
    if max_abs > 0.0 && max_abs.is_finite() {
        [-1.2 * max_abs, 1.2 * max_abs]
    } else {
        [-1.0, 1.0]
    }
}

/// A plot of one run: title, entity root, fixed y range.
struct Plot {
    /// The signal ([`signal`]): plots of several runs with the same key go side by side.
    key: &'static str,
    title: String,
    origin: String,
    y_range: Option<[f64; 2]>,
    legend: Corner,
}

impl Plot {
    fn node(&self, title: &str) -> Node {
        Node::View(View::new(ViewClass::TimeSeries, title, self.origin.clone()).y_range(self.y_range).legend(self.legend))
    }
}

/// The plots one run has: only those with data in the recording (a plot whose [`Envelope`]
/// stayed empty is left out: no voltages when none are recorded, no `|f_t|/(μ f_n)` when no
/// contact has friction or none pushes, no slip plot without `/contacts`).
fn plots(run: &Run, paths: &Paths) -> Vec<Plot> {
    let p = |key: &'static str, title: &str, y_range, env: &Envelope| Plot {
        key,
        title: title.to_string(),
        origin: paths.signal(key),
        y_range,
        legend: legend_corner(env, y_range),
    };
    // the y ranges and the legends' corners are the whole run's (`Run::survey`)
    let w = &run.whole;
    let e = &w.envelopes;
    let mut v = Vec::new();
    if !e.current.is_empty() {
        let r = w.current_range;
        let title = if r.is_some() { "currents [A] (start-up off scale)" } else { "currents [A]" };
        v.push(p(signal::CURRENT, title, r, &e.current));
    }
    if w.voltage_every_joint && !e.voltage.is_empty() {
        let r = w.voltage_range;
        let title = if r.is_some() { "voltages [V] (start-up off scale)" } else { "voltages [V]" };
        v.push(p(signal::VOLTAGE, title, r, &e.voltage));
    }
    if !run.contacts.is_empty() && !e.normal_force.is_empty() {
        v.push(p(signal::NORMAL_FORCE, "normal force f_n [N] (< 0: pull)", None, &e.normal_force));
    }
    if w.has_contact_states && !run.contacts.is_empty() {
        if !e.slip_speed.is_empty() {
            v.push(p(signal::SLIP_SPEED, "slip speed |v_t| [m/s]", None, &e.slip_speed));
        }
        if !e.friction_ratio.is_empty() {
            v.push(p(signal::FRICTION_RATIO, "|f_t| / (μ f_n) (1: sliding)", Some([0.0, 1.2]), &e.friction_ratio));
        }
        if !e.friction_force.is_empty() {
            v.push(p(signal::FRICTION_FORCE, "friction |f_t| [N]", None, &e.friction_force));
        }
        if !e.contact_mode.is_empty() {
            v.push(p(signal::CONTACT_MODE, "mode (0 sep., 1 stick, 2 slide)", Some([-0.2, 3.2]), &e.contact_mode));
        }
    }
    if !e.electric_energy.is_empty() {
        v.push(p(signal::ELECTRIC_ENERGY, "E_j electric [J]", None, &e.electric_energy));
    }
    if !e.link_work.is_empty() {
        v.push(p(signal::LINK_WORK, "W_j link work [J]", None, &e.link_work));
    }
    v
}

fn column(children: Vec<Node>) -> Node {
    Node::container(ContainerKind::Vertical, children)
}

fn row(children: Vec<Node>) -> Node {
    Node::container(ContainerKind::Horizontal, children)
}

/// The blueprint of one run (entities as [`super::entities::run_chunks`] made them).
pub fn single(run: &Run, paths: &Paths, bounds: &Bounds) -> Node {
    let world = paths.world();
    // the colours in the title (no labels on the hand points: on the target they overlapped)
    let title = "arm (hand purple, target orange)";
    let flat = is_flat(bounds);
    let arm = View::new(ViewClass::Spatial3D, title, &world).eye(if flat { wide_side_eye(bounds) } else { side_eye(bounds) });
    let hand = View::new(ViewClass::Spatial3D, "hand (purple) and target (orange)", &world).eye(hand_eye(bounds));
    let mut all = plots(run, paths);
    let mut take = |key: &str| all.iter().position(|p| p.key == key).map(|k| all.remove(k)).map(|p| p.node(&p.title));
    let mut tabs = Vec::new();
    let mut side = vec![Node::View(hand)];
    side.extend(take(signal::NORMAL_FORCE));
    tabs.push(if flat {
        // a flat arm: wide and short across the tab, the hand and the forces below it
        column(vec![Node::View(arm), row(side)]).shares(&[3.0, 2.0]).named("arm")
    } else {
        row(vec![Node::View(arm), column(side)]).shares(&[3.0, 2.0]).named("arm")
    });
    let motors: Vec<Node> = [signal::CURRENT, signal::VOLTAGE].iter().filter_map(|k| take(k)).collect();
    tabs.push(column(motors).named("motors"));
    let slip: Vec<Node> = [signal::SLIP_SPEED, signal::FRICTION_RATIO, signal::CONTACT_MODE].iter().filter_map(|k| take(k)).collect();
    if !slip.is_empty() {
        tabs.push(column(slip).named("slip / stick"));
    }
    // friction forces above the events table (full width, so its times are not cut)
    let mut contacts: Vec<Node> = take(signal::FRICTION_FORCE).into_iter().collect();
    if run.whole.has_events {
        contacts.push(Node::View(View::new(ViewClass::TextLog, "contact events", format!("{}/events", paths.prefix))));
    }
    if !contacts.is_empty() {
        let shares: &[f32] = if contacts.len() == 2 { &[1.0, 1.0] } else { &[1.0] };
        tabs.push(column(contacts).shares(shares).named("friction, events"));
    }
    let totals = View::new(ViewClass::TimeSeries, "energy totals [J]", format!("/{}", signal::ENERGY)).legend(Corner::LeftTop);
    let per_joint: Vec<Node> = [signal::ELECTRIC_ENERGY, signal::LINK_WORK].iter().filter_map(|k| take(k)).collect();
    tabs.push(column(vec![Node::View(totals), row(per_joint)]).named("energy"));
    let balance = View::new(ViewClass::TimeSeries, "balance residual [J]", paths.signal(signal::RESIDUAL))
        .y_range(Some(residual_range(run.whole.residual_max_abs)))
        .legend(Corner::RightBottom);
    tabs.push(column(vec![Node::View(balance)]).named("balance"));
    Node::container(ContainerKind::Tabs, tabs)
}

/// The blueprint of several runs side by side.
pub fn comparison(runs: &[(&Run, &Paths, &Bounds)]) -> Node {
    let scenes: Vec<Node> = runs
        .iter()
        .map(|(_, p, b)| {
            let name = p.run.clone().unwrap_or_default();
            Node::View(View::new(ViewClass::Spatial3D, name, p.world()).eye(side_eye(b)))
        })
        .collect();
    let mut tabs = vec![Node::container(
        ContainerKind::Horizontal,
        vec![
            plot("electric energy in, Σ E_j [J], all runs", format!("/{}/electric-in", signal::ENERGY)),
            plot("link work Σ W_j [J], all runs", format!("/{}/link-work", signal::ENERGY)),
            plot("energy balance residual [J], all runs", format!("/{}", signal::RESIDUAL)),
        ],
    )
    .named("energy, all runs")];
    // per signal: one plot per run, titled by the first run's plot
    let mut keys: Vec<(&'static str, String)> = Vec::new();
    for (run, paths, _) in runs {
        for p in plots(run, paths) {
            if !keys.iter().any(|(k, _)| *k == p.key) {
                keys.push((p.key, p.title));
            }
        }
    }
    for (key, title) in keys {
        let per_run: Vec<Node> = runs
            .iter()
            .filter_map(|(run, paths, _)| {
                plots(run, paths).into_iter().find(|p| p.key == key).map(|p| p.node(&format!("{}: {}", paths.run.as_deref().unwrap_or(""), p.title)))
            })
            .collect();
        tabs.push(Node::container(ContainerKind::Horizontal, per_run).named(&title));
    }
    Node::container(ContainerKind::Vertical, vec![Node::container(ContainerKind::Horizontal, scenes), Node::container(ContainerKind::Tabs, tabs)])
        .shares(&[1.2, 1.0])
}

/// The entity prefix of run `label` in a comparison.
pub fn prefix(label: &str) -> String {
    format!("/{}", escape(label))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::view::chunk::Chunk;
    use crate::view::run::Envelope;

    /// The envelope of `samples` over their time span.
    fn envelope(samples: &[(f64, Vec<f64>)]) -> Envelope {
        let mut e = Envelope::new(samples[0].0, samples[samples.len() - 1].0);
        for (t, v) in samples {
            e.push(*t, v.iter().copied());
        }
        e
    }

    /// A growing series leaves the left-top corner empty; a falling one the right-top... and
    /// the residual range is symmetric, 1.2 times the largest magnitude.
    #[test]
    fn legends_go_where_the_data_is_not() {
        let rising: Vec<(f64, Vec<f64>)> = (0..100).map(|k| (k as f64, vec![k as f64])).collect();
        assert_eq!(legend_corner(&envelope(&rising), None), Corner::LeftTop);
        let falling: Vec<(f64, Vec<f64>)> = (0..100).map(|k| (k as f64, vec![-(k as f64)])).collect();
        assert_eq!(legend_corner(&envelope(&falling), None), Corner::RightTop);
        // one series high everywhere, one low until 60 % of the run: the bottom right is empty
        let high: Vec<(f64, Vec<f64>)> = (0..100).map(|k| (k as f64, vec![if k < 70 { 1.0 } else { 0.9 }, 0.5 * f64::from(u8::from(k >= 60))])).collect();
        assert_eq!(legend_corner(&envelope(&high), None), Corner::RightBottom);
        // on a y range that puts the rising line in the top third from the start: the bottom
        // corners are empty, left bottom first
        assert_eq!(legend_corner(&envelope(&rising), Some([-200.0, 10.0])), Corner::LeftBottom);
        assert_eq!(legend_corner(&Envelope::new(0.0, 1.0), None), Corner::LeftTop);
        assert_eq!(residual_range(3e-12), [-1.2 * 3e-12, 1.2 * 3e-12]);
        assert_eq!(residual_range(0.0), [-1.0, 1.0]);
    }

    /// The run of the synthetic recording `s` with every sample, its chunks and its blueprint.
    fn laid_out(s: &schemas::synth::Synth) -> (Run, Vec<Chunk>, Node) {
        let dir = tempfile::tempdir().unwrap();
        let input = super::super::read_input(&s.write_in(dir.path())).unwrap();
        let run = super::super::window::whole_run(&input.path, &input.run).unwrap();
        let paths = Paths { prefix: String::new(), run: None, index: 0 };
        let (chunks, bounds) = super::super::entities::run_chunks(&run, &paths);
        let root = single(&run, &paths, &bounds);
        (run, chunks, root)
    }

    /// One run: tabs, at most three views to a tab, the slip / stick tab for a unilateral run
    /// with |f_t|/(mu f_n) on [0, 1.2], the residual on its fitted range.
    #[test]
    fn one_run_is_laid_out_in_readable_tabs() {
        let (s, _) = schemas::synth::unilateral();
        let (run, _, root) = laid_out(&s);
        let Node::Container { kind: ContainerKind::Tabs, children, .. } = &root else { panic!("not tabs: {root:?}") };
        let names: Vec<String> = children
            .iter()
            .map(|c| match c {
                Node::Container { name, .. } => name.clone().unwrap_or_default(),
                Node::View(v) => v.name.clone(),
            })
            .collect();
        assert_eq!(names[..2], ["arm", "motors"]);
        assert!(names.contains(&"slip / stick".to_string()) && names.contains(&"balance".to_string()), "{names:?}");
        for c in children {
            assert!(c.views().len() <= 3, "{:?}", c.views().iter().map(|v| &v.name).collect::<Vec<_>>());
        }
        let views = root.views();
        let ratio = views.iter().find(|v| v.origin == format!("/{}", signal::FRICTION_RATIO)).expect("the friction ratio plot");
        assert_eq!(ratio.y_range, Some([0.0, 1.2]));
        let res = views.iter().find(|v| v.origin == format!("/{}", signal::RESIDUAL)).unwrap();
        let r = run.energy.iter().map(|(_, e)| e.balance_residual.abs()).fold(0.0, f64::max);
        assert_eq!(res.y_range, Some(residual_range(r)));
        assert!(views.iter().all(|v| v.name.chars().count() <= 36), "{:?}", views.iter().map(|v| &v.name).collect::<Vec<_>>());
    }

    /// `--tab`: the blueprint opens on the tab named (its `active_tab` is that child), an
    /// unknown name is refused with the tab names, and without it the first tab is active.
    #[test]
    fn the_blueprint_opens_on_the_tab_asked_for() {
        use super::super::blueprint::chunks;
        use arrow_array::Array;
        let (s, _) = schemas::synth::unilateral();
        let (_, _, root) = laid_out(&s);
        let active = |root: &Node| -> (String, Vec<String>) {
            let cs = chunks(root, 7);
            let tabs = cs.iter().find(|c| c.columns.iter().any(|col| col.field == "active_tab")).expect("a tab container");
            let get = |field: &str| -> Vec<String> {
                let col = tabs.columns.iter().find(|col| col.field == field).unwrap();
                let list = col.values.as_any().downcast_ref::<arrow_array::ListArray>().unwrap().value(0);
                let strs = list.as_any().downcast_ref::<arrow_array::StringArray>().unwrap();
                (0..strs.len()).map(|k| strs.value(k).to_string()).collect()
            };
            (get("active_tab")[0].clone(), get("contents"))
        };
        let (first, contents) = active(&root);
        assert_eq!(first, contents[0]);
        let names = root.tab_names();
        let k = names.iter().position(|n| n == "slip / stick").expect("a slip / stick tab");
        let (slip, contents) = active(&root.clone().open_on("slip / stick").unwrap());
        assert_eq!(slip, contents[k]);
        assert_eq!(root.open_on("nope").unwrap_err(), names);
    }

    /// The time series views of `root` whose origin has no sample in `chunks` (no temporal
    /// chunk with rows at the origin or below it).
    fn empty_plots(root: &Node, chunks: &[Chunk]) -> Vec<String> {
        root.views()
            .iter()
            .filter(|v| v.class == ViewClass::TimeSeries)
            .filter(|v| !chunks.iter().any(|c| !c.is_static() && c.rows > 0 && (c.entity_path == v.origin || c.entity_path.starts_with(&format!("{}/", v.origin)))))
            .map(|v| format!("{} ({})", v.name, v.origin))
            .collect()
    }

    /// Layouts with only the series the recording has (issue 27 item 4): every plot of the
    /// blueprint has samples in the run's entities, for a unilateral run, the same without a
    /// friction coefficient or without a contact that pushes (no |f_t|/(μ f_n) plot: the
    /// layout of before had one, empty), and a bilateral run without `/contacts`
    /// or voltages (no slip / stick tab, no friction, no voltages); a plot for each signal the
    /// run records.
    #[test]
    fn every_plot_has_data_and_only_what_is_recorded_is_plotted() {
        let has = |root: &Node, key: &str| root.views().iter().any(|v| v.origin == format!("/{key}"));
        let (s, _) = schemas::synth::unilateral();
        let (_, chunks, root) = laid_out(&s);
        assert_eq!(empty_plots(&root, &chunks), Vec::<String>::new());
        for key in [signal::CURRENT, signal::VOLTAGE, signal::NORMAL_FORCE, signal::SLIP_SPEED, signal::FRICTION_RATIO, signal::FRICTION_FORCE, signal::CONTACT_MODE, signal::RESIDUAL] {
            assert!(has(&root, key), "{key}");
        }

        let (mut s, _) = schemas::synth::unilateral();
        for c in &mut s.contacts_record.as_mut().unwrap().contacts {
            c.friction = None;
        }
        let (_, chunks, root) = laid_out(&s);
        assert_eq!(empty_plots(&root, &chunks), Vec::<String>::new());
        assert!(!has(&root, signal::FRICTION_RATIO) && has(&root, signal::SLIP_SPEED));

        // friction, but no contact ever pushes (f_n = 0 throughout): |f_t|/(μ f_n) has no sample
        let (mut s, _) = schemas::synth::unilateral();
        let f = s.contacts.take().unwrap();
        s.contacts = Some(Box::new(move |t| schemas::ContactState { normal_force: vec![0.0; 2], mode: vec![0; 2], ..f(t) }));
        let (_, chunks, root) = laid_out(&s);
        assert_eq!(empty_plots(&root, &chunks), Vec::<String>::new());
        assert!(!has(&root, signal::FRICTION_RATIO) && has(&root, signal::FRICTION_FORCE));

        // a bilateral run whose `/motors` records no voltages
        let mut s = schemas::synth::Synth::new("bilateral", &["elbow4"], 3);
        s.motors = Some(Box::new(|t| schemas::MotorState { current: vec![t, -t, 2.0 * t], ..Default::default() }));
        let (_, chunks, root) = laid_out(&s);
        assert_eq!(empty_plots(&root, &chunks), Vec::<String>::new());
        for key in [signal::SLIP_SPEED, signal::FRICTION_RATIO, signal::FRICTION_FORCE, signal::CONTACT_MODE, signal::VOLTAGE] {
            assert!(!has(&root, key), "{key}");
        }
        assert!(has(&root, signal::NORMAL_FORCE));
        let Node::Container { children, .. } = &root else { panic!() };
        assert!(children.iter().all(|c| !matches!(c, Node::Container { name: Some(n), .. } if n == "slip / stick")));
    }
}
