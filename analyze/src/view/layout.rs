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

/// A side view of the arm: from −y, a little above, looking at the middle of its reach.
pub fn side_eye(b: &Bounds) -> Eye {
    let c = center(b.arm_min, b.arm_max);
    let d = 1.6 * extent(b.arm_min, b.arm_max) + 0.3;
    Eye { position: [c[0], c[1] - d, c[2] + 0.2 * d], look_target: c, up: [0.0, 0.0, 1.0] }
}

/// A close-up of the hand path, from the same side.
pub fn hand_eye(b: &Bounds) -> Eye {
    let c = center(b.hand_min, b.hand_max);
    let d = (2.0 * extent(b.hand_min, b.hand_max)).max(0.25);
    Eye { position: [c[0] + 0.3 * d, c[1] - d, c[2] + 0.5 * d], look_target: c, up: [0.0, 0.0, 1.0] }
}

fn plot(name: &str, origin: String) -> Node {
    Node::View(View::new(ViewClass::TimeSeries, name, origin))
}

/// The plots one run has, as `(title, signal entity root)`.
fn plots(run: &Run, paths: &Paths) -> Vec<(String, String)> {
    let mut v = vec![("motor currents [A]".to_string(), paths.signal(signal::CURRENT))];
    if run.motors.first().is_some_and(|(_, m)| !m.voltage.is_empty()) {
        v.push(("motor voltages [V]".into(), paths.signal(signal::VOLTAGE)));
    }
    if !run.contacts.is_empty() {
        v.push(("contact normal forces f_n [N] (< 0: the table pulls)".into(), paths.signal(signal::NORMAL_FORCE)));
    }
    if run.contact_states.is_some() && !run.contacts.is_empty() {
        v.push(("friction forces |f_t| [N]".into(), paths.signal(signal::FRICTION_FORCE)));
        v.push(("contact modes (0 separated, 1 sticking, 2 sliding)".into(), paths.signal(signal::CONTACT_MODE)));
    }
    v.push(("electric energy per motor E_j [J]".into(), paths.signal(signal::ELECTRIC_ENERGY)));
    v.push(("link work per joint W_j [J]".into(), paths.signal(signal::LINK_WORK)));
    v
}

/// The blueprint of one run (entities as [`super::entities::run_chunks`] made them).
pub fn single(run: &Run, paths: &Paths, bounds: &Bounds) -> Node {
    let world = paths.world();
    let arm = View::new(ViewClass::Spatial3D, "arm, side view", &world).eye(side_eye(bounds));
    let hand = View::new(ViewClass::Spatial3D, "hand close-up (orange: actual, green: target)", &world).eye(hand_eye(bounds));
    let mut grid: Vec<Node> = plots(run, paths).into_iter().map(|(name, origin)| plot(&name, origin)).collect();
    grid.push(plot("energy totals [J]", format!("/{}", signal::ENERGY)));
    grid.push(plot("energy balance residual [J]", paths.signal(signal::RESIDUAL)));
    if !run.events.is_empty() {
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
    // per signal: one plot per run
    let mut titles: Vec<String> = Vec::new();
    for (run, paths, _) in runs {
        for (title, _) in plots(run, paths) {
            if !titles.contains(&title) {
                titles.push(title);
            }
        }
    }
    for title in titles {
        let per_run: Vec<Node> = runs
            .iter()
            .filter_map(|(run, paths, _)| {
                plots(run, paths).into_iter().find(|(t, _)| *t == title).map(|(_, origin)| plot(&format!("{}: {title}", paths.run.as_deref().unwrap_or("")), origin))
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
