//! The contacts of one run in Rerun (issue 27 item 2): per contact and sample where it touches
//! (a separated contact is not drawn, as on `sim`'s `/contact_markers`) a translucent
//! marker at the contact point (`P/world/contacts/<c>`, `Points3D` larger than the link there),
//! a ring on the table around the point's projection (`…/ring`), the force of the table on the
//! arm as an arrow from that point on the surface (`…/force`, `Arrows3D`) and its label
//! (`…/label`: a point too small to see with the text `<c> <|F|> N <mode>`), coloured by mode;
//! the contact shapes, static on their links. The geometry, the scale, the colours and the
//! labels' places are `schemas::markers`' (what `sim` records for Foxglove on
//! `/contact_markers`), so both viewers draw the same: the arrow's length
//! `max(|F| × scale, shortest)`, the labels of close contacts stacked apart
//! (`schemas::markers::place_labels`, after Christensen, Marks & Shieber 1995).

use super::chunk::{f32_lists, quat_lists, rgba, str_lists, strip_lists, u32_lists, vec3_lists, Chunk, Index};
use super::entities::{f3, q4, shared, ARROWS, CAPSULES, POINTS, STRIPS};
use super::pose::{quat_z_to, Pose};
use super::run::{escape, ns, Run};
use super::urdf::Shape;

/// Radius of the point that carries a contact's label in Rerun, m (too small to see).
const LABEL_POINT_RADIUS_M: f32 = 0.0005;

/// The chunks of `run`'s contacts below `world` at the contact points `contact_points` (per
/// contact, per sample of the frame tree; `samples` of them), with their forces and modes
/// (`contact_forces`), at the scene's `scale`.
pub fn contact_chunks(run: &Run, world: &str, contact_points: &[Vec<[f64; 3]>], samples: usize, forces: &ContactForces, scale: &schemas::markers::ForceScale) -> Vec<Chunk> {
    let (f_n, f_t, modes) = forces;
    let force_times: Vec<i64> = if run.contact_states.is_some() {
        run.contact_states.iter().flatten().map(|(t, _)| ns(*t)).collect()
    } else {
        run.constraints.iter().map(|(t, _)| ns(*t)).collect()
    };
    let n_rows = force_times.len().min(samples);
    // the drawings of the contacts whose point is known (the others: plots only)
    let drawn: Vec<(usize, ContactDrawing)> = run
        .contacts
        .iter()
        .enumerate()
        .filter(|(ci, _)| contact_points[*ci].len() >= n_rows)
        .map(|(ci, c)| (ci, contact_drawing(c, &contact_points[ci][..n_rows], &f_n[ci], f_t.get(ci).map(Vec::as_slice), modes.as_ref().map(|m| m[ci].as_slice()), scale)))
        .collect();
    let names: Vec<&str> = drawn.iter().map(|(ci, _)| run.contacts[*ci].name.as_str()).collect();
    let labels = contact_labels(&names, &drawn.iter().map(|(_, d)| d).collect::<Vec<_>>());
    let mut out = Vec::new();
    for ((ci, d), (texts, anchors)) in drawn.iter().zip(labels) {
        let c = &run.contacts[*ci];
        let base = format!("{world}/contacts/{}", escape(&c.name));
        let colors: Vec<Vec<u32>> = d.modes.iter().map(|m| vec![shared(m.hex())]).collect();
        let translucent: Vec<Vec<u32>> = d.modes.iter().map(|m| vec![shared(m.hex()) & 0xffff_ff00 | 0x90]).collect();
        let ft = Index::SimTime(force_times[..n_rows].to_vec());
        out.push(
            Chunk::new(&base, ft.clone())
                .with(POINTS, "colors", "rerun.components.Color", u32_lists(&translucent))
                .with(POINTS, "positions", "rerun.components.Position3D", vec3_lists(&d.each(|k| f3(d.points[k])))),
        );
        // the marker has no label of its own: the force's label names the contact (two labels
        // at one contact overlapped)
        out.push(
            Chunk::new(&base, Index::Static)
                .with(POINTS, "radii", "rerun.components.Radius", f32_lists(&[vec![schemas::markers::CONTACT_MARKER_RADIUS_M as f32]])),
        );
        let rings: Vec<Vec<Vec<[f32; 3]>>> = d.each(|k| ring(d.glyphs[k].tail, d.normal));
        out.push(
            Chunk::new(format!("{base}/ring"), ft.clone())
                .with(STRIPS, "colors", "rerun.components.Color", u32_lists(&colors))
                .with(STRIPS, "strips", "rerun.components.LineStrip3D", strip_lists(&rings)),
        );
        out.push(
            Chunk::new(format!("{base}/ring"), Index::Static)
                .with(STRIPS, "radii", "rerun.components.Radius", f32_lists(&[vec![(0.5 * schemas::markers::RING_LINE_WIDTH_M) as f32]])),
        );
        out.push(
            Chunk::new(format!("{base}/force"), ft.clone())
                .with(ARROWS, "colors", "rerun.components.Color", u32_lists(&colors))
                .with(ARROWS, "origins", "rerun.components.Position3D", vec3_lists(&d.each(|k| f3(d.glyphs[k].tail))))
                .with(
                    ARROWS,
                    "vectors",
                    "rerun.components.Vector3D",
                    vec3_lists(&d.each(|k| f3(d.glyphs[k].direction.map(|x| x * d.glyphs[k].length_m)))),
                ),
        );
        out.push(
            Chunk::new(format!("{base}/force"), Index::Static)
                .with(ARROWS, "radii", "rerun.components.Radius", f32_lists(&[vec![(0.5 * schemas::markers::ARROW_SHAFT_DIAMETER_M) as f32]])),
        );
        // the label, where `schemas::markers::place_labels` puts it (where Foxglove's text is):
        // a point too small to see, carrying the text
        out.push(
            Chunk::new(format!("{base}/label"), ft)
                .with(POINTS, "colors", "rerun.components.Color", u32_lists(&colors))
                .with(POINTS, "labels", "rerun.components.Text", str_lists(&texts.into_iter().enumerate().map(|(k, t)| if d.drawn(k) { vec![t] } else { Vec::new() }).collect::<Vec<_>>()))
                .with(POINTS, "positions", "rerun.components.Position3D", vec3_lists(&d.each(|k| f3(anchors[k])))),
        );
        out.push(
            Chunk::new(format!("{base}/label"), Index::Static)
                .with(POINTS, "radii", "rerun.components.Radius", f32_lists(&[vec![LABEL_POINT_RADIUS_M]])),
        );
    }
    out

}

/// Every drawn contact's label per sample (text, anchor: world frame, m), placed apart
/// sample by sample with `schemas::markers::place_labels` among the contacts that touch at
/// that sample (in their order, as `sim` places Foxglove's; a separated contact is not drawn
/// and its anchor is NaN): `names[i]` is `drawings[i]`'s contact.
pub fn contact_labels(names: &[&str], drawings: &[&ContactDrawing]) -> Vec<(Vec<String>, Vec<[f64; 3]>)> {
    use schemas::markers::{default_anchor, label_capacity, place_labels, write_label, LabelBox};
    let n = drawings.iter().map(|d| d.glyphs.len()).min().unwrap_or(0);
    let mut out: Vec<(Vec<String>, Vec<[f64; 3]>)> = drawings.iter().map(|_| (Vec::with_capacity(n), Vec::with_capacity(n))).collect();
    let mut boxes = Vec::with_capacity(drawings.len());
    let mut text = String::with_capacity(names.iter().map(|s| label_capacity(s)).max().unwrap_or(0));
    for k in 0..n {
        boxes.clear();
        for (i, (d, name)) in drawings.iter().zip(names).enumerate() {
            let g = &d.glyphs[k];
            write_label(&mut text, name, g.magnitude_n, d.modes[k]);
            if d.drawn(k) {
                boxes.push(LabelBox::new(default_anchor(g, d.points[k], d.normal), text.chars().count()));
            }
            out[i].0.push(text.clone());
        }
        // apart among the drawn contacts only, as `sim` places Foxglove's
        place_labels(&mut boxes);
        let mut placed = boxes.iter();
        for (o, d) in out.iter_mut().zip(drawings) {
            o.1.push(if d.drawn(k) { placed.next().map_or([0.0; 3], |b| b.anchor) } else { [f64::NAN; 3] });
        }
    }
    out
}

/// Per contact and sample: normal force, friction components `(t1, t2)` interleaved (empty
/// without `/contacts`), and mode (when `/contacts` is recorded).
pub type ContactForces = (Vec<Vec<f64>>, Vec<Vec<f64>>, Option<Vec<Vec<u32>>>);

/// A contact's drawing, sample by sample: where its marker is, its mode, its force glyph.
#[derive(Debug, Clone)]
pub struct ContactDrawing {
    /// The contact point (the marker's centre), world frame, m.
    pub points: Vec<[f64; 3]>,
    pub modes: Vec<schemas::markers::MarkerMode>,
    pub glyphs: Vec<schemas::markers::ForceGlyph>,
    /// The plane's unit normal.
    pub normal: [f64; 3],
}

impl ContactDrawing {
    /// Whether the contact is drawn at sample `k`: not when it is separated (as `sim`'s
    /// `/contact_markers` deletes it, `schemas::markers::ContactMarkers`).
    pub fn drawn(&self, k: usize) -> bool {
        self.modes.get(k).is_some_and(|m| *m != schemas::markers::MarkerMode::Separated)
    }

    /// Per sample, `f(k)` when the contact is drawn, else nothing (a Rerun row with no
    /// instance: nothing shown at that time).
    fn each<T>(&self, f: impl Fn(usize) -> T) -> Vec<Vec<T>> {
        (0..self.points.len()).map(|k| if self.drawn(k) { vec![f(k)] } else { Vec::new() }).collect()
    }
}

/// The drawing of contact `c` at its `points` (per sample) with normal forces `f_n`, friction
/// components `f_t` (`(t1, t2)` interleaved, when recorded) and mode codes (when recorded), at
/// `scale`: the geometry of `schemas::markers` (Foxglove's), so that both viewers draw the same.
pub fn contact_drawing(
    c: &super::run::ContactPoint,
    points: &[[f64; 3]],
    f_n: &[f64],
    f_t: Option<&[f64]>,
    modes: Option<&[u32]>,
    scale: &schemas::markers::ForceScale,
) -> ContactDrawing {
    use schemas::markers::{ForceGlyph, MarkerMode};
    let (normal, offset) = c.plane.map_or(([0.0, 0.0, 1.0], 0.0), |p| {
        let n = p.normal;
        let norm = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-12);
        (n.map(|x| x / norm), p.offset_m / norm)
    });
    let mut d = ContactDrawing { points: points.to_vec(), modes: Vec::with_capacity(points.len()), glyphs: Vec::with_capacity(points.len()), normal };
    for (k, p) in points.iter().enumerate() {
        let fn_k = f_n.get(k).copied().unwrap_or(0.0);
        let mode = modes.and_then(|m| m.get(k)).map_or_else(|| MarkerMode::bilateral(fn_k), |code| MarkerMode::from_code(*code, fn_k));
        let mut f = normal.map(|x| x * fn_k);
        if let (Some((t1, t2)), Some(ft)) = (c.tangents, f_t) {
            let (a, b) = ft.get(2 * k).copied().zip(ft.get(2 * k + 1).copied()).unwrap_or((0.0, 0.0));
            f = [0, 1, 2].map(|i| f[i] + a * t1[i] + b * t2[i]);
        }
        d.modes.push(mode);
        d.glyphs.push(ForceGlyph::new(*p, normal, offset, f, scale));
    }
    d
}

/// Where contact `c` touches (or would touch) its plane, world frame, m, with its link at `link`
/// (world frame): its point, or its shape's lowest point (`schemas::ContactShapeInfo`, the
/// point `sim` draws its Foxglove marker at).
pub fn touch_point(c: &super::run::ContactPoint, link: &Pose) -> [f64; 3] {
    let center = link.apply(c.offset_m);
    match (&c.shape, c.plane) {
        (Some(s), Some(plane)) => {
            let n = plane.normal;
            let norm = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-12);
            let axis = s.axis.map_or([0.0; 3], |a| super::pose::rotate(link.rotation, a));
            s.lowest_point(center, axis, n.map(|x| x / norm))
        }
        _ => center,
    }
}

/// The static chunks of a contact shape at `path` (below its link's entity, so in the link's
/// frame): a sphere pad as an ellipsoid, a capsule as `Capsules3D` (from its first end along
/// +z, as Rerun defines it), a cylinder as `Cylinders3D` between its rims, and each rim as a
/// closed line strip; translucent cyan (`schemas::markers::colors::CONTACT_SHAPE`).
pub fn shape_chunks(path: &str, g: &schemas::markers::ShapeGlyph) -> Vec<Chunk> {
    use schemas::markers::ShapeGlyph;
    let [r, gr, b, _] = schemas::markers::colors::rgba8(schemas::markers::colors::CONTACT_SHAPE, 255);
    let fill = rgba(r, gr, b, (schemas::markers::SHAPE_ALPHA * 255.0).round() as u8);
    let line = rgba(r, gr, b, 255);
    let mut out = Vec::new();
    let segment = |ends: &[[f64; 3]; 2]| {
        let d = [0, 1, 2].map(|i| ends[1][i] - ends[0][i]);
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        (quat_z_to(d.map(|x| x / len.max(1e-300))), len)
    };
    match g {
        ShapeGlyph::Sphere { center, radius, .. } => out.push(super::mesh::shape_chunk(
            path,
            &Pose { translation: *center, rotation: [0.0, 0.0, 0.0, 1.0] },
            Shape::Sphere { radius_m: *radius },
            fill,
        )),
        ShapeGlyph::Capsule { ends, radius, .. } => {
            let (q, len) = segment(ends);
            out.push(
                Chunk::new(path, Index::Static)
                    .with(CAPSULES, "colors", "rerun.components.Color", u32_lists(&[vec![fill]]))
                    .with(CAPSULES, "lengths", "rerun.components.Length", f32_lists(&[vec![len as f32]]))
                    .with(CAPSULES, "quaternions", "rerun.components.RotationQuat", quat_lists(&[vec![q4(q)]]))
                    .with(CAPSULES, "radii", "rerun.components.Radius", f32_lists(&[vec![*radius as f32]]))
                    .with(CAPSULES, "translations", "rerun.components.Translation3D", vec3_lists(&[vec![f3(ends[0])]])),
            );
        }
        ShapeGlyph::Cylinder { ends, radius, .. } => {
            let (q, len) = segment(ends);
            let mid = [0, 1, 2].map(|i| 0.5 * (ends[0][i] + ends[1][i]));
            out.push(super::mesh::shape_chunk(
                path,
                &Pose { translation: mid, rotation: q },
                Shape::Cylinder { radius_m: *radius, length_m: len },
                rgba(r, gr, b, 64),
            ));
        }
        ShapeGlyph::Rim { .. } => {}
    }
    let rims: Vec<Vec<[f32; 3]>> = g
        .rims()
        .into_iter()
        .map(|(c, a)| {
            let mut pts: Vec<[f32; 3]> = schemas::markers::circle(c, a, g.radius()).into_iter().map(f3).collect();
            pts.push(pts[0]);
            pts
        })
        .collect();
    if !rims.is_empty() {
        out.push(
            Chunk::new(format!("{path}/rims"), Index::Static)
                .with(STRIPS, "colors", "rerun.components.Color", u32_lists(&[vec![line]]))
                .with(STRIPS, "radii", "rerun.components.Radius", f32_lists(&[vec![(0.5 * schemas::markers::RING_LINE_WIDTH_M) as f32]]))
                .with(STRIPS, "strips", "rerun.components.LineStrip3D", strip_lists(&[rims])),
        );
    }
    out
}

/// The ring around a contact's point on the table: a closed strip of
/// [`schemas::markers::CONTACT_RING_POINTS`] points about `center` in the plane of `normal`.
fn ring(center: [f64; 3], normal: [f64; 3]) -> Vec<[f32; 3]> {
    let q = quat_z_to(normal);
    let r = schemas::markers::CONTACT_RING_RADIUS_M;
    let n = schemas::markers::CONTACT_RING_POINTS;
    (0..=n)
        .map(|k| {
            let a = std::f64::consts::TAU * (k % n) as f64 / n as f64;
            let v = schemas::markers::rotate(q, [r * a.cos(), r * a.sin(), 0.0]);
            f3([0, 1, 2].map(|i| center[i] + v[i]))
        })
        .collect()
}

/// "10 mm per N" (the scale in words).
pub fn scale_words(s: &schemas::markers::ForceScale) -> String {
    let mm = s.m_per_n * 1e3;
    if mm >= 0.01 {
        format!("{} mm per N", (mm * 1e4).round() / 1e4)
    } else {
        format!("{:e} m per N", s.m_per_n)
    }
}

/// Per contact and sample: normal force, friction components `(t1, t2)` interleaved, and mode
/// (when `/contacts` is recorded; bilateral runs have `/constraints` only).
pub fn contact_forces(run: &Run) -> ContactForces {
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


#[cfg(test)]
mod tests {
    use schemas::markers::{default_anchor, ForceGlyph, ForceScale, LabelBox, MarkerMode, LABEL_ROW_M};

    use super::*;

    /// The whole-table run's geometry: nine contacts 0.3 m apart on a line on the table
    /// (joint3 … hand, normal +z), over 200 samples with forces that grow, change sign and
    /// vanish, each contact's differently. Placed by `contact_labels`, no two labels clash at
    /// any sample (clearance ≥ −1e-9 m, `LabelBox::clearance_m`); labels only move up; at their default places (above each arrow's tip) they clash at most samples, so
    /// the check has something to find.
    #[test]
    fn close_contacts_labels_never_clash() {
        let scale = ForceScale::for_arm(1.0, 3.0, 10);
        let names: Vec<String> = (0..9).map(|i| format!("joint{}", i + 3)).collect();
        let n = 200;
        let drawings: Vec<ContactDrawing> = (0..9)
            .map(|i| {
                let p = [0.3 * i as f64, 0.05 * (i % 2) as f64, 0.0];
                let mut d = ContactDrawing { points: Vec::new(), modes: Vec::new(), glyphs: Vec::new(), normal: [0.0, 0.0, 1.0] };
                for k in 0..n {
                    let t = k as f64 / n as f64;
                    // f_n from −5 to 35 N, phase by contact; zero a tenth of the time
                    let f_n = if (k + 7 * i) % 10 == 0 { 0.0 } else { 40.0 * ((t * 6.0 + i as f64).sin() * 0.5 + 0.5) - 5.0 };
                    let f = [0.3 * f_n * (i as f64).cos(), 0.2 * f_n, f_n];
                    d.points.push(p);
                    d.modes.push(MarkerMode::bilateral(f_n));
                    d.glyphs.push(ForceGlyph::new(p, d.normal, 0.0, f, &scale));
                }
                d
            })
            .collect();
        let refs: Vec<&ContactDrawing> = drawings.iter().collect();
        let name_refs: Vec<&str> = names.iter().map(String::as_str).collect();
        let labels = contact_labels(&name_refs, &refs);
        let (mut clashes_before, mut worst_after) = (0, f64::INFINITY);
        for k in 0..n {
            let placed: Vec<LabelBox> = labels.iter().map(|(t, a)| LabelBox::new(a[k], t[k].chars().count())).collect();
            let before: Vec<LabelBox> =
                drawings.iter().zip(&labels).map(|(d, (t, _))| LabelBox::new(default_anchor(&d.glyphs[k], d.points[k], d.normal), t[k].chars().count())).collect();
            let mut clashed = false;
            for i in 0..9 {
                let lift = (placed[i].anchor[2] - before[i].anchor[2]) / LABEL_ROW_M;
                assert!(placed[i].anchor[..2] == before[i].anchor[..2] && lift > -1e-9, "sample {k}, {}: moved {lift} rows", names[i]);
                for j in 0..i {
                    worst_after = worst_after.min(placed[i].clearance_m(&placed[j]));
                    clashed |= before[i].clearance_m(&before[j]) < 0.0;
                }
            }
            clashes_before += usize::from(clashed);
        }
        assert!(worst_after >= -1e-9, "labels clash by {} m", -worst_after);
        assert!(clashes_before > n / 2, "the default places clash at {clashes_before} of {n} samples");
    }
}
