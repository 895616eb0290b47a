//! The links' geometry that is not a primitive: each `<visual>` mesh of the recorded URDF
//! (STL, COLLADA `.dae`, Wavefront OBJ) loaded, placed in its link frame and logged once as a
//! static Rerun `Mesh3D` (`…/<link>/mesh<k>`), with the fallbacks a viewer owes a user whose
//! meshes are not all there.
//!
//! - Files: the `file://` URIs `sim` writes when the scene gives `robot.package_paths`
//!   (`sim::dynamics::urdf::resolve_meshes`), or absolute paths. A `package://` URI, a relative
//!   path or another scheme cannot be found from the recording alone and counts as missing.
//!   Parsing is `mesh-loader` (openrr, Apache-2.0: binary and ASCII STL, COLLADA 1.4/1.5 with
//!   its node transforms and `<unit meter>`, OBJ with its `.mtl`). COLLADA's `<up_axis>` is not
//!   applied (as `mesh-loader`; every example-robot-data file is `Z_UP`).
//! - Placement (URDF, <http://wiki.ros.org/urdf/XML/link>): a vertex `p` of the file is drawn at
//!   `x_link_visual · diag(scale) · p` in the link frame, its normal at
//!   `R_link_visual · diag(scale)⁻¹ · n`, normalised (the inverse transpose of the linear part,
//!   so that a non-uniform scale keeps normals perpendicular to the faces); a negative scale
//!   (a mirrored part) reverses the winding of every triangle, so that the faces still point
//!   out. Missing normals are the area-weighted mean of the faces' normals at each vertex.
//! - Colour: the file's own material colours (per sub-mesh, as vertex colours) when it has
//!   any, as RViz does for COLLADA; otherwise the URDF material colour (`albedo_factor`);
//!   otherwise the arm's grey.
//! - Fallback: a link whose visual mesh is missing or unreadable is drawn with its
//!   `<collision>` elements instead (primitives, or collision meshes loaded the same way,
//!   `…/<link>/collision<k>`); when that fails too, or the link has no collision, it is left
//!   out, with one note per link saying which file and why ([`Drawn::notes`], printed by
//!   `analyze view`).
//! - Memory: one mesh at a time is read, placed, encoded and dropped
//!   ([`MESH_FILE_MAX_BYTES`] bounds a file; a FIFO or a device is refused before it is read).

use std::io::Read;
use std::path::{Path, PathBuf};

use super::chunk::{f32_lists, quat_lists, rgba, tri_lists, u32_lists, u8_lists, vec3_lists, Chunk, Index};
use super::pose::{rotate, Pose};
use super::urdf::{Element, Geometry, LinkGeometry, Links, MeshRef, Shape};
use crate::Error;

const MESH: &str = "rerun.archetypes.Mesh3D";
const BOXES: &str = "rerun.archetypes.Boxes3D";
const CYLINDERS: &str = "rerun.archetypes.Cylinders3D";
const ELLIPSOIDS: &str = "rerun.archetypes.Ellipsoids3D";

/// The largest mesh file read, bytes: 256 MB (the Panda's largest visual is 1.7 MB, the Z1's
/// 3.9 MB; a file larger than this is no robot part a viewer should hold).
pub const MESH_FILE_MAX_BYTES: u64 = 256 << 20;

/// The arm's grey, when neither the file nor the URDF gives a colour.
pub const ARM: u32 = rgba(170, 180, 200, 255);

/// A triangle mesh placed in its link frame, m.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    /// One `0xRRGGBBAA` per vertex, when the file gives material colours.
    pub colors: Option<Vec<u32>>,
}

/// What [`draw`] drew for one run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Drawn {
    /// Mesh entities written (visual and collision meshes).
    pub meshes: usize,
    pub vertices: usize,
    pub triangles: usize,
    /// Links drawn with their collision geometry instead of a visual mesh.
    pub fallbacks: Vec<String>,
    /// One sentence per link that is drawn in part or not at all: which file and why.
    pub notes: Vec<String>,
    /// The largest mesh file read, bytes.
    pub largest_file: u64,
}

/// The local path of a URDF mesh `filename`, or why there is none.
pub fn local_path(filename: &str) -> Result<PathBuf, String> {
    if let Some(rest) = filename.strip_prefix("file://") {
        return Ok(PathBuf::from(rest));
    }
    if filename.starts_with("package://") {
        return Err("a package:// URI: the recording was made without robot.package_paths for its package (give them in the scene and run sim again)".into());
    }
    if filename.contains("://") {
        return Err("not a file:// URI (only local files are read)".into());
    }
    let p = PathBuf::from(filename);
    if p.is_absolute() {
        Ok(p)
    } else {
        Err("a relative path, which the recording cannot place (give robot.package_paths in the scene and run sim again)".into())
    }
}

/// The bytes of the regular file at `path`, at most [`MESH_FILE_MAX_BYTES`].
fn read_bounded(path: &Path) -> Result<Vec<u8>, String> {
    let meta = std::fs::metadata(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => format!("no file {}", path.display()),
        _ => format!("{}: {e}", path.display()),
    })?;
    if !meta.is_file() {
        return Err(format!("{} is not a regular file", path.display()));
    }
    if meta.len() > MESH_FILE_MAX_BYTES {
        return Err(format!("{} is {} bytes, over the limit of {MESH_FILE_MAX_BYTES}", path.display(), meta.len()));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    std::fs::File::open(path)
        .and_then(|f| f.take(MESH_FILE_MAX_BYTES).read_to_end(&mut bytes))
        .map_err(|e| format!("reading {}: {e}", path.display()))?;
    Ok(bytes)
}

fn color8(c: [f32; 4]) -> u32 {
    let b = |x: f32| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    rgba(b(c[0]), b(c[1]), b(c[2]), b(c[3]))
}

/// The URDF colour `rgba` (in [0, 1]) as `0xRRGGBBAA`.
pub fn urdf_color(rgba: Option<[f64; 4]>) -> Option<u32> {
    rgba.map(|c| color8(c.map(|x| x as f32)))
}

/// Loads the mesh file `m.filename` and places it by `origin` and `m.scale` ([`place`]); the
/// file's sub-meshes are merged into one. Returns the mesh and the file's size, or why it
/// cannot be drawn (no file, not a mesh format, a parse error, no triangles).
pub fn load(m: &MeshRef, origin: &Pose) -> Result<(TriMesh, u64), String> {
    if m.filename.is_empty() {
        return Err("a <mesh> without a filename".into());
    }
    if m.scale.iter().any(|s| !s.is_finite() || *s == 0.0) {
        return Err(format!("scale {:?}: not three finite nonzero numbers", m.scale));
    }
    let path = local_path(&m.filename)?;
    let bytes = read_bounded(&path)?;
    let size = bytes.len() as u64;
    let scene = mesh_loader::Loader::default().load_from_slice(&bytes, &path).map_err(|e| format!("reading {}: {e}", path.display()))?;
    drop(bytes);
    // the sub-meshes merged; a vertex colour per vertex when any material has a colour
    let has_colors = scene.materials.iter().any(|mat| mat.color.diffuse.is_some());
    let mut out = TriMesh::default();
    for (k, sub) in scene.meshes.iter().enumerate() {
        let first = u32::try_from(out.positions.len()).map_err(|_| format!("{}: over 2^32 vertices", path.display()))?;
        let n = sub.vertices.len() as u32;
        if sub.faces.iter().flatten().any(|&i| i >= n) {
            return Err(format!("{}: a triangle indexes past the {n} vertices of sub-mesh {k}", path.display()));
        }
        out.positions.extend_from_slice(&sub.vertices);
        if sub.normals.len() == sub.vertices.len() && out.normals.len() + sub.normals.len() == out.positions.len() {
            out.normals.extend_from_slice(&sub.normals);
        } else {
            out.normals.clear();
        }
        out.triangles.extend(sub.faces.iter().map(|f| f.map(|i| i + first)));
        if has_colors {
            let c = scene.materials.get(k).and_then(|mat| mat.color.diffuse).map_or(ARM, color8);
            out.colors.get_or_insert_with(Vec::new).extend(std::iter::repeat_n(c, sub.vertices.len()));
        }
    }
    if out.triangles.is_empty() {
        return Err(format!("{}: no triangles", path.display()));
    }
    place(&mut out, origin, m.scale);
    Ok((out, size))
}

/// Places `mesh` (in its file's frame) in the link frame: `p ↦ origin · diag(scale) · p`,
/// normals `n ↦ R · diag(scale)⁻¹ · n` normalised (computed from the faces when missing), the
/// winding reversed when the scale mirrors.
pub fn place(mesh: &mut TriMesh, origin: &Pose, scale: [f64; 3]) {
    for p in &mut mesh.positions {
        let s = [0, 1, 2].map(|i| f64::from(p[i]) * scale[i]);
        *p = origin.apply(s).map(|x| x as f32);
    }
    if scale.iter().product::<f64>() < 0.0 {
        for t in &mut mesh.triangles {
            t.swap(1, 2);
        }
    }
    if mesh.normals.len() == mesh.positions.len() {
        for n in &mut mesh.normals {
            let s = [0, 1, 2].map(|i| f64::from(n[i]) / scale[i]);
            *n = normalized(rotate(origin.rotation, s));
        }
    } else {
        mesh.normals = vertex_normals(&mesh.positions, &mesh.triangles);
    }
}

fn normalized(v: [f64; 3]) -> [f32; 3] {
    let norm = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if norm > 0.0 {
        v.map(|x| (x / norm) as f32)
    } else {
        [0.0, 0.0, 1.0]
    }
}

/// Area-weighted vertex normals of a triangle list (the sum of the faces' cross products at
/// each vertex, normalised).
pub fn vertex_normals(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let mut acc = vec![[0.0f64; 3]; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize].map(f64::from));
        let (u, v) = ([b[0] - a[0], b[1] - a[1], b[2] - a[2]], [c[0] - a[0], c[1] - a[1], c[2] - a[2]]);
        let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
        for &i in t {
            for k in 0..3 {
                acc[i as usize][k] += n[k];
            }
        }
    }
    acc.into_iter().map(normalized).collect()
}

/// The static `Mesh3D` chunk of `mesh` at `path`: the file's vertex colours, else `albedo`.
pub fn mesh_chunk(path: &str, mesh: TriMesh, albedo: u32) -> Chunk {
    let chunk = Chunk::new(path, Index::Static);
    let chunk = match mesh.colors {
        Some(c) => chunk.with(MESH, "vertex_colors", "rerun.components.Color", u32_lists(&[c])),
        None => chunk.with(MESH, "albedo_factor", "rerun.components.AlbedoFactor", u32_lists(&[vec![albedo]])),
    };
    chunk
        .with(MESH, "triangle_indices", "rerun.components.TriangleIndices", tri_lists(&[mesh.triangles]))
        .with(MESH, "vertex_normals", "rerun.components.Vector3D", vec3_lists(&[mesh.normals]))
        .with(MESH, "vertex_positions", "rerun.components.Position3D", vec3_lists(&[mesh.positions]))
}

/// The static chunk of a primitive `shape` at `origin` in its link frame, solid, `color`.
pub fn shape_chunk(path: &str, origin: &Pose, shape: Shape, color: u32) -> Chunk {
    let f3 = |p: [f64; 3]| p.map(|x| x as f32);
    let q4 = |q: [f64; 4]| q.map(|x| x as f32);
    let center = vec3_lists(&[vec![f3(origin.translation)]]);
    let colors = u32_lists(&[vec![color]]);
    let solid = u8_lists(&[vec![3]]);
    let chunk = Chunk::new(path, Index::Static);
    match shape {
        Shape::Box { size_m } => chunk
            .with(BOXES, "centers", "rerun.components.Translation3D", center)
            .with(BOXES, "colors", "rerun.components.Color", colors)
            .with(BOXES, "fill_mode", "rerun.components.FillMode", solid)
            .with(BOXES, "half_sizes", "rerun.components.HalfSize3D", vec3_lists(&[vec![f3(size_m.map(|s| s / 2.0))]]))
            .with(BOXES, "quaternions", "rerun.components.RotationQuat", quat_lists(&[vec![q4(origin.rotation)]])),
        Shape::Cylinder { radius_m, length_m } => chunk
            .with(CYLINDERS, "centers", "rerun.components.Translation3D", center)
            .with(CYLINDERS, "colors", "rerun.components.Color", colors)
            .with(CYLINDERS, "fill_mode", "rerun.components.FillMode", solid)
            .with(CYLINDERS, "lengths", "rerun.components.Length", f32_lists(&[vec![length_m as f32]]))
            .with(CYLINDERS, "quaternions", "rerun.components.RotationQuat", quat_lists(&[vec![q4(origin.rotation)]]))
            .with(CYLINDERS, "radii", "rerun.components.Radius", f32_lists(&[vec![radius_m as f32]])),
        Shape::Sphere { radius_m } => chunk
            .with(ELLIPSOIDS, "centers", "rerun.components.Translation3D", center)
            .with(ELLIPSOIDS, "colors", "rerun.components.Color", colors)
            .with(ELLIPSOIDS, "fill_mode", "rerun.components.FillMode", solid)
            .with(ELLIPSOIDS, "half_sizes", "rerun.components.HalfSize3D", vec3_lists(&[vec![[radius_m as f32; 3]]])),
    }
}

/// The file name of a mesh reference, for notes.
fn short(m: &MeshRef) -> &str {
    m.filename.rsplit('/').next().unwrap_or(&m.filename)
}

/// Draws the meshes of `links` and the fallbacks of [`self`](self): `link_path(link)` is the
/// entity path of a link's frame (`None`: the link has no frame in `/tf`, noted and skipped);
/// each chunk is handed to `push` as soon as it is made. Primitive visuals are not drawn here
/// (`entities` draws them with the frames).
pub fn draw(
    links: &Links,
    link_path: &dyn Fn(&str) -> Option<String>,
    push: &mut dyn FnMut(Chunk) -> Result<(), Error>,
) -> Result<Drawn, Error> {
    let mut drawn = Drawn::default();
    for (link, geometry) in links {
        let LinkGeometry { visuals, collisions } = geometry;
        let has_mesh = visuals.iter().any(|v| matches!(v.geometry, Geometry::Mesh(_)));
        if !has_mesh {
            continue;
        }
        let Some(path) = link_path(link) else {
            drawn.notes.push(format!("link {link}: not drawn, it has no frame in /tf"));
            continue;
        };
        let link_color = visuals.iter().find_map(|v| urdf_color(v.rgba)).unwrap_or(ARM);
        // the visual meshes; the first failure sends the link to its collisions
        let mut failed: Vec<String> = Vec::new();
        for (k, v) in visuals.iter().enumerate() {
            let Geometry::Mesh(m) = &v.geometry else { continue };
            match load(m, &v.origin) {
                Ok((mesh, size)) => emit(&mut drawn, push, &format!("{path}/mesh{k}"), mesh, size, urdf_color(v.rgba).unwrap_or(ARM))?,
                Err(why) => failed.push(format!("{}: {why}", short(m))),
            }
        }
        if failed.is_empty() {
            continue;
        }
        let mut drew = 0;
        let mut collision_failed: Vec<String> = Vec::new();
        for (k, c) in collisions.iter().enumerate() {
            let cpath = format!("{path}/collision{k}");
            match fallback(c, &cpath, link_color) {
                Ok(Fallback::Shape(chunk)) => {
                    push(chunk)?;
                    drew += 1;
                }
                Ok(Fallback::Mesh(mesh, size)) => {
                    emit(&mut drawn, push, &cpath, mesh, size, link_color)?;
                    drew += 1;
                }
                Err(why) => collision_failed.push(why),
            }
        }
        let visual = failed.join("; ");
        if drew > 0 {
            drawn.fallbacks.push(link.clone());
            let part = if collision_failed.is_empty() { String::new() } else { format!(" (not: {})", collision_failed.join("; ")) };
            drawn.notes.push(format!("link {link}: drawn with its collision geometry{part}, visual mesh {visual}"));
        } else if collisions.is_empty() {
            drawn.notes.push(format!("link {link}: not drawn, no collision geometry to fall back on, visual mesh {visual}"));
        } else {
            drawn.notes.push(format!("link {link}: not drawn, visual mesh {visual}; collision {}", collision_failed.join("; ")));
        }
    }
    Ok(drawn)
}

enum Fallback {
    Shape(Chunk),
    Mesh(TriMesh, u64),
}

fn fallback(c: &Element, path: &str, color: u32) -> Result<Fallback, String> {
    match &c.geometry {
        Geometry::Primitive(shape) => Ok(Fallback::Shape(shape_chunk(path, &c.origin, *shape, color))),
        Geometry::Mesh(m) => load(m, &c.origin).map(|(mesh, size)| Fallback::Mesh(mesh, size)).map_err(|why| format!("mesh {}: {why}", short(m))),
    }
}

fn emit(drawn: &mut Drawn, push: &mut dyn FnMut(Chunk) -> Result<(), Error>, path: &str, mesh: TriMesh, size: u64, albedo: u32) -> Result<(), Error> {
    drawn.meshes += 1;
    drawn.vertices += mesh.positions.len();
    drawn.triangles += mesh.triangles.len();
    drawn.largest_file = drawn.largest_file.max(size);
    push(mesh_chunk(path, mesh, albedo))
}

#[cfg(test)]
mod tests {
    use super::super::pose::quat_from_rpy;
    use super::*;

    fn erd(rel: &str) -> String {
        format!("file://{}/../sim/scenes/published/example-robot-data/robots/{rel}", env!("CARGO_MANIFEST_DIR"))
    }

    fn bbox(m: &TriMesh) -> ([f32; 3], [f32; 3]) {
        m.positions.iter().fold(([f32::MAX; 3], [f32::MIN; 3]), |(lo, hi), p| ([0, 1, 2].map(|i| lo[i].min(p[i])), [0, 1, 2].map(|i| hi[i].max(p[i]))))
    }

    fn face_normal(m: &TriMesh, t: [u32; 3]) -> [f64; 3] {
        let [a, b, c] = t.map(|i| m.positions[i as usize].map(f64::from));
        let (u, v) = ([b[0] - a[0], b[1] - a[1], b[2] - a[2]], [c[0] - a[0], c[1] - a[1], c[2] - a[2]]);
        [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    }

    fn dot(a: [f64; 3], b: [f32; 3]) -> f64 {
        a[0] * f64::from(b[0]) + a[1] * f64::from(b[1]) + a[2] * f64::from(b[2])
    }

    /// A right triangle in the file's xy plane, its normal +z.
    fn triangle() -> TriMesh {
        TriMesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            normals: vec![[0.0, 0.0, 1.0]; 3],
            triangles: vec![[0, 1, 2]],
            colors: None,
        }
    }

    /// `p ↦ origin · diag(scale) · p` exactly, normals by the inverse transpose (still
    /// perpendicular to the placed face under a non-uniform scale), winding reversed by a
    /// mirroring scale so that the face's own normal still agrees with its vertex normals.
    #[test]
    fn placement_scales_then_moves_and_keeps_normals_perpendicular() {
        // 90° about z, then (1, 2, 3); scale x by 2
        let origin = Pose { translation: [1.0, 2.0, 3.0], rotation: quat_from_rpy([0.0, 0.0, std::f64::consts::FRAC_PI_2]) };
        let mut m = triangle();
        place(&mut m, &origin, [2.0, 1.0, 1.0]);
        let want = [[1.0, 2.0, 3.0], [1.0, 4.0, 3.0], [0.0, 2.0, 3.0]];
        for (p, w) in m.positions.iter().zip(want) {
            assert!((0..3).all(|i| (f64::from(p[i]) - w[i]).abs() < 1e-6), "{p:?} vs {w:?}");
        }
        // a slanted face under a non-uniform scale: the normal stays perpendicular to both edges
        let mut m = TriMesh { positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]], normals: vec![], triangles: vec![[0, 1, 2]], colors: None };
        m.normals = vertex_normals(&m.positions, &m.triangles);
        let n0 = m.normals[0];
        assert!((f64::from(n0[0]) + 1.0 / 3f64.sqrt()).abs() < 1e-6, "{n0:?}");
        let origin = Pose { translation: [0.0; 3], rotation: quat_from_rpy([0.3, -0.2, 1.1]) };
        place(&mut m, &origin, [3.0, 0.5, 2.0]);
        let [a, b, c] = [0, 1, 2].map(|i| m.positions[i].map(f64::from));
        for n in &m.normals {
            assert!((f64::from(n[0]).powi(2) + f64::from(n[1]).powi(2) + f64::from(n[2]).powi(2) - 1.0).abs() < 1e-6);
            for e in [[b[0] - a[0], b[1] - a[1], b[2] - a[2]], [c[0] - a[0], c[1] - a[1], c[2] - a[2]]] {
                assert!(dot(e, *n).abs() < 1e-6, "edge {e:?} · normal {n:?}");
            }
            assert!(dot(face_normal(&m, m.triangles[0]), *n) > 0.0);
        }
        // a mirror (scale z = -1 on a face with normal +x) keeps the face pointing where its
        // normals point
        let mut m = TriMesh { positions: vec![[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], normals: vec![[1.0, 0.0, 0.0]; 3], triangles: vec![[0, 1, 2]], colors: None };
        place(&mut m, &Pose::IDENTITY, [1.0, 1.0, -1.0]);
        assert_eq!(m.triangles, [[0, 2, 1]]);
        assert!(dot(face_normal(&m, m.triangles[0]), m.normals[0]) > 0.0);
    }

    /// The normals computed for a closed mesh point out: a tetrahedron's vertex normals point
    /// away from its centroid.
    #[test]
    fn computed_normals_of_a_closed_mesh_point_out() {
        let positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let triangles = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        let n = vertex_normals(&positions, &triangles);
        let c = [0.25f64; 3];
        for (p, n) in positions.iter().zip(&n) {
            let out = [0, 1, 2].map(|i| f64::from(p[i]) - c[i]);
            assert!(dot(out, *n) > 0.0, "{p:?}: {n:?}");
        }
    }

    /// The same link's visual COLLADA and collision STL (example-robot-data, as shipped) occupy
    /// the same box in the link frame: the COLLADA node transforms and units are applied as the
    /// STL's metres are (the collision hull is a little larger: within 1.5 cm per face).
    #[test]
    fn a_links_visual_dae_and_collision_stl_occupy_the_same_box() {
        for (dae, stl) in [
            ("panda_description/meshes/visual/hand.dae", "panda_description/meshes/collision/hand.stl"),
            ("panda_description/meshes/visual/finger.dae", "panda_description/meshes/collision/finger.stl"),
            ("ur_description/meshes/ur5/visual/base.dae", "ur_description/meshes/ur5/collision/base.stl"),
            ("ur_description/meshes/ur5/visual/wrist3.dae", "ur_description/meshes/ur5/collision/wrist3.stl"),
        ] {
            let load = |f: &str| load(&MeshRef { filename: erd(f), scale: [1.0; 3] }, &Pose::IDENTITY).unwrap().0;
            let (v, c) = (load(dae), load(stl));
            assert!(v.positions.len() > 100 && v.triangles.iter().flatten().all(|&i| (i as usize) < v.positions.len()), "{dae}");
            assert_eq!(v.normals.len(), v.positions.len(), "{dae}");
            assert!(v.colors.as_ref().is_some_and(|c| c.len() == v.positions.len()), "{dae}: the file's material colours");
            assert!(c.colors.is_none(), "{stl}: no colours in an STL");
            let ((vl, vh), (cl, ch)) = (bbox(&v), bbox(&c));
            for i in 0..3 {
                assert!((vl[i] - cl[i]).abs() < 0.015 && (vh[i] - ch[i]).abs() < 0.015, "{dae} {vl:?}..{vh:?} vs {stl} {cl:?}..{ch:?}");
            }
            assert!((0..3).any(|i| vh[i] - vl[i] > 0.02), "{dae}: a real part, not a point");
        }
    }

    #[test]
    fn only_local_files_are_read_and_a_missing_one_is_named() {
        assert!(local_path("package://pkg/m.stl").unwrap_err().contains("package_paths"));
        assert!(local_path("meshes/m.stl").unwrap_err().contains("relative"));
        assert!(local_path("https://example.com/m.stl").unwrap_err().contains("file://"));
        assert_eq!(local_path("file:///a/b.stl").unwrap(), PathBuf::from("/a/b.stl"));
        let m = |f: &str| MeshRef { filename: f.into(), scale: [1.0; 3] };
        assert_eq!(load(&m("file:///nonexistent/x.stl"), &Pose::IDENTITY).unwrap_err(), "no file /nonexistent/x.stl");
        assert!(load(&m(""), &Pose::IDENTITY).unwrap_err().contains("without a filename"));
        let flat = MeshRef { filename: "file:///a.stl".into(), scale: [1.0, 0.0, 1.0] };
        assert!(load(&flat, &Pose::IDENTITY).unwrap_err().contains("scale"));
        let dir = tempfile::tempdir().unwrap();
        assert!(load(&m(&format!("file://{}", dir.path().display())), &Pose::IDENTITY).unwrap_err().contains("not a regular file"));
        // a file that does not parse, and one of no known format, are named with the reason
        for (name, text) in [("broken.dae", "<COLLADA><library_geometries><geometry"), ("part.step", "ISO-10303-21;")] {
            let f = dir.path().join(name);
            std::fs::write(&f, text).unwrap();
            let why = load(&m(&format!("file://{}", f.display())), &Pose::IDENTITY).unwrap_err();
            assert!(why.starts_with(&format!("reading {}: ", f.display())), "{why}");
        }
    }

    /// [`draw`]: a present mesh becomes one `Mesh3D` entity; a missing one sends its link to
    /// its collision primitive (with a note), or, with no collision, leaves it out (a note);
    /// a link without a frame is noted; a link of primitives only is left to `entities`.
    #[test]
    fn missing_meshes_fall_back_to_collisions_or_a_note() {
        use super::super::urdf::links;
        let dir = tempfile::tempdir().unwrap();
        let stl = dir.path().join("tri.stl");
        std::fs::write(&stl, "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n").unwrap();
        let xml = format!(
            r#"<robot name="r">
              <link name="present"><visual><origin xyz="0 0 1"/><geometry><mesh filename="file://{}" scale="2 2 2"/></geometry>
                <material name="red"/></visual></link>
              <link name="fallback"><visual><geometry><mesh filename="package://p/gone.dae"/></geometry></visual>
                <collision><origin xyz="0 0 0.1"/><geometry><cylinder radius="0.02" length="0.2"/></geometry></collision></link>
              <link name="bare"><visual><geometry><mesh filename="file:///nonexistent/gone.stl"/></geometry></visual></link>
              <link name="unplaced"><visual><geometry><mesh filename="file:///nonexistent/x.stl"/></geometry></visual></link>
              <link name="primitive"><visual><geometry><box size="1 1 1"/></geometry></visual></link>
              <material name="red"><color rgba="1 0 0 1"/></material>
            </robot>"#,
            stl.display()
        );
        let links = links(&xml).unwrap();
        let mut chunks = Vec::new();
        let d = draw(&links, &|l: &str| (l != "unplaced").then(|| format!("/world/{l}")), &mut |c| {
            chunks.push(c);
            Ok(())
        })
        .unwrap();
        let paths: Vec<&str> = chunks.iter().map(|c| c.entity_path.as_str()).collect();
        assert_eq!(paths, ["/world/fallback/collision0", "/world/present/mesh0"]);
        assert_eq!((d.meshes, d.vertices, d.triangles), (1, 3, 1));
        assert_eq!(d.fallbacks, ["fallback"]);
        assert_eq!(d.notes.len(), 3, "{:?}", d.notes);
        assert!(d.notes[0].starts_with("link bare: not drawn, no collision geometry") && d.notes[0].contains("no file /nonexistent/gone.stl"), "{}", d.notes[0]);
        assert!(d.notes[1].starts_with("link fallback: drawn with its collision geometry") && d.notes[1].contains("package_paths"), "{}", d.notes[1]);
        assert!(d.notes[2].contains("unplaced") && d.notes[2].contains("no frame"), "{}", d.notes[2]);
        let fields = |c: &Chunk| c.columns.iter().map(|k| format!("{}:{}", k.archetype.rsplit('.').next().unwrap(), k.field)).collect::<Vec<_>>();
        assert!(fields(&chunks[0]).contains(&"Cylinders3D:radii".to_string()));
        let mesh = &chunks[1];
        assert_eq!(fields(mesh), ["Mesh3D:albedo_factor", "Mesh3D:triangle_indices", "Mesh3D:vertex_normals", "Mesh3D:vertex_positions"]);
        // scaled by 2, lifted by 1 m; the URDF's red
        let pos = mesh.columns[3].values.as_any().downcast_ref::<arrow_array::ListArray>().unwrap().value(0);
        let pos = pos.as_any().downcast_ref::<arrow_array::FixedSizeListArray>().unwrap();
        let v1 = pos.value(1);
        let v1 = v1.as_any().downcast_ref::<arrow_array::Float32Array>().unwrap();
        assert_eq!(v1.values().to_vec(), [2.0, 0.0, 1.0]);
        let albedo = mesh.columns[0].values.as_any().downcast_ref::<arrow_array::ListArray>().unwrap().value(0);
        assert_eq!(albedo.as_any().downcast_ref::<arrow_array::UInt32Array>().unwrap().value(0), rgba(255, 0, 0, 255));
    }
}
