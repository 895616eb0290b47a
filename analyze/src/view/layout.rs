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
use super::run::{escape, Run};

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
    let d = 1.05 * extent(b.arm_min, b.arm_max) + 0.2;
    let s = side_direction(b);
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

/// A y range that leaves out a start-up transient: the range of the samples after the first
/// 5 % of the run, padded by 10 %, when the whole range is more than 3 times wider (else
/// `None`: the viewer fits every sample).
pub fn range_after_transient(samples: &[(f64, Vec<f64>)]) -> Option<[f64; 2]> {
    let t_end = samples.last()?.0;
    let t0 = samples.first()?.0;
    let skip = t0 + 0.05 * (t_end - t0);
    let span = |it: &mut dyn Iterator<Item = f64>| it.fold([f64::INFINITY, f64::NEG_INFINITY], |[a, b], x| [a.min(x), b.max(x)]);
    let [lo_all, hi_all] = span(&mut samples.iter().flat_map(|(_, v)| v.iter().copied()));
    let [lo, hi] = span(&mut samples.iter().filter(|(t, _)| *t >= skip).flat_map(|(_, v)| v.iter().copied()));
    if !(lo.is_finite() && hi.is_finite()) || hi_all - lo_all <= 3.0 * (hi - lo) {
        return None;
    }
    let pad = 0.1 * (hi - lo).max(1e-9);
    Some([lo - pad, hi + pad])
}

/// The corner of a plot whose legend covers the fewest samples: each corner's box (a third of
/// the time axis, the top or bottom third of the y range shown) is counted over every series;
/// the first of left top, right top, left bottom, right bottom with the fewest wins.
pub fn legend_corner(samples: &[(f64, Vec<f64>)], y_range: Option<[f64; 2]>) -> Corner {
    let (Some(first), Some(last)) = (samples.first(), samples.last()) else { return Corner::LeftTop };
    let (t0, t1) = (first.0, last.0);
    let [lo, hi] = y_range.unwrap_or_else(|| {
        samples.iter().flat_map(|(_, v)| v.iter().copied()).filter(|x| x.is_finite()).fold([f64::INFINITY, f64::NEG_INFINITY], |[a, b], x| [a.min(x), b.max(x)])
    });
    if !(hi > lo) || !(t1 > t0) {
        return Corner::LeftTop;
    }
    let mut counts = [0usize; 4];
    for (t, v) in samples {
        let x = (t - t0) / (t1 - t0);
        for y in v.iter().map(|y| (y - lo) / (hi - lo)) {
            let left = x <= 1.0 / 3.0;
            let right = x >= 2.0 / 3.0;
            let top = y >= 2.0 / 3.0;
            let bottom = y <= 1.0 / 3.0;
            for (k, hit) in [left && top, right && top, left && bottom, right && bottom].into_iter().enumerate() {
                counts[k] += usize::from(hit);
            }
        }
    }
    let best = (0..4).min_by_key(|&k| counts[k]).unwrap_or(0);
    [Corner::LeftTop, Corner::RightTop, Corner::LeftBottom, Corner::RightBottom][best]
}

/// The y range of the balance residual: symmetric about 0, 1.2 times its largest magnitude
/// (so the line is drawn across the plot even when it is 1e-12 J), `[-1, 1]` J when it is 0.
pub fn residual_range(residual: &[f64]) -> [f64; 2] {
    let m = residual.iter().filter(|x| x.is_finite()).fold(0.0f64, |a, x| a.max(x.abs()));
    if m > 0.0 {
        [-1.2 * m, 1.2 * m]
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

/// The plots one run has.
fn plots(run: &Run, paths: &Paths) -> Vec<Plot> {
    let p = |key: &'static str, title: &str, y_range, samples: &[(f64, Vec<f64>)]| Plot {
        key,
        title: title.to_string(),
        origin: paths.signal(key),
        y_range,
        legend: legend_corner(samples, y_range),
    };
    let currents: Vec<(f64, Vec<f64>)> = run.motors.iter().map(|(t, m)| (*t, m.current.clone())).collect();
    let r = range_after_transient(&currents);
    let title = if r.is_some() { "currents [A] (start-up off scale)" } else { "currents [A]" };
    let mut v = vec![p(signal::CURRENT, title, r, &currents)];
    if run.motors.first().is_some_and(|(_, m)| !m.voltage.is_empty()) {
        let volts: Vec<(f64, Vec<f64>)> = run.motors.iter().map(|(t, m)| (*t, m.voltage.clone())).collect();
        let r = range_after_transient(&volts);
        let title = if r.is_some() { "voltages [V] (start-up off scale)" } else { "voltages [V]" };
        v.push(p(signal::VOLTAGE, title, r, &volts));
    }
    if !run.contacts.is_empty() {
        let f: Vec<(f64, Vec<f64>)> = match &run.contact_states {
            Some(s) => s.iter().map(|(t, c)| (*t, c.normal_force.clone())).collect(),
            None => run.constraints.iter().map(|(t, c)| (*t, c.normal_force.clone())).collect(),
        };
        v.push(p(signal::NORMAL_FORCE, "normal force f_n [N] (< 0: pull)", None, &f));
    }
    if let Some(states) = run.contact_states.as_ref().filter(|_| !run.contacts.is_empty()) {
        let none: &[(f64, Vec<f64>)] = &[];
        let slip: Vec<(f64, Vec<f64>)> = states
            .iter()
            .map(|(t, s)| (*t, s.slip_velocity_t1.iter().zip(&s.slip_velocity_t2).map(|(a, b)| (a * a + b * b).sqrt()).collect()))
            .collect();
        v.push(p(signal::SLIP_SPEED, "slip speed |v_t| [m/s]", None, &slip));
        if run.contacts.iter().any(|c| c.friction.is_some_and(|m| m > 0.0)) {
            v.push(p(signal::FRICTION_RATIO, "|f_t| / (μ f_n) (1: sliding)", Some([0.0, 1.2]), none));
        }
        v.push(p(signal::FRICTION_FORCE, "friction |f_t| [N]", None, none));
        v.push(p(signal::CONTACT_MODE, "mode (0 sep., 1 stick, 2 slide)", Some([-0.2, 3.2]), none));
    }
    let e: Vec<(f64, Vec<f64>)> = run.energy.iter().map(|(t, e)| (*t, e.electric_energy.clone())).collect();
    v.push(p(signal::ELECTRIC_ENERGY, "E_j electric [J]", None, &e));
    let w: Vec<(f64, Vec<f64>)> = run.energy.iter().map(|(t, e)| (*t, e.link_work.clone())).collect();
    v.push(p(signal::LINK_WORK, "W_j link work [J]", None, &w));
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
    let arm = View::new(ViewClass::Spatial3D, "arm, side view", &world).eye(side_eye(bounds));
    let hand = View::new(ViewClass::Spatial3D, "hand (purple) and target (orange)", &world).eye(hand_eye(bounds));
    let mut all = plots(run, paths);
    let mut take = |key: &str| all.iter().position(|p| p.key == key).map(|k| all.remove(k)).map(|p| p.node(&p.title));
    let mut tabs = Vec::new();
    let mut side = vec![Node::View(hand)];
    side.extend(take(signal::NORMAL_FORCE));
    tabs.push(row(vec![Node::View(arm), column(side)]).shares(&[3.0, 2.0]).named("arm"));
    let motors: Vec<Node> = [signal::CURRENT, signal::VOLTAGE].iter().filter_map(|k| take(k)).collect();
    tabs.push(column(motors).named("motors"));
    let slip: Vec<Node> = [signal::SLIP_SPEED, signal::FRICTION_RATIO, signal::CONTACT_MODE].iter().filter_map(|k| take(k)).collect();
    if !slip.is_empty() {
        tabs.push(column(slip).named("slip / stick"));
    }
    // friction forces above the events table (full width, so its times are not cut)
    let mut contacts: Vec<Node> = take(signal::FRICTION_FORCE).into_iter().collect();
    if !run.events.is_empty() {
        contacts.push(Node::View(View::new(ViewClass::TextLog, "contact events", format!("{}/events", paths.prefix))));
    }
    if !contacts.is_empty() {
        let shares: &[f32] = if contacts.len() == 2 { &[1.0, 1.0] } else { &[1.0] };
        tabs.push(column(contacts).shares(shares).named("friction, events"));
    }
    let totals = View::new(ViewClass::TimeSeries, "energy totals [J]", format!("/{}", signal::ENERGY)).legend(Corner::LeftTop);
    let per_joint: Vec<Node> = [signal::ELECTRIC_ENERGY, signal::LINK_WORK].iter().filter_map(|k| take(k)).collect();
    tabs.push(column(vec![Node::View(totals), row(per_joint)]).named("energy"));
    let residual: Vec<f64> = run.energy.iter().map(|(_, e)| e.balance_residual).collect();
    let balance = View::new(ViewClass::TimeSeries, "balance residual [J]", paths.signal(signal::RESIDUAL)).y_range(Some(residual_range(&residual))).legend(Corner::RightBottom);
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

    /// A growing series leaves the left-top corner empty; a falling one the right-top... and
    /// the residual range is symmetric, 1.2 times the largest magnitude.
    #[test]
    fn legends_go_where_the_data_is_not() {
        let rising: Vec<(f64, Vec<f64>)> = (0..100).map(|k| (k as f64, vec![k as f64])).collect();
        assert_eq!(legend_corner(&rising, None), Corner::LeftTop);
        let falling: Vec<(f64, Vec<f64>)> = (0..100).map(|k| (k as f64, vec![-(k as f64)])).collect();
        assert_eq!(legend_corner(&falling, None), Corner::RightTop);
        // one series high everywhere, one low until 60 % of the run: the bottom right is empty
        let high: Vec<(f64, Vec<f64>)> = (0..100).map(|k| (k as f64, vec![if k < 70 { 1.0 } else { 0.9 }, 0.5 * f64::from(u8::from(k >= 60))])).collect();
        assert_eq!(legend_corner(&high, None), Corner::RightBottom);
        assert_eq!(residual_range(&[1e-12, -3e-12, 2e-12]), [-1.2 * 3e-12, 1.2 * 3e-12]);
        assert_eq!(residual_range(&[0.0, 0.0]), [-1.0, 1.0]);
    }

    /// One run: tabs, at most three views to a tab, the slip / stick tab for a unilateral run
    /// with |f_t|/(mu f_n) on [0, 1.2], the residual on its fitted range.
    #[test]
    fn one_run_is_laid_out_in_readable_tabs() {
        let dir = tempfile::tempdir().unwrap();
        let (s, _) = schemas::synth::unilateral();
        let input = super::super::read_input(&s.write_in(dir.path())).unwrap();
        let paths = Paths { prefix: String::new(), run: None, index: 0 };
        let (_, bounds) = super::super::entities::run_chunks(&input.run, &paths);
        let root = single(&input.run, &paths, &bounds);
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
        let r: Vec<f64> = input.run.energy.iter().map(|(_, e)| e.balance_residual).collect();
        assert_eq!(res.y_range, Some(residual_range(&r)));
        assert!(views.iter().all(|v| v.name.chars().count() <= 36), "{:?}", views.iter().map(|v| &v.name).collect::<Vec<_>>());
    }
}
