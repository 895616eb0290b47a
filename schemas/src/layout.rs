//! The Foxglove layout of a scene's recordings: a 3D panel (the URDF from
//! [`topics::ROBOT_DESCRIPTION`], `/tf`, [`topics::SCENE`], [`topics::CONTACT_MARKERS`],
//! [`topics::HAND_POINTS`] with a trail, a side-view camera) and plots of the motor currents and
//! voltages per joint, the contact forces (and modes, for runs with non-bilateral contacts), the
//! energies per joint and in total, the energy balance residual and the hand error, each series
//! labelled with its joint or contact name and its unit ([`crate::units`]).
//!
//! The format is Foxglove's layout JSON, as the last open-source Foxglove Studio and its fork
//! Lichtblick (<https://github.com/lichtblick-suite/lichtblick>, commit `66adecb`) define it:
//! - the file: `LayoutData` = `{configById, layout, globalVariables, playbackConfig, userNodes}`
//!   (`packages/suite-base/src/context/CurrentLayoutContext/actions.ts`), `playbackConfig` =
//!   `{speed}` (`packages/suite-base/src/types/panels.ts`); `layout` is a react-mosaic tree:
//!   a panel id, or `{direction: "row" | "column", first, second, splitPercentage}`; a panel id is
//!   `<type>!<id>` (`3D!…`, `Plot!…`);
//! - a Plot panel: `PlotConfig` (`packages/suite-base/src/panels/Plot/utils/config.ts`):
//!   `paths: [{value, enabled, timestampMethod: "receiveTime" | "headerStamp", label, color}]`
//!   (a value that parses as a number is a reference line), `showLegend`, `legendDisplay`,
//!   `showPlotValuesInLegend`, `showXAxisLabels`, `showYAxisLabels`, `isSynced`, `xAxisVal:
//!   "timestamp"`, `sidebarDimension`, optional `yAxisLabel`; message paths are `/topic.field[k]`;
//! - a 3D panel: `RendererConfig` (`packages/suite-base/src/panels/ThreeDeeRender/IRenderer.ts`),
//!   every key optional in a saved layout (merged over defaults in `ThreeDeeRender.tsx`):
//!   `cameraState` (`camera.ts`: distance, perspective, phi and thetaOffset in degrees, target,
//!   targetOffset, targetOrientation, fovy, near, far), `followMode`, `followTf`, `scene`,
//!   `topics` (topic → `{visible, …}`; point clouds take `pointSize` in px, `decayTime` in s,
//!   `colorMode`: `pointExtensionUtils.ts`, `colorMode.ts`), `layers` (instance id → `{layerId:
//!   "foxglove.Grid", …}`: `renderables/Grids.ts`), `transforms`, `publish`, `imageMode`. A topic
//!   `/robot_description` with schema `std_msgs/msg/String` is the URDF source
//!   (`renderables/Urdfs.ts`): `topics["/robot_description"].visible` switches it on.
//!
//! Panel titles are set under both keys the two apps read (`foxglovePanelTitle`,
//! `lichtblickPanelTitle`: `packages/suite-base/src/util/layout.ts`).

use serde_json::{json, Value};

use crate::{markers::colors, topics, units};

/// The series of one run that a layout describes: what the recordings of a scene (or one
/// recording) have.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LayoutRun {
    /// The run's name.
    pub run: String,
    /// Its contact names, in array order of `/constraints` and `/contacts`.
    pub contacts: Vec<String>,
    /// It records `/contacts` (a non-bilateral contact: modes, friction).
    pub has_contact_topic: bool,
    /// Per entry of `contacts`, whether it has friction (μ > 0, non-bilateral); the run records
    /// `/contact_friction` when one has. Empty: none has.
    pub frictional: Vec<bool>,
    /// It has at least one `/contact_events` message (the topic exists only then).
    pub has_contact_events: bool,
}

impl LayoutRun {
    /// It records `/contact_friction`.
    pub fn has_friction_topic(&self) -> bool {
        self.frictional.iter().any(|&f| f)
    }
}

/// What [`foxglove`] lays out.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LayoutInput {
    /// A title (the scene's name).
    pub title: String,
    /// Joint names, in array order of `/motors` and `/energy` (the same in every run of a scene).
    pub joint_names: Vec<String>,
    /// The runs the layout is for (their contacts may differ).
    pub runs: Vec<LayoutRun>,
    /// Where the 3D camera looks, world frame, m (the middle of the target path).
    pub focus: [f64; 3],
    /// How far the camera stands from `focus`, m (about twice the arm's reach).
    pub camera_distance_m: f64,
}

/// A 10-colour palette for series (Matplotlib's `tab10`, the figures' own).
const PALETTE: [&str; 10] = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"];

fn path(value: String, label: String, color: &str) -> Value {
    json!({"value": value, "enabled": true, "timestampMethod": "receiveTime", "label": label, "color": color})
}

fn unit(topic: &str, field: &str) -> &'static str {
    units::unit(topic, field).unwrap_or("1")
}

/// A plot panel; its legend above the plot (`legendDisplay: "top"`) for up to four series, in
/// a sidebar on the left for more (never floating over the data).
fn plot(title: &str, y_label: &str, paths: Vec<Value>) -> Value {
    let series = paths.iter().filter(|p| p["value"].as_str().is_some_and(|v| v.starts_with('/'))).count();
    let (legend, sidebar) = if series <= 4 { ("top", 240) } else { ("left", 170) };
    json!({
        "paths": paths,
        "showLegend": true,
        "legendDisplay": legend,
        "showPlotValuesInLegend": false,
        "showXAxisLabels": true,
        "showYAxisLabels": true,
        "isSynced": true,
        "xAxisVal": "timestamp",
        "sidebarDimension": sidebar,
        "yAxisLabel": y_label,
        "foxglovePanelTitle": title,
        "lichtblickPanelTitle": title,
    })
}

/// A path per joint of the array `field` of `topic`, labelled `<joint> <what> [unit]`.
fn per_joint(input: &LayoutInput, topic: &str, field: &str, what: &str) -> Vec<Value> {
    let u = unit(topic, field);
    input
        .joint_names
        .iter()
        .enumerate()
        .map(|(j, name)| path(format!("{topic}.{field}[{j}]"), format!("{name} {what} [{u}]"), PALETTE[j % PALETTE.len()]))
        .collect()
}

/// The name of entry `k` of the contact arrays of `topic` over the runs that record `topic`:
/// the name when they agree, else each run's name for it.
fn contact_label(input: &LayoutInput, k: usize, contact_topic: bool) -> String {
    let runs: Vec<&LayoutRun> = input.runs.iter().filter(|r| r.has_contact_topic == contact_topic && k < r.contacts.len()).collect();
    let first = runs.first().map(|r| r.contacts[k].as_str()).unwrap_or("");
    if runs.iter().all(|r| r.contacts[k] == first) {
        return first.to_string();
    }
    // each name once, with the runs that give entry k that name
    let mut names: Vec<(&str, Vec<&str>)> = Vec::new();
    for r in &runs {
        let n = r.contacts[k].as_str();
        match names.iter_mut().find(|(m, _)| *m == n) {
            Some((_, rs)) => rs.push(&r.run),
            None => names.push((n, vec![&r.run])),
        }
    }
    names.iter().map(|(n, rs)| format!("{n} in {}", rs.join(", "))).collect::<Vec<_>>().join("; ")
}

/// How many entries the contact arrays of the runs that record `/contacts` (or not) have, at most.
fn contact_count(input: &LayoutInput, contact_topic: bool) -> usize {
    input.runs.iter().filter(|r| r.has_contact_topic == contact_topic).map(|r| r.contacts.len()).max().unwrap_or(0)
}

/// A reference line at 0 (the value parses as a number: `isReferenceLinePlotPathType`).
fn zero_line() -> Value {
    json!({"value": "0", "enabled": true, "timestampMethod": "receiveTime", "label": "0", "color": "#7f7f7f"})
}

/// A path of a State Transitions panel (`StateTransitionPath`,
/// `packages/suite-base/src/panels/StateTransitions/types.ts`): a band per value over time.
fn state_path(value: String, label: String, color: &str) -> Value {
    json!({"value": value, "enabled": true, "timestampMethod": "receiveTime", "label": label, "color": color})
}

/// A State Transitions panel (`StateTransitionConfig`): the mode of each contact as coloured
/// bands on the plots' time axis (synced with them), each change marked by a point.
fn state_transitions(paths: Vec<Value>) -> Value {
    json!({
        "paths": paths,
        "isSynced": true,
        "showPoints": true,
        "foxglovePanelTitle": "Modes (0 sep. 1 stick 2 slide)",
        "lichtblickPanelTitle": "Modes (0 sep. 1 stick 2 slide)",
    })
}

/// A panel (plot, state transitions, table): its id, config and the tab it goes in.
struct PlotPanel {
    id: String,
    tab: &'static str,
    config: Value,
}

/// The tabs of the plots, in order (a tab without plots is left out); the unilateral and
/// compliant contacts' forces get their own tab when bilateral ones share the layout.
const TABS: [&str; 7] = ["motors", "contacts", "contacts (unilateral)", "slip / stick", "events", "energy", "balance"];

/// The plot panels, in layout order: only series the runs record (a contact index that no run
/// has is not plotted; a scene's layout, [`foxglove`], is for runs with the same topics).
fn plots(input: &LayoutInput) -> Vec<PlotPanel> {
    let mut out = Vec::new();
    let mut add = |id: &str, tab: &'static str, config: Value| out.push(PlotPanel { id: id.to_string(), tab, config });
    add("Plot!currents", "motors", plot("Currents", "current [A]", per_joint(input, topics::MOTORS, "current", "i")));
    add("Plot!voltages", "motors", plot("Voltages", "voltage [V]", per_joint(input, topics::MOTORS, "voltage", "v")));
    // bilateral runs: /constraints; blue above 0 (the table pushes), below 0 it pulls
    let nb = contact_count(input, false);
    if nb > 0 {
        let u = unit(topics::CONSTRAINTS, "normal_force");
        let mut paths: Vec<Value> = (0..nb)
            .map(|k| {
                path(
                    format!("{}.normal_force[{k}]", topics::CONSTRAINTS),
                    format!("{} f_n [{u}]", contact_label(input, k, false)),
                    PALETTE[k % PALETTE.len()],
                )
            })
            .collect();
        paths.push(zero_line());
        add("Plot!constraint_forces", "contacts", plot("Normal forces (< 0: pull)", "force [N]", paths));
    }
    let nu = contact_count(input, true);
    if nu > 0 {
        let t = topics::CONTACTS;
        let (mut normal, mut friction, mut modes) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..nu {
            let name = contact_label(input, k, true);
            let c = PALETTE[k % PALETTE.len()];
            normal.push(path(format!("{t}.normal_force[{k}]"), format!("{name} f_n [{}]", unit(t, "normal_force")), c));
            for (field, what) in [("friction_force_t1", "f_t1"), ("friction_force_t2", "f_t2")] {
                friction.push(path(format!("{t}.{field}[{k}]"), format!("{name} {what} [{}]", unit(t, field)), c));
            }
            modes.push(state_path(format!("{t}.mode[{k}]"), format!("{name} mode"), c));
        }
        normal.push(zero_line());
        let tab = if nb > 0 { "contacts (unilateral)" } else { "contacts" };
        add("Plot!contact_forces", tab, plot("Normal forces", "force [N]", normal));
        add("Plot!friction_forces", tab, plot("Friction forces", "force [N]", friction));
        // slip / stick: what Foxglove cannot combine from /contacts, from /contact_friction
        // (the frictional contacts only), the mode bands and the events on one time axis
        let nf = input.runs.iter().filter(|r| r.has_contact_topic).map(|r| r.frictional.iter().rposition(|&f| f).map_or(0, |k| k + 1)).max().unwrap_or(0);
        let frictional = |k: usize| input.runs.iter().any(|r| r.has_contact_topic && r.frictional.get(k) == Some(&true));
        let f = topics::CONTACT_FRICTION;
        let (mut speed, mut used) = (Vec::new(), Vec::new());
        for k in (0..nf).filter(|&k| frictional(k)) {
            let name = contact_label(input, k, true);
            let c = PALETTE[k % PALETTE.len()];
            speed.push(path(format!("{f}.slip_speed[{k}]"), format!("{name} |v_t| [{}]", unit(f, "slip_speed")), c));
            used.push(path(format!("{f}.friction_use[{k}]"), format!("{name} |f_t|/(μ f_n)"), c));
        }
        if !speed.is_empty() {
            used.push(json!({"value": "1", "enabled": true, "timestampMethod": "receiveTime", "label": "1 (sliding)", "color": "#7f7f7f"}));
            add("Plot!slip_speed", "slip / stick", plot("Slip speed", "|v_t| [m/s]", speed));
            add("Plot!friction_use", "slip / stick", plot("Friction use (1: sliding)", "|f_t|/(μ f_n)", used));
        }
        let events = input.runs.iter().any(|r| r.has_contact_topic && r.has_contact_events);
        if events {
            let e = topics::CONTACT_EVENTS;
            modes.push(state_path(format!("{e}.kind"), "event (last kind)".into(), "#7f7f7f"));
            modes.push(state_path(format!("{e}.contact"), "event (contact)".into(), "#7f7f7f"));
        }
        add("StateTransitions!modes", "slip / stick", state_transitions(modes));
        if events {
            add("Table!events", "events", json!({"topicPath": topics::CONTACT_EVENTS, "foxglovePanelTitle": "Last contact event", "lichtblickPanelTitle": "Last contact event"}));
        }
    }
    add("Plot!energy_per_joint", "energy", plot("Electric energy per joint", "energy [J]", per_joint(input, topics::ENERGY, "electric_energy", "E")));
    let e = topics::ENERGY;
    let totals = [
        ("electric_energy_total", "E total (electric in)"),
        ("link_work_total", "W total (motors on links)"),
        ("kinetic", "kinetic"),
        ("potential", "potential"),
        ("magnetic", "magnetic"),
        ("resistive_loss", "winding loss (R)"),
        ("friction_loss", "friction loss (D + D_m)"),
    ];
    let paths = totals.iter().enumerate().map(|(k, (f, l))| path(format!("{e}.{f}"), format!("{l} [{}]", unit(e, f)), PALETTE[k])).collect();
    add("Plot!energy_totals", "energy", plot("Energy totals", "energy [J]", paths));
    add(
        "Plot!balance",
        "balance",
        plot("Balance residual", "residual [J]", vec![path(format!("{e}.balance_residual"), format!("residual [{}]", unit(e, "balance_residual")), PALETTE[3]), zero_line()]),
    );
    let h = topics::HAND;
    let paths = [("error_norm", "|r - r_d|"), ("error.x", "x error"), ("error.y", "y error"), ("error.z", "z error")]
        .iter()
        .enumerate()
        .map(|(k, (f, l))| path(format!("{h}.{f}"), format!("{l} [{}]", unit(h, f)), PALETTE[k]))
        .collect();
    add("Plot!hand_error", "balance", plot("Hand error", "error [m]", paths));
    out
}

/// The 3D panel's config: URDF on, `/tf`, the scene entities, the hand points with a trail, a
/// side view (camera on −y looking along +y, slightly from above) of `focus`.
fn three_d(input: &LayoutInput) -> Value {
    json!({
        "cameraState": {
            "distance": input.camera_distance_m,
            "perspective": true,
            // phi: angle from +z (90 = horizontal); thetaOffset: about +z, 0 looks along +y
            "phi": 80.0,
            "thetaOffset": 0.0,
            "target": [0.0, 0.0, 0.0],
            "targetOffset": input.focus,
            "targetOrientation": [0.0, 0.0, 0.0, 1.0],
            "fovy": 45.0,
            "near": 0.01,
            "far": 100.0
        },
        "followMode": "follow-none",
        "followTf": crate::markers::WORLD_FRAME,
        "scene": {"transforms": {"showLabel": false, "axisScale": 0.05}},
        "transforms": {},
        "topics": {
            topics::ROBOT_DESCRIPTION: {"visible": true},
            topics::SCENE: {"visible": true},
            topics::CONTACT_MARKERS: {"visible": true},
            topics::HAND_POINTS: {
                "visible": true,
                "pointSize": 6.0,
                "pointShape": "circle",
                // the trail: every point of the last 5 s (the paper's whole circle)
                "decayTime": 5.0,
                "colorMode": "rgba-fields"
            }
        },
        "layers": {
            "grid": {
                "visible": true,
                "layerId": "foxglove.Grid",
                "label": "Grid (0.1 m, in z = 0)",
                "instanceId": "grid",
                "frameId": crate::markers::WORLD_FRAME,
                "size": 2.0,
                "divisions": 20,
                "lineWidth": 1.0,
                "color": "#24824d80",
                "position": [0.0, 0.0, 0.0],
                "rotation": [0.0, 0.0, 0.0],
                "order": 1
            }
        },
        "foxglovePanelTitle": format!("{} in 3D (hand: actual {}, desired {})", input.title, colors::HAND_ACTUAL, colors::HAND_DESIRED),
        "lichtblickPanelTitle": format!("{} in 3D", input.title),
    })
}

/// A react-mosaic tree of `ids` split evenly in `direction` (`"row"` or `"column"`).
fn even_split(ids: &[String], direction: &str) -> Value {
    match ids {
        [] => Value::Null,
        [one] => Value::String(one.clone()),
        _ => {
            let half = ids.len() / 2;
            json!({
                "direction": direction,
                "first": even_split(&ids[..half], direction),
                "second": even_split(&ids[half..], direction),
                "splitPercentage": 100.0 * half as f64 / ids.len() as f64,
            })
        }
    }
}

/// The Foxglove layout (see the module docs): the 3D panel on the left (45 %), on the right a
/// Tab panel (`Tab!plots`, Foxglove's `TabPanelConfig`: `{activeTabIdx, tabs: [{title,
/// layout}]}`) with at most two plots per tab, one above the other (readable at 1440×900).
pub fn foxglove(input: &LayoutInput) -> Value {
    let plots = plots(input);
    let mut config = serde_json::Map::new();
    config.insert("3D!arm".into(), three_d(input));
    let mut tabs = Vec::new();
    for tab in TABS {
        let ids: Vec<String> = plots.iter().filter(|p| p.tab == tab).map(|p| p.id.clone()).collect();
        if !ids.is_empty() {
            tabs.push(json!({"title": tab, "layout": even_split(&ids, "column")}));
        }
    }
    for p in plots {
        config.insert(p.id, p.config);
    }
    config.insert("Tab!plots".into(), json!({"activeTabIdx": 0, "tabs": tabs}));
    json!({
        "configById": config,
        "globalVariables": {},
        "userNodes": {},
        "playbackConfig": {"speed": 1.0},
        "layout": {"direction": "row", "first": "3D!arm", "second": "Tab!plots", "splitPercentage": 45.0},
    })
}

/// Every panel id of `layout`: the leaves of its mosaic tree and of its Tab panels' trees.
pub fn panel_ids(layout: &Value) -> Vec<String> {
    fn leaves(v: &Value, configs: &Value, out: &mut Vec<String>) {
        match v {
            Value::String(s) => {
                out.push(s.clone());
                for t in configs[s.as_str()]["tabs"].as_array().into_iter().flatten() {
                    leaves(&t["layout"], configs, out);
                }
            }
            Value::Object(o) => {
                for k in ["first", "second"] {
                    if let Some(c) = o.get(k) {
                        leaves(c, configs, out);
                    }
                }
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    leaves(&layout["layout"], &layout["configById"], &mut out);
    out
}

/// Where the camera looks and from how far, for a hand that moves through `points` (world
/// frame, m) on an arm based at the origin: the middle of the box around the points and the
/// base, and 2.5 times that box's half diagonal (at least 0.5 m).
pub fn camera_for(points: &[[f64; 3]]) -> ([f64; 3], f64) {
    let (mut lo, mut hi) = ([0.0f64; 3], [0.0f64; 3]);
    for p in points.iter().filter(|p| p.iter().all(|x| x.is_finite())) {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let mid = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0, (lo[2] + hi[2]) / 2.0];
    let half = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt() / 2.0;
    (mid, (2.5 * half).max(0.5))
}

impl LayoutInput {
    /// The layout input of one recording: its scene, joint and contact names (metadata `run`),
    /// whether it has `/contacts`, and the camera from the desired hand positions of `/hand`
    /// (read `rec` with at least [`topics::HAND`]).
    pub fn from_recording(rec: &crate::Recording) -> Result<Self, crate::Error> {
        let run = rec.run()?;
        let desired: Vec<[f64; 3]> = rec
            .messages(topics::HAND)
            .unwrap_or(&[])
            .iter()
            .filter_map(|(_, m)| {
                let d = m.get("desired")?;
                let f = |k: &str| d.get(k).and_then(crate::Value::as_f64);
                Some([f("x")?, f("y")?, f("z")?])
            })
            .collect();
        let (focus, camera_distance_m) = camera_for(&desired);
        Ok(LayoutInput {
            title: run.scene.clone(),
            joint_names: run.joint_names.clone(),
            runs: vec![LayoutRun {
                run: run.run.clone(),
                contacts: run.contacts.clone(),
                has_contact_topic: rec.channel(topics::CONTACTS).is_some(),
                frictional: frictional(rec, &run.contacts)?,
                has_contact_events: rec.channel(topics::CONTACT_EVENTS).is_some(),
            }],
            focus,
            camera_distance_m,
        })
    }
}

/// Per contact of `names`, whether it is on `rec`'s `/contact_friction` (μ > 0 in the record
/// `contacts`); empty when the recording has no `/contact_friction`.
fn frictional(rec: &crate::Recording, names: &[String]) -> Result<Vec<bool>, crate::Error> {
    if rec.channel(topics::CONTACT_FRICTION).is_none() {
        return Ok(Vec::new());
    }
    let record = rec.record_opt::<crate::ContactsRecord>()?;
    let mu = |n: &String| record.as_ref().and_then(|r| r.contacts.iter().find(|c| &c.name == n)).and_then(|c| c.friction).unwrap_or(0.0);
    Ok(names.iter().map(|n| mu(n) > 0.0).collect())
}

/// The layout's file name for `name`: a recording's file stem (`sim` writes one beside each
/// recording, `<scene>-<run>.foxglove-layout.json`) or a scene's name (`analyze layout -o`).
pub fn file_name(name: &str) -> String {
    format!("{name}.foxglove-layout.json")
}

/// Every topic a layout names (its 3D panel's topics and its plots' paths' topics), sorted,
/// without duplicates.
pub fn topics_named(layout: &Value) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(configs) = layout.get("configById").and_then(Value::as_object) {
        for c in configs.values() {
            if let Some(t) = c.get("topics").and_then(Value::as_object) {
                out.extend(t.keys().cloned());
            }
            if let Some(t) = c.get("topicPath").and_then(Value::as_str) {
                out.push(t.to_string());
            }
            for p in c.get("paths").and_then(Value::as_array).into_iter().flatten() {
                let v = p.get("value").and_then(Value::as_str).unwrap_or("");
                if v.starts_with('/') {
                    out.push(v.split('.').next().unwrap_or(v).to_string());
                }
            }
        }
    }
    out.sort();
    out.dedup();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn input() -> LayoutInput {
        LayoutInput {
            title: "paper".into(),
            joint_names: (1..=3).map(|k| format!("joint{k}")).collect(),
            runs: vec![
                LayoutRun { run: "two".into(), contacts: vec!["elbow4".into(), "elbow7".into()], ..Default::default() },
                LayoutRun { run: "one".into(), contacts: vec!["elbow4".into()], ..Default::default() },
                LayoutRun {
                    run: "uni".into(),
                    contacts: vec!["joint3".into(), "elbow4".into()],
                    has_contact_topic: true,
                    frictional: vec![false, true],
                    has_contact_events: true,
                },
                LayoutRun { run: "uni2".into(), contacts: vec!["elbow4".into()], has_contact_topic: true, ..Default::default() },
            ],
            focus: [0.5, 0.0, 0.2],
            camera_distance_m: 3.0,
        }
    }

    /// Every panel of the mosaic tree has a config and every config is in the tree; labels carry
    /// names and units; contact entries that differ between runs say so.
    #[test]
    fn the_layout_is_consistent_and_labelled() {
        let l = foxglove(&input());
        let configs = l["configById"].as_object().unwrap();
        let mut ids = panel_ids(&l);
        let mut keys: Vec<String> = configs.keys().cloned().collect();
        ids.sort();
        keys.sort();
        assert_eq!(ids, keys);
        let currents = &configs["Plot!currents"]["paths"];
        assert_eq!(currents[1]["value"], "/motors.current[1]");
        assert_eq!(currents[1]["label"], "joint2 i [A]");
        let f = &configs["Plot!constraint_forces"]["paths"];
        assert_eq!(f[0]["label"], "elbow4 f_n [N]");
        assert_eq!(f[1]["label"], "elbow7 f_n [N]");
        let c = &configs["Plot!contact_forces"]["paths"];
        assert_eq!(c[0]["label"], "joint3 in uni; elbow4 in uni2 f_n [N]");
        assert_eq!(configs["3D!arm"]["topics"]["/robot_description"]["visible"], true);
        let named = topics_named(&l);
        for t in ["/contacts", "/constraints", "/motors", "/energy", "/hand", "/scene", "/contact_markers", "/hand_points", "/robot_description"] {
            assert!(named.contains(&t.to_string()), "{t}: {named:?}");
        }
    }

    /// Readable (issue 27): a Tab panel, at most two plots per tab, every plot in a tab, no
    /// legend over the data, short titles (at most 32 characters).
    #[test]
    fn the_layout_is_tabbed_and_readable() {
        let l = foxglove(&input());
        let configs = l["configById"].as_object().unwrap();
        let tabs = configs["Tab!plots"]["tabs"].as_array().unwrap();
        let titles: Vec<&str> = tabs.iter().map(|t| t["title"].as_str().unwrap()).collect();
        assert_eq!(titles, ["motors", "contacts", "contacts (unilateral)", "slip / stick", "events", "energy", "balance"]);
        let mut in_tabs = 0;
        for t in tabs {
            let mut ids = Vec::new();
            fn leaves(v: &Value, out: &mut Vec<String>) {
                match v {
                    Value::String(s) => out.push(s.clone()),
                    Value::Object(o) => {
                        leaves(&o["first"], out);
                        leaves(&o["second"], out);
                    }
                    _ => panic!("bad node {v}"),
                }
            }
            leaves(&t["layout"], &mut ids);
            let plots = ids.iter().filter(|i| i.starts_with("Plot!")).count();
            assert!(plots <= 2 && (1..=3).contains(&ids.len()), "{}: {ids:?}", t["title"]);
            in_tabs += plots;
        }
        let plots: Vec<(&String, &Value)> = configs.iter().filter(|(k, _)| k.starts_with("Plot!")).collect();
        assert_eq!(in_tabs, plots.len());
        for (id, c) in plots {
            assert_ne!(c["legendDisplay"], "floating", "{id}");
            let series = c["paths"].as_array().unwrap().iter().filter(|p| p["value"].as_str().unwrap().starts_with('/')).count();
            assert_eq!(c["legendDisplay"], if series <= 4 { "top" } else { "left" }, "{id}");
            assert!(c["foxglovePanelTitle"].as_str().unwrap().chars().count() <= 32, "{id}: {}", c["foxglovePanelTitle"]);
        }
        assert_eq!(l["layout"]["second"], "Tab!plots");
    }

    /// The slip/stick tab (issue 27 item 4): slip speed and friction use of the frictional
    /// contacts only (entry 1 of run `uni`: its joint3 has no friction), from
    /// `/contact_friction`; the mode of every contact of `/contacts` and the events as bands;
    /// the events table in a tab of its own. Without friction or events, none of theirs.
    #[test]
    fn the_slip_stick_tab_has_the_frictional_contacts_modes_and_events() {
        let l = foxglove(&input());
        let configs = l["configById"].as_object().unwrap();
        let values = |id: &str| -> Vec<String> { configs[id]["paths"].as_array().unwrap().iter().map(|p| p["value"].as_str().unwrap().to_string()).collect() };
        assert_eq!(values("Plot!slip_speed"), ["/contact_friction.slip_speed[1]"]);
        assert_eq!(values("Plot!friction_use"), ["/contact_friction.friction_use[1]", "1"]);
        assert_eq!(configs["Plot!friction_use"]["paths"][0]["label"], "elbow4 |f_t|/(μ f_n)");
        assert_eq!(values("StateTransitions!modes"), ["/contacts.mode[0]", "/contacts.mode[1]", "/contact_events.kind", "/contact_events.contact"]);
        assert_eq!(configs["StateTransitions!modes"]["isSynced"], true);
        assert_eq!(configs["Table!events"]["topicPath"], "/contact_events");
        let tabs = configs["Tab!plots"]["tabs"].as_array().unwrap();
        let slip = tabs.iter().find(|t| t["title"] == "slip / stick").unwrap();
        let mut ids = Vec::new();
        fn leaves(v: &Value, out: &mut Vec<String>) {
            match v {
                Value::String(s) => out.push(s.clone()),
                v => {
                    leaves(&v["first"], out);
                    leaves(&v["second"], out);
                }
            }
        }
        leaves(&slip["layout"], &mut ids);
        assert_eq!(ids, ["Plot!slip_speed", "Plot!friction_use", "StateTransitions!modes"]);
        assert!(topics_named(&l).contains(&"/contact_friction".to_string()) && topics_named(&l).contains(&"/contact_events".to_string()));

        let mut i = input();
        for r in &mut i.runs {
            r.frictional.clear();
            r.has_contact_events = false;
        }
        let l = foxglove(&i);
        let configs = l["configById"].as_object().unwrap();
        assert!(!configs.contains_key("Plot!slip_speed") && !configs.contains_key("Plot!friction_use") && !configs.contains_key("Table!events"));
        assert_eq!(configs["StateTransitions!modes"]["paths"].as_array().unwrap().len(), 2);
        let named = topics_named(&l);
        assert!(!named.contains(&"/contact_friction".to_string()) && !named.contains(&"/contact_events".to_string()), "{named:?}");
    }

    /// A scene without contacts has neither contact plot.
    #[test]
    fn no_contacts_no_contact_plots() {
        let mut i = input();
        i.runs = vec![LayoutRun { run: "free".into(), ..Default::default() }];
        let l = foxglove(&i);
        let configs = l["configById"].as_object().unwrap();
        assert!(!configs.contains_key("Plot!constraint_forces") && !configs.contains_key("Plot!contact_forces"));
        assert!(!topics_named(&l).contains(&"/contacts".to_string()));
    }
}
