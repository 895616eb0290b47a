//! Issue 27 item 2: the contact shapes of issue 23 drawn as they are, in both viewers, checked
//! from the entities (as the Foxglove checks are).
//!
//! One scene of three planar bodies (prismatic x, prismatic z, revolute pitch about world y,
//! each from its own origin at y = 0, 0.5, 1.0 m): a ball with a sphere pad (`pad`, r = 0.1 m,
//! thrown along the table: it slides, then rolls), a rod with a capsule (`table.points`: the
//! contacts `rod/0`, `rod/1`, r = 0.04 m, the segment ±0.3 m along the rod) released tilted by
//! 30° on one end, and a drum whose URDF `<collision>` cylinder (r = 0.05 m, length 0.4 m along
//! its x axis) gives the two rim contacts `drum/c0/0`, `drum/c0/1` (`table.from_collisions`),
//! released tilted by 20° on one rim. `sim` records it and `analyze view` converts it. Then:
//! - the metadata (record `contacts`) carries each contact's shape as the scene gave it:
//!   kind, radius, link and the link-frame centre (and the rims' axis ±x);
//! - `/scene` (Foxglove) has one entity per shape in its link's frame, frame-locked: the pad a
//!   sphere of diameter 0.2 m at the link origin, the capsule a cylinder 0.08 × 0.08 × 0.6 m
//!   along the link's x axis with its end spheres at x = ±0.3 m, the drum a cylinder
//!   0.1 × 0.1 × 0.4 m along x with its two rims, every rim point 0.05 m from its centre in the
//!   plane x = ±0.2 m (1e-12);
//! - at every sample of `/contact_markers`, each contact's marker is where the shape touches,
//!   from the recorded joint positions by the closed forms (the sphere's centre less r ẑ; a rim
//!   tilted by θ: its centre less r (sin θ, 0, cos θ)), 1e-9 m, and on the table (|z| ≤ 1e-6 m)
//!   whenever its mode is sticking or sliding; a contact separated at a sample (`/contacts`) is
//!   not drawn at it, in either viewer;
//! - the `.rrd`: the same shapes below each link's entity (`Ellipsoids3D`, `Capsules3D`,
//!   `Cylinders3D` and the rims' `LineStrips3D`, same numbers in f32), and at every sample each
//!   Rerun marker where the Foxglove one is (2e-6 m, f32); `rerun rrd verify` passes on it.
//!
//! A recording without shapes (the paper's) writes none of this: its `/scene` is as it was
//! (`recordings/refresh.sh --check`).

use std::collections::BTreeMap;
use std::path::Path;

use arrow_array::{Array, FixedSizeListArray, Float32Array, ListArray, RecordBatch};
use schemas::Value;

use crate::{run_analyze, run_sim};

const R_BALL: f64 = 0.1;
const R_CAP: f64 = 0.04;
const H_ROD: f64 = 0.3;
const R_DRUM: f64 = 0.05;
const H_DRUM: f64 = 0.2;
/// The bodies' origins along y, m (ball, rod, drum).
const Y0: [f64; 3] = [0.0, 0.5, 1.0];

fn urdf() -> String {
    let lim = r#"<limit lower="-1000" upper="1000" effort="1e6" velocity="1e3"/>"#;
    let branch = |tag: &str, y: f64, body: &str, inertia: [f64; 3], extra: &str| {
        let [ixx, iyy, izz] = inertia;
        format!(
            r#"
  <joint name="{tag}x" type="prismatic"><parent link="base"/><child link="{tag}cx"/><origin xyz="0 {y} 0"/><axis xyz="1 0 0"/>{lim}</joint>
  <link name="{tag}cx"/>
  <joint name="{tag}z" type="prismatic"><parent link="{tag}cx"/><child link="{tag}cz"/><origin xyz="0 0 0"/><axis xyz="0 0 1"/>{lim}</joint>
  <link name="{tag}cz"/>
  <joint name="{tag}pitch" type="continuous"><parent link="{tag}cz"/><child link="{body}"/><origin xyz="0 0 0"/><axis xyz="0 1 0"/></joint>
  <link name="{body}">{extra}<inertial><origin xyz="0 0 0"/><mass value="1"/><inertia ixx="{ixx}" ixy="0" ixz="0" iyy="{iyy}" iyz="0" izz="{izz}"/></inertial></link>"#
        )
    };
    let ib = 0.4 * R_BALL * R_BALL;
    let (ir, id) = (H_ROD * H_ROD / 3.0, H_DRUM * H_DRUM / 3.0);
    let drum = format!(
        r#"<collision><origin xyz="0 0 0" rpy="0 1.5707963267948966 0"/><geometry><cylinder radius="{R_DRUM}" length="{}"/></geometry></collision>"#,
        2.0 * H_DRUM
    );
    format!(
        "<?xml version=\"1.0\"?>\n<robot name=\"shapes\">\n  <link name=\"base\"/>{}{}{}\n</robot>\n",
        branch("b", Y0[0], "ball", [ib; 3], ""),
        branch("r", Y0[1], "rod", [1e-6, ir, ir], ""),
        branch("d", Y0[2], "drum", [1e-6, id, id], &drum)
    )
}

/// The initial tilts of the rod and the drum, rad.
const TILT_ROD: f64 = 30.0 * std::f64::consts::PI / 180.0;
const TILT_DRUM: f64 = 20.0 * std::f64::consts::PI / 180.0;

fn scene() -> serde_json::Value {
    let q0 = [
        0.0,
        R_BALL,
        0.0,
        0.0,
        R_CAP + H_ROD * TILT_ROD.sin(),
        -TILT_ROD,
        0.0,
        H_DRUM * TILT_DRUM.sin() + R_DRUM * TILT_DRUM.cos(),
        -TILT_DRUM,
    ];
    let joints = ["bx", "bz", "bpitch", "rx", "rz", "rpitch", "dx", "dz", "dpitch"];
    let plane = serde_json::json!({"normal": [0.0, 0.0, 1.0], "offset": 0.0});
    serde_json::json!({
        "$schema": "../../../../sim/scenes/scene.schema.json", "name": "shapes", "urdf": "shapes.urdf", "gravity": [0.0, 0.0, -9.81], "duration": 0.5, "output_rate": 1000.0,
        "joint_damping": 0.0,
        "motor": {"torque_constant": 0.5, "resistance": 1.0, "inductance": 0.0, "rotor_inertia": 1e-5, "gear_ratio": 1.0, "gear_damping": 0.0},
        "controller": {"kp": 0.0, "kd": 0.0}, "passive": joints, "hand": {"link": "ball"},
        "target": {"kind": "joint-spline", "waypoints": [{"t": 0.0, "q": q0}, {"t": 1.0, "q": q0}]},
        "initial": {"q": q0, "qd": [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]},
        "contacts": [{"name": "pad", "point": {"link": "ball"}, "plane": plane, "model": "unilateral", "friction": 0.3,
                      "shape": {"kind": "sphere", "radius": R_BALL}}],
        "table": {"plane": plane, "model": "unilateral",
                  "points": [{"name": "rod", "point": {"link": "rod", "offset": [-H_ROD, 0.0, 0.0]},
                              "shape": {"kind": "capsule", "radius": R_CAP, "to": {"link": "rod", "offset": [H_ROD, 0.0, 0.0]}}}],
                  "from_collisions": ["drum"]},
        "integrator": {"method": "dopri45", "rtol": 1e-8, "atol": 1e-10},
        "runs": [{"name": "bodies", "contacts": ["pad"]}]
    })
}

/// Each contact: (name, body index 0..3, kind, radius, link-frame centre).
fn expected() -> Vec<(&'static str, usize, &'static str, f64, [f64; 3])> {
    vec![
        ("pad", 0, "sphere", R_BALL, [0.0; 3]),
        ("rod/0", 1, "sphere", R_CAP, [-H_ROD, 0.0, 0.0]),
        ("rod/1", 1, "sphere", R_CAP, [H_ROD, 0.0, 0.0]),
        ("drum/c0/0", 2, "rim", R_DRUM, [-H_DRUM, 0.0, 0.0]),
        ("drum/c0/1", 2, "rim", R_DRUM, [H_DRUM, 0.0, 0.0]),
    ]
}

const LINKS: [&str; 3] = ["ball", "rod", "drum"];

/// Where contact `k` of [`expected`] touches at joint positions `q` (closed forms: body `b` at
/// (x, y0, z) turned by θ about +y, `R_y(θ) (ox, 0, oz) = (ox cos θ + oz sin θ, 0,
/// −ox sin θ + oz cos θ)`; a sphere touches r below its centre; a rim whose axis is the
/// body's x axis, `(cos θ, 0, −sin θ)`, at its centre less r (sin θ, 0, cos θ) when cos θ > 0).
fn touching(k: usize, q: &[f64]) -> [f64; 3] {
    let (_, b, kind, r, o) = expected()[k];
    let (x, z, th) = (q[3 * b], q[3 * b + 1], q[3 * b + 2]);
    let c = [x + o[0] * th.cos() + o[2] * th.sin(), Y0[b] + o[1], z - o[0] * th.sin() + o[2] * th.cos()];
    match kind {
        "sphere" => [c[0], c[1], c[2] - r],
        _ => {
            assert!(th.cos() > 0.5, "the drum stays within 60° of flat: θ = {th}");
            [c[0] - r * th.sin(), c[1], c[2] - r * th.cos()]
        }
    }
}

fn num(v: &Value, path: &str) -> f64 {
    v.get(path).and_then(Value::as_f64).unwrap_or(0.0)
}

fn xyz(v: &Value, path: &str) -> [f64; 3] {
    ["x", "y", "z"].map(|a| num(v, &if path.is_empty() { a.to_string() } else { format!("{path}.{a}") }))
}

fn list<'a>(v: &'a Value, path: &str) -> &'a [Value] {
    v.get(path).and_then(Value::as_list).unwrap_or(&[])
}

fn entity<'a>(msg: &'a Value, id: &str) -> &'a Value {
    list(msg, "entities").iter().find(|e| e.get("id").and_then(Value::as_str) == Some(id)).unwrap_or_else(|| panic!("no entity {id}"))
}

fn meta(e: &Value, key: &str) -> String {
    list(e, "metadata").iter().find(|kv| kv.get("key").and_then(Value::as_str) == Some(key)).and_then(|kv| kv.get("value")?.as_str()).unwrap_or("").to_string()
}

fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() <= tol)
}

/// The unit z axis of the orientation at `path` of `v`, turned into the parent frame.
fn z_axis(v: &Value, path: &str) -> [f64; 3] {
    let q = ["x", "y", "z", "w"].map(|a| num(v, &format!("{path}.{a}")));
    schemas::markers::rotate(q, [0.0, 0.0, 1.0])
}

fn path_of(b: &RecordBatch) -> String {
    b.schema().metadata()["rerun:entity_path"].clone()
}

fn f32_rows<const N: usize>(b: &RecordBatch, name: &str) -> Vec<Vec<[f64; N]>> {
    let list = b.column_by_name(name).unwrap_or_else(|| panic!("{}: no {name}", path_of(b)));
    let list = list.as_any().downcast_ref::<ListArray>().unwrap();
    (0..list.len())
        .map(|row| {
            let items = list.value(row);
            let fixed = items.as_any().downcast_ref::<FixedSizeListArray>().unwrap();
            let flat = fixed.values().as_any().downcast_ref::<Float32Array>().unwrap();
            (0..fixed.len()).map(|k| std::array::from_fn(|j| flat.value(k * N + j) as f64)).collect()
        })
        .collect()
}

fn scalars(b: &RecordBatch, name: &str) -> Vec<f64> {
    let list = b.column_by_name(name).unwrap_or_else(|| panic!("{}: no {name}", path_of(b)));
    let list = list.as_any().downcast_ref::<ListArray>().unwrap();
    let items = list.value(0);
    let flat = items.as_any().downcast_ref::<Float32Array>().unwrap();
    (0..flat.len()).map(|k| flat.value(k) as f64).collect()
}

fn one<'a>(batches: &'a [RecordBatch], suffix: &str, column: &str) -> &'a RecordBatch {
    batches
        .iter()
        .find(|b| path_of(b).ends_with(suffix) && b.column_by_name(column).is_some())
        .unwrap_or_else(|| panic!("no entity …{suffix} with {column}: {:?}", batches.iter().map(path_of).collect::<std::collections::BTreeSet<_>>()))
}

/// The scene as the book keeps it (`docs/screenshots.sh` pictures it): the files in
/// [`DEMO`] are this test's scene and URDF (`ELBOW_BLESS=1` rewrites them).
const DEMO: &str = "docs/src/how-to/contact-shapes";

fn make(dir: &Path) -> (std::path::PathBuf, std::path::PathBuf) {
    let (scene_text, urdf_text) = (serde_json::to_string_pretty(&scene()).unwrap() + "\n", urdf());
    let demo = Path::new(env!("CARGO_MANIFEST_DIR")).join(DEMO);
    if std::env::var_os("ELBOW_BLESS").is_some() {
        std::fs::create_dir_all(&demo).unwrap();
        std::fs::write(demo.join("shapes.json"), &scene_text).unwrap();
        std::fs::write(demo.join("shapes.urdf"), &urdf_text).unwrap();
    }
    for (file, text) in [("shapes.json", &scene_text), ("shapes.urdf", &urdf_text)] {
        let kept = std::fs::read_to_string(demo.join(file)).unwrap_or_default();
        assert!(kept == *text, "{DEMO}/{file} is not this test's scene: run the test with ELBOW_BLESS=1 and commit it");
    }
    std::fs::write(dir.join("shapes.urdf"), &urdf_text).unwrap();
    std::fs::write(dir.join("shapes.json"), &scene_text).unwrap();
    let out = dir.join("out");
    let o = run_sim(&["run", dir.join("shapes.json").to_str().unwrap(), "-q", "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "sim: {}", String::from_utf8_lossy(&o.stderr));
    let mcap = out.join("shapes-bodies.mcap");
    let rrd = out.join("shapes-bodies.rrd");
    let o = run_analyze(&["view", mcap.to_str().unwrap(), "-o", rrd.to_str().unwrap()]);
    assert!(o.status.success(), "analyze view: {}", String::from_utf8_lossy(&o.stderr));
    (mcap, rrd)
}

#[test]
fn contact_shapes_are_drawn_as_they_are_in_both_viewers() {
    let dir = tempfile::tempdir().unwrap();
    let (mcap, rrd) = make(dir.path());
    let rec = schemas::read_recording(&mcap).unwrap();

    // the metadata: each contact's shape as the scene gave it
    let record = rec.record::<schemas::ContactsRecord>().unwrap();
    let names: Vec<&str> = record.contacts.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, expected().iter().map(|e| e.0).collect::<Vec<_>>());
    for (c, (name, b, kind, r, o)) in record.contacts.iter().zip(expected()) {
        let s = c.shape.as_ref().unwrap_or_else(|| panic!("{name}: no shape in the record"));
        assert_eq!((s.kind.as_str(), s.radius, s.link.as_str()), (kind, r, LINKS[b]), "{name}");
        assert!(close(s.center, o, 1e-12), "{name}: centre {:?}, scene {o:?}", s.center);
        match kind {
            "rim" => assert!(s.axis.is_some_and(|a| (a[0].abs() - 1.0).abs() <= 1e-12 && a[1].abs() <= 1e-12 && a[2].abs() <= 1e-12), "{name}: {:?}", s.axis),
            _ => assert_eq!(s.axis, None, "{name}"),
        }
    }

    // /scene: one entity per shape, in its link's frame, frame-locked
    let scene = &rec.messages(schemas::topics::SCENE).unwrap()[0].1;
    let pad = entity(scene, "shape/pad");
    assert_eq!((pad.get("frame_id").and_then(Value::as_str), pad.get("frame_locked").and_then(Value::as_f64)), (Some("ball"), Some(1.0)));
    assert_eq!((meta(pad, "kind").as_str(), meta(pad, "radius_m").as_str()), ("sphere", "0.1"));
    assert!(close(xyz(pad, "spheres.0.pose.position"), [0.0; 3], 1e-15) && close(xyz(pad, "spheres.0.size"), [0.2; 3], 1e-15));
    let rod = entity(scene, "shape/rod");
    assert_eq!((rod.get("frame_id").and_then(Value::as_str), rod.get("frame_locked").and_then(Value::as_f64)), (Some("rod"), Some(1.0)));
    assert_eq!((meta(rod, "kind").as_str(), meta(rod, "contacts").as_str()), ("capsule", "rod/0, rod/1"));
    assert!(close(xyz(rod, "cylinders.0.size"), [2.0 * R_CAP, 2.0 * R_CAP, 2.0 * H_ROD], 1e-15), "{:?}", xyz(rod, "cylinders.0.size"));
    assert!(close(xyz(rod, "cylinders.0.pose.position"), [0.0; 3], 1e-15));
    assert!(close(z_axis(rod, "cylinders.0.pose.orientation"), [1.0, 0.0, 0.0], 1e-12), "{:?}", z_axis(rod, "cylinders.0.pose.orientation"));
    let ends: Vec<[f64; 3]> = list(rod, "spheres").iter().map(|s| xyz(s, "pose.position")).collect();
    assert_eq!(ends, [[-H_ROD, 0.0, 0.0], [H_ROD, 0.0, 0.0]]);
    assert!(list(rod, "spheres").iter().all(|s| close(xyz(s, "size"), [2.0 * R_CAP; 3], 1e-15)));
    let drum = entity(scene, "shape/drum/c0");
    assert_eq!((drum.get("frame_id").and_then(Value::as_str), meta(drum, "kind").as_str()), (Some("drum"), "cylinder"));
    assert!(close(xyz(drum, "cylinders.0.size"), [2.0 * R_DRUM, 2.0 * R_DRUM, 2.0 * H_DRUM], 1e-15));
    assert!(close(z_axis(drum, "cylinders.0.pose.orientation").map(f64::abs), [1.0, 0.0, 0.0], 1e-12));
    let rims = list(drum, "lines");
    assert_eq!(rims.len(), 2);
    for (line, cx) in rims.iter().zip([-H_DRUM, H_DRUM]) {
        let pts = list(line, "points");
        assert_eq!(pts.len(), schemas::markers::CONTACT_RING_POINTS);
        for p in pts {
            let [x, y, z] = xyz(p, "");
            assert!((x - cx).abs() <= 1e-12 && ((y * y + z * z).sqrt() - R_DRUM).abs() <= 1e-12, "rim at x = {cx}: ({x}, {y}, {z})");
        }
    }

    // /contact_markers at every sample: the marker where the shape touches
    let q: Vec<Vec<f64>> = rec.read::<schemas::JointState>().unwrap().into_iter().map(|(_, j)| j.position).collect();
    let markers = rec.messages(schemas::topics::CONTACT_MARKERS).unwrap();
    let states = rec.read::<schemas::ContactState>().unwrap();
    assert_eq!(markers.len(), q.len());
    assert_eq!(states.len(), q.len());
    assert!(q.len() > 400, "{} samples", q.len());
    let mut fox: Vec<Vec<[f64; 3]>> = vec![Vec::new(); expected().len()];
    let (mut closed, mut worst, mut separated) = (0, 0.0f64, 0);
    for (((_, m), q), (_, st)) in markers.iter().zip(&q).zip(&states) {
        for (k, (name, ..)) in expected().into_iter().enumerate() {
            // a separated contact is not drawn (deleted when it separates): Rerun neither
            let id = format!("contact/{name}");
            let i = st.name.iter().position(|n| n == name).unwrap_or_else(|| panic!("{name} not on /contacts"));
            let shown = list(m, "entities").iter().any(|e| e.get("id").and_then(Value::as_str) == Some(id.as_str()));
            assert_eq!(shown, st.mode[i] != schemas::contact_mode::SEPARATED, "t = {} s, {name}: mode {}, drawn {shown}", st.time, st.mode[i]);
            if !shown {
                separated += 1;
                fox[k].push([f64::NAN; 3]);
                continue;
            }
            let e = entity(m, &id);
            let p = xyz(e, "spheres.0.pose.position");
            let want = touching(k, q);
            worst = worst.max((0..3).map(|i| (p[i] - want[i]).abs()).fold(0.0, f64::max));
            assert!(close(p, want, 1e-9), "t = {} s, {name}: marker at {p:?}, the shape touches at {want:?}", num(e, "timestamp.sec") + 1e-9 * num(e, "timestamp.nsec"));
            let mode = meta(e, "mode");
            if mode == "sticking" || mode == "sliding" {
                closed += 1;
                assert!(p[2].abs() <= 1e-6, "{name} is {mode} with its marker {} m off the table", p[2]);
            }
            fox[k].push(p);
        }
    }
    eprintln!("contact shapes: markers at the closed-form touching points within {worst:e} m; {closed} closed marker-samples on the table; {separated} separated ones not drawn");
    assert!(closed > 1000, "the contacts touch the table: {closed}");

    // the .rrd: the same shapes below the links, the same markers
    let bytes = std::fs::read(&rrd).unwrap();
    let batches = crate::rerun_meshes::batches(&bytes);
    let b = one(&batches, "/ball/contact_shape/pad", "Ellipsoids3D:half_sizes");
    assert!(close(f32_rows::<3>(b, "Ellipsoids3D:half_sizes")[0][0], [R_BALL; 3], 1e-7) && close(f32_rows::<3>(b, "Ellipsoids3D:centers")[0][0], [0.0; 3], 0.0));
    let b = one(&batches, "/rod/contact_shape/rod", "Capsules3D:lengths");
    assert_eq!((scalars(b, "Capsules3D:lengths"), scalars(b, "Capsules3D:radii")), (vec![(2.0 * H_ROD) as f32 as f64], vec![R_CAP as f32 as f64]));
    assert!(close(f32_rows::<3>(b, "Capsules3D:translations")[0][0], [-H_ROD, 0.0, 0.0], 1e-7));
    let q = f32_rows::<4>(b, "Capsules3D:quaternions")[0][0];
    assert!(close(schemas::markers::rotate(q, [0.0, 0.0, 1.0]), [1.0, 0.0, 0.0], 1e-6), "capsule axis {q:?}");
    let b = one(&batches, "/drum/contact_shape/drum\\/c0", "Cylinders3D:lengths");
    assert_eq!((scalars(b, "Cylinders3D:lengths"), scalars(b, "Cylinders3D:radii")), (vec![(2.0 * H_DRUM) as f32 as f64], vec![R_DRUM as f32 as f64]));
    let q = f32_rows::<4>(b, "Cylinders3D:quaternions")[0][0];
    assert!(close(schemas::markers::rotate(q, [0.0, 0.0, 1.0]).map(f64::abs), [1.0, 0.0, 0.0], 1e-6), "cylinder axis {q:?}");
    let b = one(&batches, "/drum/contact_shape/drum\\/c0/rims", "LineStrips3D:strips");
    let strips = b.column_by_name("LineStrips3D:strips").unwrap().as_any().downcast_ref::<ListArray>().unwrap().value(0);
    let strips = strips.as_any().downcast_ref::<ListArray>().unwrap();
    assert_eq!(strips.len(), 2);
    for (s, cx) in (0..2).zip([-H_DRUM, H_DRUM]) {
        let fixed = strips.value(s);
        let fixed = fixed.as_any().downcast_ref::<FixedSizeListArray>().unwrap();
        let flat = fixed.values().as_any().downcast_ref::<Float32Array>().unwrap();
        assert_eq!(fixed.len(), schemas::markers::CONTACT_RING_POINTS + 1, "a closed strip");
        for k in 0..fixed.len() {
            let [x, y, z] = [0, 1, 2].map(|j| flat.value(3 * k + j) as f64);
            assert!((x - cx).abs() <= 1e-6 && ((y * y + z * z).sqrt() - R_DRUM).abs() <= 1e-6, "Rerun rim at x = {cx}: ({x}, {y}, {z})");
        }
    }
    let mut rerun: BTreeMap<String, Vec<[f64; 3]>> = BTreeMap::new();
    for b in batches.iter().filter(|b| path_of(b).starts_with("/world/contacts/") && b.column_by_name("Points3D:positions").is_some()) {
        // a row without a point: the contact is separated at that sample, not drawn
        rerun.entry(path_of(b)).or_default().extend(f32_rows::<3>(b, "Points3D:positions").into_iter().map(|row| row.first().copied().unwrap_or([f64::NAN; 3])));
    }
    for (k, (name, ..)) in expected().into_iter().enumerate() {
        let path = format!("/world/contacts/{}", analyze::view::run::escape(name));
        let pts = rerun.get(&path).unwrap_or_else(|| panic!("no Rerun marker {path}: {:?}", rerun.keys()));
        assert_eq!(pts.len(), fox[k].len(), "{name}");
        for (i, (a, b)) in pts.iter().zip(&fox[k]).enumerate() {
            let (a_shown, b_shown) = (!a[0].is_nan(), !b[0].is_nan());
            assert_eq!(a_shown, b_shown, "{name}, sample {i}: drawn in Rerun {a_shown}, in Foxglove {b_shown}");
            assert!(!a_shown || close(*a, *b, 2e-6), "{name}, sample {i}: Rerun {a:?}, Foxglove {b:?}");
        }
    }

    if let Some(rerun) = crate::rerun_meshes::rerun_cli("rerun_contact_shapes::contact_shapes_are_drawn_as_they_are_in_both_viewers") {
        let o = std::process::Command::new(rerun).args(["rrd", "verify"]).arg(&rrd).output().expect("rerun starts");
        assert!(o.status.success(), "rerun rrd verify {}: {}", rrd.display(), String::from_utf8_lossy(&o.stderr));
    }
}
