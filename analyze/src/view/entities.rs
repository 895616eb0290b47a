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

use super::chunk::{f32_lists, quat_lists, rgba, str_lists, strip_lists, u32_lists, u8_lists, vec3_lists, Chunk, Index};
use super::pose::{quat_z_to, Pose};
use super::run::{escape, ns, Plane, Run};
use super::urdf::Shape;
use super::contacts::{contact_chunks, contact_forces, shape_chunks, touch_point};
pub use super::signals::signal;
use super::signals::signal_chunks;

pub(super) const POINTS: &str = "rerun.archetypes.Points3D";
pub(super) const ARROWS: &str = "rerun.archetypes.Arrows3D";
pub(super) const STRIPS: &str = "rerun.archetypes.LineStrips3D";
const BOXES: &str = "rerun.archetypes.Boxes3D";
pub(super) const CAPSULES: &str = "rerun.archetypes.Capsules3D";
const TRANSFORM: &str = "rerun.archetypes.Transform3D";
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
pub(super) fn shared(hex: &str) -> u32 {
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
const TABLE: u32 = rgba(0x8c, 0x6d, 0x46, 70);
const ARM: u32 = rgba(170, 180, 200, 255);

pub(super) fn f3(p: [f64; 3]) -> [f32; 3] {
    p.map(|x| x as f32)
}

pub(super) fn q4(q: [f64; 4]) -> [f32; 4] {
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
            out.push(super::mesh::shape_chunk(&format!("{path}/visual{k}"), &v.origin, v.shape, color));
        }
    }

    // the contact shapes, static on their links (`schemas::markers::shape_glyphs`: what
    // Foxglove's `/scene` draws)
    let infos: Vec<(&str, &schemas::ContactShapeInfo)> = run.contacts.iter().filter_map(|c| c.shape.as_ref().map(|s| (c.name.as_str(), s))).collect();
    for g in schemas::markers::shape_glyphs(infos) {
        if run.frames.iter().any(|(n, _)| n == g.link()) || g.link() == run.root_frame {
            out.extend(shape_chunks(&format!("{}/contact_shape/{}", run.frame_path(g.link(), &world), escape(g.name())), &g));
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
                pts.push(poses.get(link.as_str()).map_or([0.0; 3], |p: &Pose| touch_point(c, p)));
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
        // the trail up to the current time: the actual positions so far (the whole run's,
        // `Run::survey`), re-logged at most TRAIL_UPDATES times over the run, each strip at most
        // TRAIL_POINTS points (bounded: a long run's trail is thinned, never a strip per sample
        // of every sample before it); this window's updates
        let window = (hand_times[0], hand_times[hand_times.len() - 1]);
        let (trail_t, trail) = trail_updates(&w.hand_trail_t, &w.hand_trail, window);
        out.push(
            Chunk::new(format!("{world}/hand_trail"), Index::SimTime(trail_t))
                .with(STRIPS, "strips", "rerun.components.LineStrip3D", strip_lists(&trail)),
        );
        out.push(
            Chunk::new(format!("{world}/hand_trail"), Index::Static)
                .with(STRIPS, "colors", "rerun.components.Color", u32_lists(&[vec![hand_actual()]]))
                .with(STRIPS, "radii", "rerun.components.Radius", f32_lists(&[vec![0.0015]])),
        );
        // no text labels: on its target the two labels overlapped; the views' titles name the
        // colours
        for (name, pts, color, r) in [("actual", &actual, hand_actual(), r_point), ("desired", &desired, hand_desired(), 0.75 * r_point)] {
            out.push(
                Chunk::new(format!("{world}/hand/{name}"), Index::SimTime(hand_times.clone()))
                    .with(POINTS, "positions", "rerun.components.Position3D", vec3_lists(&pts.iter().map(|p| vec![f3(*p)]).collect::<Vec<_>>())),
            );
            out.push(
                Chunk::new(format!("{world}/hand/{name}"), Index::Static)
                    .with(POINTS, "colors", "rerun.components.Color", u32_lists(&[vec![color]]))
                    .with(POINTS, "radii", "rerun.components.Radius", f32_lists(&[vec![r as f32]])),
            );
        }
    }

    // the table: the boxes of `/scene` (what Foxglove draws, the same size); for a recording
    // without them every contact plane, a thin translucent box whose top face is the plane,
    // covering the arm's reach
    let mut planes: Vec<Plane> = Vec::new();
    for p in run.contacts.iter().filter_map(|c| c.plane).chain(run.other_planes.iter().copied()) {
        if !planes.contains(&p) {
            planes.push(p);
        }
    }
    let mut boxes: Vec<schemas::markers::TableBox> = run.scene.tables.clone();
    if boxes.is_empty() {
        for plane in &planes {
            let n = plane.normal;
            let norm = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-12);
            let n = n.map(|x| x / norm);
            let d = plane.offset_m / norm;
            // the arm's bounds, projected on the plane: centre and half extent
            let c = [0, 1, 2].map(|i| 0.5 * (bounds.arm_min[i] + bounds.arm_max[i]));
            let half = [0, 1, 2].map(|i| 0.5 * (bounds.arm_max[i] - bounds.arm_min[i])).iter().fold(0.0f64, |a, b| a.max(*b)) + 0.15;
            let dist = n[0] * c[0] + n[1] * c[1] + n[2] * c[2] - d;
            let on_plane = [0, 1, 2].map(|i| c[i] - dist * n[i]);
            let thickness = 0.01;
            let center = [0, 1, 2].map(|i| on_plane[i] - 0.5 * thickness * n[i]);
            boxes.push(schemas::markers::TableBox { center, rotation: quat_z_to(n), size: [2.0 * half, 2.0 * half, thickness], alpha: 70.0 / 255.0 });
        }
    }
    for (k, b) in boxes.iter().enumerate() {
        let [r, g, bl, _] = TABLE.to_be_bytes();
        let alpha = (b.alpha.clamp(0.05, 1.0) * 255.0).round() as u8;
        out.push(
            Chunk::new(format!("{world}/table{k}"), Index::Static)
                .with(BOXES, "centers", "rerun.components.Translation3D", vec3_lists(&[vec![f3(b.center)]]))
                .with(BOXES, "colors", "rerun.components.Color", u32_lists(&[vec![rgba(r, g, bl, alpha)]]))
                .with(BOXES, "fill_mode", "rerun.components.FillMode", u8_lists(&[vec![4]]))
                .with(BOXES, "half_sizes", "rerun.components.HalfSize3D", vec3_lists(&[vec![f3(b.size.map(|x| 0.5 * x))]]))
                .with(BOXES, "quaternions", "rerun.components.RotationQuat", quat_lists(&[vec![q4(b.rotation)]])),
        );
    }
    // the force arrows' scale bar, where Foxglove draws it, with its legend
    let scale = run.scene.force_scale;
    if !run.contacts.is_empty() {
        let bar = run.scene.scale_bar.clone().or_else(|| {
            // a recording without one: a bar on the first plane, at the base's projection
            planes.first().map(|p| {
                let f = scale.bar_force_n();
                let n = p.normal;
                let gap = n[0] * bounds.base[0] + n[1] * bounds.base[1] + n[2] * bounds.base[2] - p.offset_m;
                let tail = [0, 1, 2].map(|i| bounds.base[i] - gap * n[i]);
                schemas::markers::ScaleBar { tail, vector: n.map(|x| x * f * scale.m_per_n), text: format!("{f} N = {:.3} m", f * scale.m_per_n) }
            })
        });
        if let Some(bar) = bar {
            out.push(
                Chunk::new(format!("{world}/force_scale"), Index::Static)
                    .with(ARROWS, "colors", "rerun.components.Color", u32_lists(&[vec![shared(schemas::markers::colors::SCALE_BAR)]]))
                    // short, so that it is not cut at the view's edge (the scale in words is
                    // in the side view's title)
                    .with(ARROWS, "labels", "rerun.components.Text", str_lists(&[vec![bar.text.clone()]]))
                    .with(ARROWS, "origins", "rerun.components.Position3D", vec3_lists(&[vec![f3(bar.tail)]]))
                    .with(ARROWS, "radii", "rerun.components.Radius", f32_lists(&[vec![(0.5 * schemas::markers::ARROW_SHAFT_DIAMETER_M) as f32]]))
                    .with(ARROWS, "vectors", "rerun.components.Vector3D", vec3_lists(&[vec![f3(bar.vector)]])),
            );
        }
    }

    // contacts: marker, ring, force arrow and label per sample, coloured by mode, at the
    // scene's one scale (`/scene`), as Foxglove draws them (`super::contacts`)
    let forces = contact_forces(run);
    out.extend(contact_chunks(run, &world, &contact_points, times.len(), &forces, &scale));

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
                .with(TEXT_LOG, "level", "rerun.components.TextLogLevel", str_lists(&vec![vec!["INFO".to_string()]; n]))
                .with(TEXT_LOG, "text", "rerun.components.Text", str_lists(&text)),
        );
    }

    out.extend(signal_chunks(run, paths, &forces));
    (out, bounds)
}

/// How many times the hand trail is re-logged, at most, and how many points each has, at most.
pub const TRAIL_UPDATES: usize = 400;
pub const TRAIL_POINTS: usize = 400;

/// The line strips of one row of a `LineStrips3D` entity, points in the world frame (f32).
pub type Strips = Vec<Vec<[f32; 3]>>;

/// The hand trail up to the current time: `(times, rows)`, one row per update (a strip of the
/// actual positions from the first sample to that update's, thinned to at most
/// [`TRAIL_POINTS`], its own sample last), at most [`TRAIL_UPDATES`] updates, the last at the
/// last sample; of those, the updates at times within `window` (ns, both ends included: the
/// time window being drawn). No row holds a position after its time.
pub fn trail_updates(times: &[i64], actual: &[[f64; 3]], window: (i64, i64)) -> (Vec<i64>, Vec<Strips>) {
    let n = times.len().min(actual.len());
    if n == 0 {
        return (Vec::new(), Vec::new());
    }
    let stride = n.div_ceil(TRAIL_UPDATES).max(1);
    let mut ks: Vec<usize> = (0..n).step_by(stride).collect();
    if ks.last() != Some(&(n - 1)) {
        ks.push(n - 1);
    }
    ks.retain(|&k| (window.0..=window.1).contains(&times[k]));
    let rows = ks
        .iter()
        .map(|&k| {
            let thin = (k + 1).div_ceil(TRAIL_POINTS).max(1);
            let mut strip: Vec<[f32; 3]> = (0..=k).step_by(thin).map(|i| f3(actual[i])).collect();
            if (k % thin) != 0 {
                strip.push(f3(actual[k]));
            }
            vec![strip]
        })
        .collect();
    (ks.iter().map(|&k| times[k]).collect(), rows)
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use arrow_array::cast::AsArray;
    use arrow_array::types::Float32Type;
    use arrow_array::Array;

    use super::*;
    use schemas::markers::{LabelBox, CONTACT_MARKER_RADIUS_M, MIN_ARROW_LENGTH_M};

    /// The 3-vectors of column `field` of `chunk`, one row each (the first of the row).
    fn vec3_rows(chunk: &Chunk, field: &str) -> Vec<[f64; 3]> {
        let col = chunk.columns.iter().find(|c| c.field == field).unwrap_or_else(|| panic!("{}: no {field}", chunk.entity_path));
        let list = col.values.as_list::<i32>();
        (0..list.len())
            .map(|r| {
                let row = list.value(r);
                let fixed = row.as_fixed_size_list();
                let v = fixed.value(0);
                let v = v.as_primitive::<Float32Type>();
                [v.value(0) as f64, v.value(1) as f64, v.value(2) as f64]
            })
            .collect()
    }

    fn strings(chunk: &Chunk, field: &str) -> Vec<String> {
        let col = chunk.columns.iter().find(|c| c.field == field).unwrap();
        let list = col.values.as_list::<i32>();
        (0..list.len()).map(|r| list.value(r).as_string::<i32>().value(0).to_string()).collect()
    }

    fn find<'a>(chunks: &'a [Chunk], path: &str, temporal: bool) -> &'a Chunk {
        chunks.iter().find(|c| c.entity_path == path && c.is_static() != temporal).unwrap_or_else(|| panic!("no chunk {path}"))
    }

    /// Length of the segment a-b outside the ball (c, r), m.
    fn outside(a: [f64; 3], b: [f64; 3], c: [f64; 3], r: f64) -> f64 {
        let d = [0, 1, 2].map(|i| b[i] - a[i]);
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let u = d.map(|x| x / len);
        let m = [0, 1, 2].map(|i| a[i] - c[i]);
        let bq = u[0] * m[0] + u[1] * m[1] + u[2] * m[2];
        let disc = bq * bq - (m[0] * m[0] + m[1] * m[1] + m[2] * m[2] - r * r);
        if disc <= 0.0 {
            return len;
        }
        len - ((-bq + disc.sqrt()).clamp(0.0, len) - (-bq - disc.sqrt()).clamp(0.0, len))
    }

    /// Issue 27's acceptance, Rerun side: in the paper's two-elbow recording (the archive),
    /// every nonzero contact force (every sample of `/constraints`, both elbows) is drawn as an
    /// arrow that leaves its marker by at least 20 mm, from the contact point's projection on
    /// the table (1e-6 m, f32), max(|F| × scale, 60 mm) long (1e-6 relative) at the scale of
    /// `/scene` (the arm's: 10 mm per N), which is the scale of the recording's Foxglove arrows;
    /// the marker is larger than the URDF's sphere at the contact; the label gives |F| to
    /// 0.1 N; the table is `/scene`'s; the hand trail never holds a position after its time.
    #[test]
    fn every_nonzero_force_is_drawn_outside_its_marker_in_the_paper_two_elbow_run() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../recordings/paper-archive-two-elbow.mcap");
        let input = super::super::read_input(&path).unwrap();
        let run = &super::super::window::whole_run(&path, &input.run).unwrap();
        assert!(run.scene.scale_recorded, "the archive records its force scale on /scene");
        let scale = run.scene.force_scale;
        assert_eq!(scale.m_per_n, 0.01);
        // Foxglove's arrows in the same file: the same scale
        let rec = schemas::read_recording(&path).unwrap();
        assert_eq!(schemas::markers::recorded_arrow_scale(&rec), Some(scale.m_per_n));

        let paths = Paths { prefix: String::new(), run: None, index: 0 };
        let (chunks, _) = run_chunks(run, &paths);
        let mut nonzero = 0;
        let mut min_outside = f64::INFINITY;
        let mut label_boxes: Vec<Vec<LabelBox>> = Vec::new();
        for (ci, c) in run.contacts.iter().enumerate() {
            let base = format!("/world/contacts/{}", c.name);
            let marker = vec3_rows(find(&chunks, &base, true), "positions");
            let radius = {
                let col = find(&chunks, &base, false).columns.iter().find(|c| c.field == "radii").unwrap().values.clone();
                col.as_list::<i32>().value(0).as_primitive::<Float32Type>().value(0) as f64
            };
            assert!((radius - CONTACT_MARKER_RADIUS_M).abs() < 1e-7);
            let link_sphere = run.visuals[c.link.as_ref().unwrap()]
                .iter()
                .filter_map(|v| match v.shape {
                    Shape::Sphere { radius_m } => Some(radius_m),
                    _ => None,
                })
                .fold(0.0, f64::max);
            assert!(link_sphere > 0.0 && radius > link_sphere, "{}: marker {radius} m, URDF sphere {link_sphere} m", c.name);
            let arrows = find(&chunks, &format!("{base}/force"), true);
            let (origins, vectors) = (vec3_rows(arrows, "origins"), vec3_rows(arrows, "vectors"));
            let label_chunk = find(&chunks, &format!("{base}/label"), true);
            let labels = strings(label_chunk, "labels");
            label_boxes.push(vec3_rows(label_chunk, "positions").into_iter().zip(&labels).map(|(p, t)| LabelBox::new(p, t.chars().count())).collect::<Vec<_>>());
            assert_eq!(origins.len(), run.constraints.len());
            for (k, (_, s)) in run.constraints.iter().enumerate() {
                let f = s.normal_force[ci].abs();
                let len = vectors[k].iter().map(|x| x * x).sum::<f64>().sqrt();
                let want = if f > 0.0 { (f * scale.m_per_n).max(MIN_ARROW_LENGTH_M) } else { 0.0 };
                assert!((len - want).abs() <= 1e-6 * want.max(1.0), "{} sample {k}: {len} m for {f} N", c.name);
                assert!(origins[k][2].abs() < 1e-6, "{} sample {k}: the arrow starts {} m off the table", c.name, origins[k][2]);
                assert!((origins[k][0] - marker[k][0]).abs() < 1e-6 && (origins[k][1] - marker[k][1]).abs() < 1e-6);
                let value: f64 = labels[k].split(' ').nth(1).unwrap().parse().unwrap();
                assert!((value - f).abs() <= 0.05 + 1e-9, "{}: label {:?} for {f} N", c.name, labels[k]);
                if f > 0.0 {
                    let tip = [0, 1, 2].map(|i| origins[k][i] + vectors[k][i]);
                    let o = outside(origins[k], tip, marker[k], radius);
                    assert!(o >= 0.02, "{} sample {k}: |F| = {f} N, {o} m outside its marker", c.name);
                    min_outside = min_outside.min(o);
                    nonzero += 1;
                }
            }
        }
        assert_eq!(nonzero, 2 * run.constraints.len(), "both elbows carry a force at every sample");
        assert!(min_outside >= 0.02, "{min_outside}");
        // the two labels never clash (`schemas::markers::LabelBox`: a row apart or side by
        // side, at every sample; f32 positions: 1e-6 m)
        assert_eq!(label_boxes[0].len(), run.constraints.len());
        for (k, (a, b)) in label_boxes[0].iter().zip(&label_boxes[1]).enumerate() {
            let c = a.clearance_m(b);
            assert!(c >= -1e-6, "sample {k}: the labels clash by {} m: {a:?} {b:?}", -c);
        }

        // the table is /scene's (the size Foxglove draws)
        let table = find(&chunks, "/world/table0", false);
        let half = vec3_rows(table, "half_sizes")[0];
        let fox = run.scene.tables[0].size;
        assert!((2.0 * half[0] - fox[0]).abs() < 1e-6 && (2.0 * half[1] - fox[1]).abs() < 1e-6, "{half:?} vs {fox:?}");
        // the trail up to the current time
        let trail = find(&chunks, "/world/hand_trail", true);
        let Index::SimTime(t) = &trail.index else { panic!() };
        let list = trail.columns.iter().find(|c| c.field == "strips").unwrap().values.as_list::<i32>().clone();
        for (r, t_r) in t.iter().enumerate() {
            let strips = list.value(r);
            let points = strips.as_list::<i32>().value(0);
            let n = points.len();
            assert!(n <= TRAIL_POINTS + 1);
            let last = points.as_fixed_size_list().value(n - 1);
            let last = last.as_primitive::<Float32Type>();
            let k = run.hand.iter().position(|(th, _)| super::ns(*th) == *t_r).unwrap();
            let h = &run.hand[k].1.actual;
            assert_eq!([last.value(0), last.value(1), last.value(2)], [h.x as f32, h.y as f32, h.z as f32], "row {r}: ends at its own time");
        }
        assert_eq!(*t.last().unwrap(), super::ns(run.hand.last().unwrap().0));
    }

    /// The trail: at most TRAIL_UPDATES rows, each ending at its own sample, none longer than
    /// TRAIL_POINTS + 1, the last at the last sample; one row per sample for short runs.
    #[test]
    fn the_trail_is_bounded_and_never_ahead() {
        for n in [1usize, 2, 399, 400, 401, 1000, 100_001] {
            let times: Vec<i64> = (0..n as i64).collect();
            let pts: Vec<[f64; 3]> = (0..n).map(|k| [k as f64, 0.0, 0.0]).collect();
            let (t, rows) = trail_updates(&times, &pts, (i64::MIN, i64::MAX));
            assert!(t.len() <= TRAIL_UPDATES + 1 && t.len() == rows.len(), "{n}");
            assert_eq!(*t.last().unwrap(), n as i64 - 1);
            for (tr, row) in t.iter().zip(&rows) {
                let strip = &row[0];
                assert!(strip.len() <= TRAIL_POINTS + 1);
                assert_eq!(strip.last().unwrap()[0], *tr as f32);
                assert!(strip.iter().all(|p| p[0] <= *tr as f32));
                assert_eq!(strip[0][0], 0.0);
            }
            if n <= TRAIL_UPDATES {
                assert_eq!(t.len(), n);
            }
        }
    }
}
