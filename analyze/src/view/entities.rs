//! What one run shows in Rerun: its entities, as chunks (archetypes of `rerun.archetypes`,
//! field names and component types as the 0.41 SDK writes them; see [`super::chunk`]).
//!
//! Entity paths (`P` = the run's prefix: empty for one recording, `/<run>` for a comparison):
//! - 3D, below `P/world` (z up): the `/tf` frame tree, one entity per frame nested like the
//!   frames (`P/world/base_link/link1/…`, `Transform3D` per sample), each link's URDF visuals
//!   (`…/visual0`, static `Cylinders3D` / `Boxes3D` / `Ellipsoids3D`), the table
//!   (`P/world/table0`: a thin translucent box whose top face is the contact plane), the target
//!   path (`P/world/target_path`, the desired hand positions as a line strip), the hand's trail
//!   (`P/world/hand_trail`), the hand now (`P/world/hand/actual`, `…/desired`, points larger
//!   than the hand sphere), and per contact a marker (`P/world/contacts/<c>`) and the force on
//!   the arm (`…/<c>/force`, an arrow), coloured by mode;
//! - signals, named by joint or contact, the unit in the first path part
//!   (`/current_A/<joint>`, `/voltage_V/<joint>`, `/normal_force_N/<contact>`,
//!   `/friction_force_N/<contact>`, `/contact_mode/<contact>`, `/electric_energy_J/<joint>`,
//!   `/link_work_J/<joint>`; for a comparison the run comes second: `/current_A/<run>/<joint>`);
//!   the energy totals `/energy_J/<term>[/<run>]` and the balance residual
//!   `/energy_residual_J[/<run>]` (the recorded `E − (ΔT + ΔV + ΔL i²/2 + losses)`, see
//!   `crate::metrics`), so that one view can overlay a term over runs;
//! - contact events as a text log (`P/events`).
//!
//! Colours: joints and contacts take the Tableau 10 palette in array order (the figures' order);
//! contact modes: separated grey, sticking green, sliding orange, bilateral pushing blue,
//! bilateral *pulling* (`f_n < 0`, what a real table cannot do) red.

use arrow_array::ArrayRef;

use super::chunk::{f32_lists, f64_each, quat_lists, rgba, str_lists, strip_lists, u32_lists, u8_lists, vec3_lists, Chunk, Index};
use super::pose::{quat_z_to, Pose};
use super::run::{escape, ns, Plane, Run};
use super::urdf::Shape;

const POINTS: &str = "rerun.archetypes.Points3D";
const ARROWS: &str = "rerun.archetypes.Arrows3D";
const STRIPS: &str = "rerun.archetypes.LineStrips3D";
const BOXES: &str = "rerun.archetypes.Boxes3D";
const CYLINDERS: &str = "rerun.archetypes.Cylinders3D";
const ELLIPSOIDS: &str = "rerun.archetypes.Ellipsoids3D";
const TRANSFORM: &str = "rerun.archetypes.Transform3D";
const SCALARS: &str = "rerun.archetypes.Scalars";
const SERIES: &str = "rerun.archetypes.SeriesLines";
const TEXT_LOG: &str = "rerun.archetypes.TextLog";
const VIEW_COORDINATES: &str = "rerun.archetypes.ViewCoordinates";

/// Tableau 10, in order.
pub const PALETTE: [[u8; 3]; 10] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
];

pub fn palette(k: usize) -> u32 {
    let [r, g, b] = PALETTE[k % PALETTE.len()];
    rgba(r, g, b, 255)
}

/// A colour of [`schemas::markers::colors`] (the one owner of the viewers' colours, so Rerun
/// and Foxglove draw the same thing in the same colour) as Rerun's packed RGBA.
fn shared(hex: &str) -> u32 {
    let [r, g, b, a] = schemas::markers::colors::rgba8(hex, 255);
    rgba(r, g, b, a)
}

/// The hand: actual purple, desired (the target) orange, as in Foxglove's `/contact_markers`.
fn hand_actual() -> u32 {
    shared(schemas::markers::colors::HAND_ACTUAL)
}
fn hand_desired() -> u32 {
    shared(schemas::markers::colors::HAND_DESIRED)
}
const TABLE: u32 = rgba(176, 140, 96, 70);
const ARM: u32 = rgba(170, 180, 200, 255);

/// A contact marker's colour: the mode the Foxglove markers give it ([`schemas::markers::MarkerMode`]:
/// a `/contacts` code, else a bilateral contact pushing or pulling by the sign of f_n).
fn mode_color(mode: Option<u32>, f_n: f64) -> u32 {
    use schemas::markers::MarkerMode;
    let marker = mode.map_or_else(|| MarkerMode::bilateral(f_n), |code| MarkerMode::from_code(code, f_n));
    shared(marker.hex())
}

fn f3(p: [f64; 3]) -> [f32; 3] {
    p.map(|x| x as f32)
}

fn q4(q: [f64; 4]) -> [f32; 4] {
    q.map(|x| x as f32)
}

/// Where one run's entities go.
#[derive(Debug, Clone)]
pub struct Paths {
    /// `""` or `/<run>`.
    pub prefix: String,
    /// `None` for a single run, `Some(run)` in a comparison.
    pub run: Option<String>,
    /// The run's place in a comparison (its colour in the overlaid totals).
    pub index: usize,
}

impl Paths {
    pub fn world(&self) -> String {
        format!("{}/world", self.prefix)
    }

    /// `/<signal>[/<run>]`.
    pub fn signal(&self, signal: &str) -> String {
        match &self.run {
            Some(r) => format!("/{signal}/{}", escape(r)),
            None => format!("/{signal}"),
        }
    }
}

/// The signal groups and their entity names (the first path part; the unit after `_`).
pub mod signal {
    pub const CURRENT: &str = "current_A";
    pub const VOLTAGE: &str = "voltage_V";
    pub const NORMAL_FORCE: &str = "normal_force_N";
    pub const FRICTION_FORCE: &str = "friction_force_N";
    pub const CONTACT_MODE: &str = "contact_mode";
    pub const ELECTRIC_ENERGY: &str = "electric_energy_J";
    pub const LINK_WORK: &str = "link_work_J";
    pub const ENERGY: &str = "energy_J";
    pub const RESIDUAL: &str = "energy_residual_J";
}

/// The energy totals: entity name, series label, and how to get it from `/energy`.
pub const ENERGY_TERMS: [(&str, &str, fn(&schemas::EnergyState) -> f64); 8] = [
    ("electric-in", "electric energy in, Σ E_j", |e| e.electric_energy_total),
    ("link-work", "link work, Σ W_j", |e| e.link_work_total),
    ("kinetic", "kinetic T", |e| e.kinetic),
    ("potential", "potential V", |e| e.potential),
    ("magnetic", "magnetic L i²/2", |e| e.magnetic),
    ("resistive-loss", "resistive loss", |e| e.resistive_loss),
    ("friction-loss", "friction loss (joints D and gears D_m)", |e| e.friction_loss),
    ("gear-friction-loss", "gear friction loss", |e| e.gear_friction_loss),
];

/// A time series: `Scalars` per sample plus its static `SeriesLines` style (name, colour).
fn series(path: String, times: &[i64], values: Vec<f64>, name: &str, color: u32, width: f32) -> [Chunk; 2] {
    [
        Chunk::new(&path, Index::SimTime(times.to_vec())).with(SCALARS, "scalars", "rerun.components.Scalar", f64_each(&values)),
        Chunk::new(&path, Index::Static)
            .with(SERIES, "colors", "rerun.components.Color", u32_lists(&[vec![color]]))
            .with(SERIES, "names", "rerun.components.Name", str_lists(&[vec![name.to_string()]]))
            .with(SERIES, "widths", "rerun.components.StrokeWidth", f32_lists(&[vec![width]])),
    ]
}

fn repeat<T: Clone>(x: T, n: usize) -> Vec<T> {
    vec![x; n]
}

/// What the views of a run need to know to place their cameras: bounds of the arm and the hand
/// path, m (world frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    pub arm_min: [f64; 3],
    pub arm_max: [f64; 3],
    pub hand_min: [f64; 3],
    pub hand_max: [f64; 3],
    /// The arm's base (the first frame below the root), at t = 0.
    pub base: [f64; 3],
}

/// Radius of the largest sphere among the URDF visuals (the hand's, in the paper's arm), m.
fn hand_sphere_radius(run: &Run) -> f64 {
    run.visuals
        .values()
        .flatten()
        .filter_map(|v| match v.shape {
            Shape::Sphere { radius_m } => Some(radius_m),
            _ => None,
        })
        .fold(0.0, f64::max)
}

/// Every chunk of `run` under `paths`, and the bounds of what it draws.
pub fn run_chunks(run: &Run, paths: &Paths) -> (Vec<Chunk>, Bounds) {
    let mut out = Vec::new();
    let world = paths.world();
    out.push(Chunk::new(&world, Index::Static).with(
        VIEW_COORDINATES,
        "xyz",
        "rerun.components.ViewCoordinates",
        // right-handed, z up: X = right (3), Y = forward (5), Z = up (1)
        {
            use arrow_array::builder::{FixedSizeListBuilder, UInt8Builder};
            let mut b = FixedSizeListBuilder::new(UInt8Builder::new(), 3)
                .with_field(std::sync::Arc::new(arrow_schema::Field::new("item", arrow_schema::DataType::UInt8, false)));
            b.values().append_slice(&[3, 5, 1]);
            b.append(true);
            let values: ArrayRef = std::sync::Arc::new(b.finish());
            let field = std::sync::Arc::new(arrow_schema::Field::new("item", values.data_type().clone(), true));
            std::sync::Arc::new(arrow_array::ListArray::new(field, arrow_buffer::OffsetBuffer::from_lengths([1]), values, None))
        },
    ));

    // the frame tree: transforms per sample
    let times = &run.tf_times_ns;
    for (name, frame) in &run.frames {
        let path = run.frame_path(name, &world);
        let translations: Vec<Vec<[f32; 3]>> = frame.in_parent.iter().map(|p| vec![f3(p.translation)]).collect();
        let rotations: Vec<Vec<[f32; 4]>> = frame.in_parent.iter().map(|p| vec![q4(p.rotation)]).collect();
        out.push(
            Chunk::new(&path, Index::SimTime(times.clone()))
                .with(TRANSFORM, "quaternion", "rerun.components.RotationQuat", quat_lists(&rotations))
                .with(TRANSFORM, "translation", "rerun.components.Translation3D", vec3_lists(&translations)),
        );
        // the link's visuals, static in the link frame
        for (k, v) in run.visuals.get(name).into_iter().flatten().enumerate() {
            let color = v.rgba.map_or(ARM, |c| {
                let b = |x: f64| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
                rgba(b(c[0]), b(c[1]), b(c[2]), b(c[3]))
            });
            let vpath = format!("{path}/visual{k}");
            let center = vec3_lists(&[vec![f3(v.origin.translation)]]);
            let colors = u32_lists(&[vec![color]]);
            let solid = u8_lists(&[vec![3]]);
            let chunk = Chunk::new(&vpath, Index::Static);
            let chunk = match v.shape {
                Shape::Box { size_m } => chunk
                    .with(BOXES, "centers", "rerun.components.Translation3D", center)
                    .with(BOXES, "colors", "rerun.components.Color", colors)
                    .with(BOXES, "fill_mode", "rerun.components.FillMode", solid)
                    .with(BOXES, "half_sizes", "rerun.components.HalfSize3D", vec3_lists(&[vec![f3(size_m.map(|s| s / 2.0))]]))
                    .with(BOXES, "quaternions", "rerun.components.RotationQuat", quat_lists(&[vec![q4(v.origin.rotation)]])),
                Shape::Cylinder { radius_m, length_m } => chunk
                    .with(CYLINDERS, "centers", "rerun.components.Translation3D", center)
                    .with(CYLINDERS, "colors", "rerun.components.Color", colors)
                    .with(CYLINDERS, "fill_mode", "rerun.components.FillMode", solid)
                    .with(CYLINDERS, "lengths", "rerun.components.Length", f32_lists(&[vec![length_m as f32]]))
                    .with(CYLINDERS, "quaternions", "rerun.components.RotationQuat", quat_lists(&[vec![q4(v.origin.rotation)]]))
                    .with(CYLINDERS, "radii", "rerun.components.Radius", f32_lists(&[vec![radius_m as f32]])),
                Shape::Sphere { radius_m } => chunk
                    .with(ELLIPSOIDS, "centers", "rerun.components.Translation3D", center)
                    .with(ELLIPSOIDS, "colors", "rerun.components.Color", colors)
                    .with(ELLIPSOIDS, "fill_mode", "rerun.components.FillMode", solid)
                    .with(ELLIPSOIDS, "half_sizes", "rerun.components.HalfSize3D", vec3_lists(&[vec![[radius_m as f32; 3]]])),
            };
            out.push(chunk);
        }
    }

    // the bounds are the whole run's (`Run::survey`); the contact points those of the window
    let w = &run.whole;
    let bounds = Bounds { arm_min: w.arm_min, arm_max: w.arm_max, hand_min: w.hand_min, hand_max: w.hand_max, base: w.base };
    let mut contact_points: Vec<Vec<[f64; 3]>> = vec![Vec::with_capacity(times.len()); run.contacts.len()];
    for k in 0..times.len() {
        let poses = run.world_poses(k);
        for (c, pts) in run.contacts.iter().zip(contact_points.iter_mut()) {
            if let Some(link) = &c.link {
                pts.push(poses.get(link.as_str()).map_or([0.0; 3], |p: &Pose| p.apply(c.offset_m)));
            }
        }
    }

    // the hand: path, trail (the whole run's), points now
    let hand_times: Vec<i64> = run.hand.iter().map(|(t, _)| ns(*t)).collect();
    let v3 = |v: &schemas::Vec3| [v.x, v.y, v.z];
    let desired: Vec<[f64; 3]> = run.hand.iter().map(|(_, h)| v3(&h.desired)).collect();
    let actual: Vec<[f64; 3]> = run.hand.iter().map(|(_, h)| v3(&h.actual)).collect();
    let r_hand = hand_sphere_radius(run);
    // larger than the hand sphere, so that the actual point shows around it
    let r_point = if r_hand > 0.0 { 1.35 * r_hand } else { 0.02 };
    if !run.hand.is_empty() {
        out.push(
            Chunk::new(format!("{world}/target_path"), Index::Static)
                .with(STRIPS, "colors", "rerun.components.Color", u32_lists(&[vec![hand_desired()]]))
                .with(STRIPS, "radii", "rerun.components.Radius", f32_lists(&[vec![0.002]]))
                .with(STRIPS, "strips", "rerun.components.LineStrip3D", strip_lists(&[vec![w.target_path.iter().copied().map(f3).collect()]])),
        );
        out.push(
            Chunk::new(format!("{world}/hand_trail"), Index::Static)
                .with(STRIPS, "colors", "rerun.components.Color", u32_lists(&[vec![hand_actual()]]))
                .with(STRIPS, "radii", "rerun.components.Radius", f32_lists(&[vec![0.0015]]))
                .with(STRIPS, "strips", "rerun.components.LineStrip3D", strip_lists(&[vec![w.hand_trail.iter().copied().map(f3).collect()]])),
        );
        for (name, pts, color, label, r) in
            [("actual", &actual, hand_actual(), "hand (actual)", r_point), ("desired", &desired, hand_desired(), "target (desired)", 0.75 * r_point)]
        {
            out.push(
                Chunk::new(format!("{world}/hand/{name}"), Index::SimTime(hand_times.clone()))
                    .with(POINTS, "positions", "rerun.components.Position3D", vec3_lists(&pts.iter().map(|p| vec![f3(*p)]).collect::<Vec<_>>())),
            );
            out.push(
                Chunk::new(format!("{world}/hand/{name}"), Index::Static)
                    .with(POINTS, "colors", "rerun.components.Color", u32_lists(&[vec![color]]))
                    .with(POINTS, "labels", "rerun.components.Text", str_lists(&[vec![label.to_string()]]))
                    .with(POINTS, "radii", "rerun.components.Radius", f32_lists(&[vec![r as f32]])),
            );
        }
    }

    // the table: every contact plane, a thin translucent box whose top face is the plane,
    // covering the arm's reach
    let mut planes: Vec<Plane> = Vec::new();
    for p in run.contacts.iter().filter_map(|c| c.plane).chain(run.other_planes.iter().copied()) {
        if !planes.contains(&p) {
            planes.push(p);
        }
    }
    for (k, plane) in planes.iter().enumerate() {
        let n = plane.normal;
        let norm = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-12);
        let n = n.map(|x| x / norm);
        let d = plane.offset_m / norm;
        let q = quat_z_to(n);
        // the arm's bounds, projected on the plane: centre and half extent
        let c = [0, 1, 2].map(|i| 0.5 * (bounds.arm_min[i] + bounds.arm_max[i]));
        let half = [0, 1, 2].map(|i| 0.5 * (bounds.arm_max[i] - bounds.arm_min[i])).iter().fold(0.0f64, |a, b| a.max(*b)) + 0.15;
        let dist = n[0] * c[0] + n[1] * c[1] + n[2] * c[2] - d;
        let on_plane = [0, 1, 2].map(|i| c[i] - dist * n[i]);
        let thickness = 0.01;
        let center = [0, 1, 2].map(|i| on_plane[i] - 0.5 * thickness * n[i]);
        out.push(
            Chunk::new(format!("{world}/table{k}"), Index::Static)
                .with(BOXES, "centers", "rerun.components.Translation3D", vec3_lists(&[vec![f3(center)]]))
                .with(BOXES, "colors", "rerun.components.Color", u32_lists(&[vec![TABLE]]))
                .with(BOXES, "fill_mode", "rerun.components.FillMode", u8_lists(&[vec![4]]))
                .with(BOXES, "half_sizes", "rerun.components.HalfSize3D", vec3_lists(&[vec![[half as f32, half as f32, (0.5 * thickness) as f32]]]))
                .with(BOXES, "labels", "rerun.components.Text", str_lists(&[vec!["table".to_string()]]))
                .with(BOXES, "quaternions", "rerun.components.RotationQuat", quat_lists(&[vec![q4(q)]])),
        );
    }

    // contacts: marker and force arrow per sample, coloured by mode
    let (f_n, f_t, modes) = contact_forces(run);
    // the largest force after the start-up transient (the first 5 % of the samples, where an
    // impulse-like peak would shrink every arrow) is drawn 0.25 m long (`Run::survey`)
    let scale = w.force_scale;
    let force_times: Vec<i64> = if run.contact_states.is_some() {
        run.contact_states.iter().flatten().map(|(t, _)| ns(*t)).collect()
    } else {
        run.constraints.iter().map(|(t, _)| ns(*t)).collect()
    };
    let n_rows = force_times.len().min(times.len());
    for (ci, c) in run.contacts.iter().enumerate() {
        if contact_points[ci].len() < n_rows {
            continue; // where it acts is unknown: plots only
        }
        let base = format!("{world}/contacts/{}", escape(&c.name));
        let norm = c.plane.map_or([0.0, 0.0, 1.0], |p| p.normal);
        let mut colors = Vec::with_capacity(n_rows);
        let mut origins = Vec::with_capacity(n_rows);
        let mut vectors = Vec::with_capacity(n_rows);
        for k in 0..n_rows {
            let fn_k = f_n[ci][k];
            let mode = modes.as_ref().map(|m| m[ci][k]);
            colors.push(vec![mode_color(mode, fn_k)]);
            let p = contact_points[ci][k];
            origins.push(vec![f3(p)]);
            let mut f = norm.map(|x| x * fn_k);
            if let (Some((t1, t2)), Some(ft)) = (c.tangents, f_t.get(ci)) {
                let (a, b) = ft.get(2 * k).copied().zip(ft.get(2 * k + 1).copied()).unwrap_or((0.0, 0.0));
                f = [0, 1, 2].map(|i| f[i] + a * t1[i] + b * t2[i]);
            }
            vectors.push(vec![f3(f.map(|x| x * scale))]);
        }
        let ft = Index::SimTime(force_times[..n_rows].to_vec());
        out.push(
            Chunk::new(&base, ft.clone())
                .with(POINTS, "colors", "rerun.components.Color", u32_lists(&colors))
                .with(POINTS, "positions", "rerun.components.Position3D", vec3_lists(&origins)),
        );
        out.push(
            Chunk::new(&base, Index::Static)
                .with(POINTS, "labels", "rerun.components.Text", str_lists(&[vec![c.name.clone()]]))
                .with(POINTS, "radii", "rerun.components.Radius", f32_lists(&[vec![(0.6 * r_point) as f32]])),
        );
        out.push(
            Chunk::new(format!("{base}/force"), ft)
                .with(ARROWS, "colors", "rerun.components.Color", u32_lists(&colors))
                .with(ARROWS, "origins", "rerun.components.Position3D", vec3_lists(&origins))
                .with(ARROWS, "vectors", "rerun.components.Vector3D", vec3_lists(&vectors)),
        );
        out.push(Chunk::new(format!("{base}/force"), Index::Static).with(ARROWS, "radii", "rerun.components.Radius", f32_lists(&[vec![0.006]])));
    }

    // contact events
    if !run.events.is_empty() {
        let t: Vec<i64> = run.events.iter().map(|(t, _)| ns(*t)).collect();
        let text: Vec<Vec<String>> = run
            .events
            .iter()
            .map(|(_, e)| {
                let mut s = format!("{}: {}", e.contact, e.kind);
                if e.impulse != 0.0 || e.energy_lost != 0.0 {
                    s.push_str(&format!(" (impulse {:.3} N·s, {:.3} J lost)", e.impulse, e.energy_lost));
                }
                vec![s]
            })
            .collect();
        let n = t.len();
        out.push(
            Chunk::new(format!("{}/events", paths.prefix), Index::SimTime(t))
                .with(TEXT_LOG, "level", "rerun.components.TextLogLevel", str_lists(&repeat(vec!["INFO".to_string()], n)))
                .with(TEXT_LOG, "text", "rerun.components.Text", str_lists(&text)),
        );
    }

    out.extend(signal_chunks(run, paths, &f_n, &f_t, modes.as_deref()));
    (out, bounds)
}

/// Per contact and sample: normal force, friction components `(t1, t2)` interleaved, and mode
/// (when `/contacts` is recorded; bilateral runs have `/constraints` only).
#[allow(clippy::type_complexity)]
fn contact_forces(run: &Run) -> (Vec<Vec<f64>>, Vec<Vec<f64>>, Option<Vec<Vec<u32>>>) {
    let nc = run.contacts.len();
    match &run.contact_states {
        Some(states) => {
            let mut f_n = vec![Vec::with_capacity(states.len()); nc];
            let mut f_t = vec![Vec::with_capacity(2 * states.len()); nc];
            let mut modes = vec![Vec::with_capacity(states.len()); nc];
            for (_, s) in states {
                for c in 0..nc {
                    f_n[c].push(s.normal_force[c]);
                    f_t[c].push(s.friction_force_t1.get(c).copied().unwrap_or(0.0));
                    f_t[c].push(s.friction_force_t2.get(c).copied().unwrap_or(0.0));
                    modes[c].push(s.mode[c]);
                }
            }
            (f_n, f_t, Some(modes))
        }
        None => {
            let mut f_n = vec![Vec::with_capacity(run.constraints.len()); nc];
            for (_, s) in &run.constraints {
                for c in 0..nc {
                    f_n[c].push(s.normal_force[c]);
                }
            }
            (f_n, Vec::new(), None)
        }
    }
}

/// The typed scalar entities of a run ([`signal`]).
fn signal_chunks(run: &Run, paths: &Paths, f_n: &[Vec<f64>], f_t: &[Vec<f64>], modes: Option<&[Vec<u32>]>) -> Vec<Chunk> {
    use signal::*;
    let mut out = Vec::new();
    let motor_t: Vec<i64> = run.motors.iter().map(|(t, _)| ns(*t)).collect();
    let energy_t: Vec<i64> = run.energy.iter().map(|(t, _)| ns(*t)).collect();
    let width = 1.5;
    for (j, joint) in run.joints.iter().enumerate() {
        let color = palette(j);
        let jp = escape(joint);
        let current = run.motors.iter().map(|(_, m)| m.current[j]).collect();
        out.extend(series(format!("{}/{jp}", paths.signal(CURRENT)), &motor_t, current, &format!("{joint} [A]"), color, width));
        if run.whole.voltage_every_joint {
            let v = run.motors.iter().map(|(_, m)| m.voltage[j]).collect();
            out.extend(series(format!("{}/{jp}", paths.signal(VOLTAGE)), &motor_t, v, &format!("{joint} [V]"), color, width));
        }
        let e = run.energy.iter().map(|(_, e)| e.electric_energy[j]).collect();
        out.extend(series(format!("{}/{jp}", paths.signal(ELECTRIC_ENERGY)), &energy_t, e, &format!("E {joint} [J]"), color, width));
        let w = run.energy.iter().map(|(_, e)| e.link_work[j]).collect();
        out.extend(series(format!("{}/{jp}", paths.signal(LINK_WORK)), &energy_t, w, &format!("W {joint} [J]"), color, width));
    }
    let force_t: Vec<i64> = match &run.contact_states {
        Some(s) => s.iter().map(|(t, _)| ns(*t)).collect(),
        None => run.constraints.iter().map(|(t, _)| ns(*t)).collect(),
    };
    for (c, contact) in run.contacts.iter().enumerate() {
        // contacts after the joints in the palette's order would repeat joint colours: start at
        // the far end
        let color = palette(PALETTE.len() - 1 - c % PALETTE.len());
        let cp = escape(&contact.name);
        out.extend(series(format!("{}/{cp}", paths.signal(NORMAL_FORCE)), &force_t, f_n[c].clone(), &format!("{} f_n [N]", contact.name), color, width));
        if let Some(ft) = f_t.get(c).filter(|v| !v.is_empty()) {
            let mag = ft.chunks(2).map(|p| (p[0] * p[0] + p[1] * p[1]).sqrt()).collect();
            out.extend(series(format!("{}/{cp}", paths.signal(FRICTION_FORCE)), &force_t, mag, &format!("{} |f_t| [N]", contact.name), color, width));
        }
        if let Some(m) = modes {
            let v = m[c].iter().map(|&x| f64::from(x)).collect();
            out.extend(series(
                format!("{}/{cp}", paths.signal(CONTACT_MODE)),
                &force_t,
                v,
                &format!("{} mode (0 separated, 1 sticking, 2 sliding)", contact.name),
                color,
                width,
            ));
        }
    }
    // totals and the residual: `/energy_J/<term>[/<run>]`
    let term_path = |term: &str| match &paths.run {
        Some(r) => format!("/{ENERGY}/{term}/{}", escape(r)),
        None => format!("/{ENERGY}/{term}"),
    };
    for (k, (term, label, get)) in ENERGY_TERMS.iter().enumerate() {
        let v = run.energy.iter().map(|(_, e)| get(e)).collect();
        let name = match &paths.run {
            Some(r) => format!("{r}: {label} [J]"),
            None => format!("{label} [J]"),
        };
        let color = if paths.run.is_some() { palette(paths.index) } else { palette(k) };
        out.extend(series(term_path(term), &energy_t, v, &name, color, width));
    }
    let residual = run.energy.iter().map(|(_, e)| e.balance_residual).collect();
    let name = match &paths.run {
        Some(r) => format!("{r}: balance residual [J]"),
        None => "balance residual E − (ΔT + ΔV + ΔL i²/2 + losses) [J]".to_string(),
    };
    let color = if paths.run.is_some() { palette(paths.index) } else { rgba(90, 90, 90, 255) };
    out.extend(series(paths.signal(RESIDUAL), &energy_t, residual, &name, color, width));
    out
}
