//! The blueprint of a converted recording: which views, where, with which cameras.
//!
//! One run: left, the arm in 3D from the side (the table edge-on, so that an elbow below it
//! shows) above a close-up of the hand; right, a grid of plots: motor currents and voltages per
//! joint, the contact forces (and friction and modes when the contact model records them), the
//! contact events, energies per joint (E_j electric, W_j link work), the energy totals and the
//! balance residual. Several runs: one 3D view per run side by side, and below them tabs that
//! overlay the energy totals and the residual of every run (coloured by run), then one tab per
//! signal with a plot per run side by side.

use super::blueprint::{ContainerKind, Eye, Node, View, ViewClass};
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

pub use super::run::range_after_transient;

/// A plot of one run: title, entity root, fixed y range.
struct Plot {
    /// The signal ([`signal`]): plots of several runs with the same key go side by side.
    key: &'static str,
    title: String,
    origin: String,
    y_range: Option<[f64; 2]>,
}

impl Plot {
    fn node(&self, title: &str) -> Node {
        Node::View(View::new(ViewClass::TimeSeries, title, self.origin.clone()).y_range(self.y_range))
    }
}

/// The plots one run has.
fn plots(run: &Run, paths: &Paths) -> Vec<Plot> {
    let p = |key: &'static str, title: &str, y_range| Plot { key, title: title.to_string(), origin: paths.signal(key), y_range };
    // the y ranges are the whole run's (`Run::survey`)
    let r = run.whole.current_range;
    let title = if r.is_some() { "motor currents [A] (start-up transient off scale)" } else { "motor currents [A]" };
    let mut v = vec![p(signal::CURRENT, title, r)];
    if run.whole.has_voltage {
        let r = run.whole.voltage_range;
        let title = if r.is_some() { "motor voltages [V] (start-up transient off scale)" } else { "motor voltages [V]" };
        v.push(p(signal::VOLTAGE, title, r));
    }
    if !run.contacts.is_empty() {
        v.push(p(signal::NORMAL_FORCE, "contact normal forces f_n [N] (< 0: the table pulls)", None));
    }
    if run.whole.has_contact_states && !run.contacts.is_empty() {
        v.push(p(signal::FRICTION_FORCE, "friction forces |f_t| [N]", None));
        v.push(p(signal::CONTACT_MODE, "contact modes (0 separated, 1 sticking, 2 sliding, 3 bilateral)", Some([-0.2, 3.2])));
    }
    v.push(p(signal::ELECTRIC_ENERGY, "electric energy per motor E_j [J]", None));
    v.push(p(signal::LINK_WORK, "link work per joint W_j [J]", None));
    v
}

/// The blueprint of one run (entities as [`super::entities::run_chunks`] made them).
pub fn single(run: &Run, paths: &Paths, bounds: &Bounds) -> Node {
    let world = paths.world();
    let arm = View::new(ViewClass::Spatial3D, "arm, side view", &world).eye(side_eye(bounds));
    let hand = View::new(ViewClass::Spatial3D, "hand close-up (purple: actual, orange: target)", &world).eye(hand_eye(bounds));
    let mut grid: Vec<Node> = plots(run, paths).iter().map(|p| p.node(&p.title)).collect();
    grid.push(plot("energy totals [J]", format!("/{}", signal::ENERGY)));
    grid.push(plot("energy balance residual [J]", paths.signal(signal::RESIDUAL)));
    if run.whole.has_events {
        grid.push(Node::View(View::new(ViewClass::TextLog, "contact events", format!("{}/events", paths.prefix))));
    }
    Node::container(
        ContainerKind::Horizontal,
        vec![
            Node::container(ContainerKind::Vertical, vec![Node::View(arm), Node::View(hand)]).shares(&[3.0, 2.0]),
            Node::container(ContainerKind::Grid, grid),
        ],
    )
    .shares(&[1.0, 1.3])
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
