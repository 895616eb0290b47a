//! Issue 27 item 1, acceptance: `analyze view` on the published UR5, Panda and Z1
//! (example-robot-data URDFs with the meshes shipped in `sim/scenes/published/`, package paths
//! given by the scenes there) writes a file in which the arm is drawn.
//!
//! Per arm: `sim` runs the scene; its recorded URDF names every mesh by an absolute `file://`
//! URI (what Foxglove's URDF panel and `analyze view` read); `analyze view` writes the `.rrd`,
//! exit 0, with one note per link that is not drawn from its visual mesh. The `.rrd` is read
//! back chunk by chunk (RRD framing, Arrow IPC) and, against the recorded URDF and the files
//! present: every link whose visual mesh file exists has a `Mesh3D` entity `…/<link>/mesh<k>`,
//! every link whose visual mesh is missing is drawn from its collision geometry
//! (`…/collision<k>`) or named in a note; each mesh has vertices, triangles indexing them and
//! one unit normal per vertex; and at every recorded sample, every vertex of every mesh,
//! placed by the recorded link poses (the `Transform3D` chain of its entity path), lies within
//! the arm's published reach of its base (plus the hand and the base's own size) and above
//! the floor, while the arm drawn spans at least half that reach. `rerun rrd verify` (the
//! venv's rerun-sdk 0.41; `skip.rs` policy) passes on each file.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use analyze::view::pose::Pose;
use analyze::view::urdf::{self, Geometry};
use arrow_array::{Array, FixedSizeListArray, Float32Array, ListArray, RecordBatch, UInt32Array};

use crate::{run_analyze, run_sim};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The chunks of the recording store of an `.rrd`, in file order (RRD framing, each chunk
/// decompressed and read with arrow's IPC reader).
pub(crate) fn batches(bytes: &[u8]) -> Vec<RecordBatch> {
    use prost::Message;
    let mut out = Vec::new();
    let mut i = 12;
    while i + 16 <= bytes.len() {
        let kind = u64::from_le_bytes(bytes[i..i + 8].try_into().unwrap());
        let len = u64::from_le_bytes(bytes[i + 8..i + 16].try_into().unwrap()) as usize;
        let payload = &bytes[i + 16..i + 16 + len];
        i += 16 + len;
        match kind {
            analyze::view::rrd::KIND_END => break,
            analyze::view::rrd::KIND_ARROW_MSG => {
                let msg = analyze::view::rrd::ArrowMsg::decode(payload).unwrap();
                out.push(analyze::view::rrd::payload_batch(&msg).unwrap());
            }
            _ => {}
        }
    }
    out
}

fn path_of(b: &RecordBatch) -> String {
    b.schema().metadata()["rerun:entity_path"].clone()
}

/// Row `row` of the `List<FixedSizeList<f32, N>>` column `name`, as N-vectors.
fn vecs<const N: usize>(b: &RecordBatch, name: &str, row: usize) -> Vec<[f32; N]> {
    let list = b.column_by_name(name).unwrap_or_else(|| panic!("{}: no {name}", path_of(b)));
    let items = list.as_any().downcast_ref::<ListArray>().unwrap().value(row);
    let fixed = items.as_any().downcast_ref::<FixedSizeListArray>().unwrap();
    let flat = fixed.values().as_any().downcast_ref::<Float32Array>().unwrap();
    (0..fixed.len()).map(|k| std::array::from_fn(|j| flat.value(k * N + j))).collect()
}

/// A `Mesh3D` entity read back.
struct Mesh {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
}

fn mesh(b: &RecordBatch) -> Mesh {
    let list = b.column_by_name("Mesh3D:triangle_indices").unwrap();
    let items = list.as_any().downcast_ref::<ListArray>().unwrap().value(0);
    let fixed = items.as_any().downcast_ref::<FixedSizeListArray>().unwrap();
    let flat = fixed.values().as_any().downcast_ref::<UInt32Array>().unwrap();
    let triangles = (0..fixed.len()).map(|k| [flat.value(3 * k), flat.value(3 * k + 1), flat.value(3 * k + 2)]).collect();
    Mesh { positions: vecs::<3>(b, "Mesh3D:vertex_positions", 0), normals: vecs::<3>(b, "Mesh3D:vertex_normals", 0), triangles }
}

/// Each frame entity's poses in its parent, per `sim_time` row (windows concatenated).
fn transforms(batches: &[RecordBatch]) -> BTreeMap<String, Vec<Pose>> {
    let mut out: BTreeMap<String, Vec<Pose>> = BTreeMap::new();
    for b in batches.iter().filter(|b| b.column_by_name("Transform3D:translation").is_some()) {
        let poses = out.entry(path_of(b)).or_default();
        for row in 0..b.num_rows() {
            let t = vecs::<3>(b, "Transform3D:translation", row)[0].map(f64::from);
            let q = vecs::<4>(b, "Transform3D:quaternion", row)[0].map(f64::from);
            poses.push(Pose { translation: t, rotation: q });
        }
    }
    out
}

/// The world pose of entity `path` at sample `k`: its ancestors' transforms composed.
fn world_pose(tf: &BTreeMap<String, Vec<Pose>>, path: &str, k: usize) -> Pose {
    let mut pose = Pose::IDENTITY;
    let mut prefix = String::new();
    for part in path.trim_start_matches('/').split('/') {
        prefix.push('/');
        prefix.push_str(part);
        if let Some(p) = tf.get(&prefix) {
            pose = pose.compose(&p[k]);
        }
    }
    pose
}

struct Arm {
    scene: &'static str,
    /// The published reach, m (datasheets: UR5 850 mm, Panda 855 mm, Z1 740 mm).
    reach_m: f64,
    /// Mesh entities expected with the shipped subset (README of `sim/scenes/published`).
    meshes: usize,
}

const ARMS: [Arm; 3] = [
    Arm { scene: "ur5", reach_m: 0.85, meshes: 7 },
    Arm { scene: "panda", reach_m: 0.855, meshes: 11 },
    Arm { scene: "z1", reach_m: 0.74, meshes: 3 },
];

/// Beyond the reach (measured at the wrist or flange): the hand, the gripper and the base's
/// own size, m.
const MARGIN_M: f64 = 0.3;

pub(crate) fn rerun_cli(test: &str) -> Option<PathBuf> {
    let python = std::env::var_os("ELBOW_RERUN_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(std::env::var_os("HOME").unwrap_or_default()).join(".cache/elbow-sim/venv-check/bin/python"));
    let rerun = python.parent().map(|d| d.join("rerun")).filter(|r| r.is_file());
    if rerun.is_none() {
        crate::skip::skip(test, &format!("no `rerun` next to {} (rerun-sdk 0.41; make the venv as .ci/run does)", python.display()));
    }
    rerun
}

#[test]
fn published_arms_are_drawn_with_their_meshes() {
    let dir = tempfile::tempdir().unwrap();
    let rerun = rerun_cli("rerun_meshes::published_arms_are_drawn_with_their_meshes");
    for arm in ARMS {
        let scene = root().join(format!("sim/scenes/published/{}.json", arm.scene));
        let o = run_sim(&[Path::new("run"), scene.as_path(), Path::new("-q"), Path::new("-o"), dir.path()]);
        assert!(o.status.success(), "sim {}: {}", arm.scene, String::from_utf8_lossy(&o.stderr));
        let mcap = dir.path().join(format!("published-{}-move.mcap", arm.scene));

        // the recorded URDF names each mesh by an absolute file:// URI (Foxglove and `view`)
        let rec = schemas::read_recording(&mcap).unwrap();
        let xml = rec.record::<schemas::UrdfRecord>().unwrap().xml;
        let links = urdf::links(&xml).unwrap();
        let refs: Vec<&urdf::MeshRef> = links
            .values()
            .flat_map(|l| l.visuals.iter().chain(&l.collisions))
            .filter_map(|e| match &e.geometry {
                Geometry::Mesh(m) => Some(m),
                Geometry::Primitive(_) => None,
            })
            .collect();
        assert!(!refs.is_empty());
        for m in &refs {
            assert!(m.filename.starts_with("file:///") && m.filename.contains("/example-robot-data/robots/"), "{}: {}", arm.scene, m.filename);
        }

        let rrd = dir.path().join(format!("{}.rrd", arm.scene));
        let o = run_analyze(&[Path::new("view"), mcap.as_path(), Path::new("-o"), rrd.as_path()]);
        let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
        assert!(o.status.success(), "analyze view {}: {stderr}", arm.scene);
        let batches = batches(&std::fs::read(&rrd).unwrap());
        let meshes: BTreeMap<String, Mesh> = batches.iter().filter(|b| b.column_by_name("Mesh3D:vertex_positions").is_some()).map(|b| (path_of(b), mesh(b))).collect();
        let entity = |link: &str, leaf: &str| meshes.keys().find(|p| p.ends_with(&format!("/{link}/{leaf}"))).cloned();
        let exists = |m: &urdf::MeshRef| Path::new(m.filename.trim_start_matches("file://")).is_file();

        // each link: its visual mesh when the file is there, else its collisions, else a note
        for (link, g) in &links {
            for (k, v) in g.visuals.iter().enumerate() {
                let Geometry::Mesh(m) = &v.geometry else { continue };
                if exists(m) {
                    assert!(entity(link, &format!("mesh{k}")).is_some(), "{}: link {link} has no mesh{k}: {:?}", arm.scene, meshes.keys());
                    continue;
                }
                let note = stderr.lines().find(|l| l.contains("note:") && l.contains(&format!("link {link}:"))).unwrap_or_else(|| panic!("{}: no note on {link}: {stderr}", arm.scene));
                let file = m.filename.rsplit('/').next().unwrap();
                assert!(note.contains(file) && note.contains("no file"), "{note}");
                for (j, c) in g.collisions.iter().enumerate() {
                    match &c.geometry {
                        Geometry::Mesh(cm) if exists(cm) => assert!(entity(link, &format!("collision{j}")).is_some(), "{}: {link} collision{j}", arm.scene),
                        Geometry::Mesh(_) => assert!(note.contains("collision"), "{note}"),
                        Geometry::Primitive(_) => assert!(
                            batches.iter().any(|b| path_of(b).ends_with(&format!("/{link}/collision{j}")) && b.column_by_name("Cylinders3D:radii").is_some()
                                || b.column_by_name("Boxes3D:half_sizes").is_some() && path_of(b).ends_with(&format!("/{link}/collision{j}"))
                                || b.column_by_name("Ellipsoids3D:half_sizes").is_some() && path_of(b).ends_with(&format!("/{link}/collision{j}"))),
                            "{}: {link} collision{j} primitive",
                            arm.scene
                        ),
                    }
                }
                if g.collisions.is_empty() {
                    assert!(note.contains("not drawn"), "{note}");
                }
            }
        }
        assert_eq!(meshes.len(), arm.meshes, "{}: {:?}", arm.scene, meshes.keys());

        // each mesh: vertices, triangles within them, one unit normal per vertex
        for (p, m) in &meshes {
            assert!(!m.positions.is_empty() && !m.triangles.is_empty(), "{p}");
            assert!(m.triangles.iter().flatten().all(|&i| (i as usize) < m.positions.len()), "{p}");
            assert_eq!(m.normals.len(), m.positions.len(), "{p}");
            assert!(m.normals.iter().all(|n| ((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() - 1.0).abs() < 1e-4), "{p}");
        }

        // at every sample, every vertex placed by the recorded poses: within reach, above the
        // floor; the arm spans at least half its reach
        let tf = transforms(&batches);
        let samples = tf.values().map(Vec::len).max().unwrap();
        assert_eq!(samples, rec.read::<schemas::Transforms>().unwrap().len(), "{}", arm.scene);
        let mut farthest = 0.0f64;
        for k in 0..samples {
            let mut lo = [f64::MAX; 3];
            let mut hi = [f64::MIN; 3];
            for (p, m) in &meshes {
                let x = world_pose(&tf, p.rsplit_once('/').unwrap().0, k);
                for v in &m.positions {
                    let w = x.apply(v.map(f64::from));
                    let r = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
                    assert!(r <= arm.reach_m + MARGIN_M, "{}: {p} at sample {k}: a vertex {r:.3} m from the base", arm.scene);
                    assert!(w[2] >= -0.02, "{}: {p} at sample {k}: a vertex at z = {:.3} m", arm.scene, w[2]);
                    farthest = farthest.max(r);
                    for i in 0..3 {
                        lo[i] = lo[i].min(w[i]);
                        hi[i] = hi[i].max(w[i]);
                    }
                }
            }
            assert!(hi[2] - lo[2] > 0.25, "{}: sample {k}: the arm drawn is {:.3} m tall", arm.scene, hi[2] - lo[2]);
        }
        assert!(farthest >= 0.5 * arm.reach_m, "{}: the farthest vertex is {farthest:.3} m from the base", arm.scene);

        if let Some(rerun) = &rerun {
            let v = Command::new(rerun).args(["rrd", "verify"]).arg(&rrd).output().expect("rerun starts");
            let said = format!("{}{}", String::from_utf8_lossy(&v.stdout), String::from_utf8_lossy(&v.stderr));
            assert!(v.status.success() && said.contains("verified without error"), "rerun rrd verify {}: {said}", arm.scene);
        }
    }
}
