//! Bad input to `sim`: scene JSON and URDF mutations of the built-in paper scene.
//!
//! - `table_of_bad_scenes`: one case per kind of mistake; each must be an `Err` from
//!   [`Scene::from_json`] whose message starts with the file name and names the field (or the
//!   URDF item) and the offending value.
//! - the same through the `sim` binary: `tests/e2e/sim_bad_input.rs` (root package).
//! - the 10,000-case fuzz of the scene reader is in `fuzz_scenes.rs`.

use std::panic::{catch_unwind, AssertUnwindSafe};

use serde_json::{json, Value};
use sim::scene::{Scene, PAPER_SCENE_JSON, PAPER_URDF};

const FILE: &str = "edited.json";

fn paper_json() -> Value {
    serde_json::from_str(PAPER_SCENE_JSON).unwrap()
}

fn build(json: &str, urdf: &str, file: &str) -> Result<Scene, String> {
    let urdf = urdf.to_string();
    Scene::from_json(json, file, move |name| {
        if name == "paper_arm.urdf" {
            Ok(urdf.clone())
        } else {
            Err(format!("no file `{name}`"))
        }
    })
    .map_err(|e| e.to_string())
}

/// How a case changes the paper scene.
enum Edit {
    /// Edit the parsed JSON.
    Json(fn(&mut Value)),
    /// Replace the JSON text.
    Text(fn(&str) -> String),
    /// Replace the URDF text.
    Urdf(fn(&str) -> String),
}

struct Case {
    what: &'static str,
    edit: Edit,
    /// Every one of these must be in the message (the field or URDF item, the value, why).
    want: &'static [&'static str],
}

/// Replaces the `n`-th (0-based) occurrence of `from` in `s`.
fn replace_nth(s: &str, from: &str, to: &str, n: usize) -> String {
    let (i, _) = s.match_indices(from).nth(n).unwrap_or_else(|| panic!("no {from:?} #{n}"));
    format!("{}{to}{}", &s[..i], &s[i + from.len()..])
}

/// The `<link name="NAME">…</link>` element removed.
fn without_link(s: &str, name: &str) -> String {
    let start = s.find(&format!("<link name=\"{name}\">")).unwrap();
    let end = start + s[start..].find("</link>").unwrap() + "</link>".len();
    format!("{}{}", &s[..start], &s[end..])
}

fn insert_before_end(s: &str, xml: &str) -> String {
    s.replace("</robot>", &format!("{xml}\n</robot>"))
}

const LINK2_INERTIA: &str = r#"<inertia ixx="0.0007525" ixy="0" ixz="0" iyy="0.0007525" iyz="0" izz="5e-06"/>"#;

/// (Line numbers are the paper scene's, whose first key is `"$schema"` on line 2; half of it now
/// ends inside a number of `initial.q`, one line further on.)
fn cases() -> Vec<Case> {
    use Edit::*;
    vec![
        // malformed JSON
        Case { what: "truncated JSON", edit: Text(|t| t[..t.len() / 2].to_string()), want: &["field `initial.q[3]`", "EOF while parsing a value at line 55"] },
        Case {
            what: "trailing comma",
            edit: Text(|t| replace_nth(t, "\"offset\": 0.0\n", "\"offset\": 0.0,\n", 0)),
            want: &["field `contacts[0].plane`", "trailing comma at line 79"],
        },
        Case { what: "empty file", edit: Text(|_| String::new()), want: &["(document)", "EOF while parsing"] },
        Case { what: "not an object", edit: Text(|_| "[1, 2, 3]".into()), want: &["field `[0]`", "integer `1`, expected a string"] },
        // unknown keys
        Case { what: "unknown top-level key", edit: Json(|v| v["colour"] = json!("red")), want: &["unknown field `colour`"] },
        Case { what: "unknown nested key", edit: Json(|v| v["motor"]["resistnce"] = json!(1.0)), want: &["motor", "unknown field `resistnce`"] },
        Case {
            what: "unknown key in a contact",
            edit: Json(|v| v["contacts"][1]["plane"]["normale"] = json!([0, 0, 1])),
            want: &["contacts[1].plane", "unknown field `normale`"],
        },
        // wrong types
        Case { what: "string for a number", edit: Json(|v| v["duration"] = json!("five")), want: &["duration", "\"five\"", "expected f64"] },
        Case { what: "number for a string", edit: Json(|v| v["urdf"] = json!(42)), want: &["urdf", "integer `42`", "expected a string"] },
        Case { what: "object for an array", edit: Json(|v| v["runs"] = json!({"a": 1})), want: &["runs", "invalid type: map"] },
        Case {
            what: "string in a per-joint array",
            edit: Json(|v| v["initial"]["q"][3] = json!("x")),
            want: &["initial.q", "string \"x\"", "expected f64"],
        },
        Case { what: "gravity of 2 numbers", edit: Json(|v| v["gravity"] = json!([0, -9.81])), want: &["gravity", "invalid length 2"] },
        Case { what: "null for a required value", edit: Json(|v| v["output_rate"] = Value::Null), want: &["output_rate", "null"] },
        Case {
            what: "unknown integrator",
            edit: Json(|v| v["integrator"]["method"] = json!("euler")),
            want: &["integrator.method", "unknown variant `euler`"],
        },
        // infinite numbers in JSON
        Case {
            what: "1e999",
            edit: Text(|t| t.replace("\"duration\": 5.0", "\"duration\": 1e999")),
            want: &["field `duration` = 1e999", "number out of range at line 11 column 19"],
        },
        Case {
            what: "-1e999 in an array",
            edit: Text(|t| replace_nth(t, "-9.81", "-1e999", 0)),
            want: &["gravity", "= -1e999", "number out of range"],
        },
        // numbers out of their range
        Case { what: "zero resistance", edit: Json(|v| v["motor"]["resistance"] = json!(0.0)), want: &["motor.resistance` = 0", "> 0 ohm"] },
        Case {
            what: "negative resistance on one joint",
            edit: Json(|v| v["motor"]["resistance"] = json!([1.1, 1.1, 1.1, 1.1, -2.5, 1.1, 1.1, 1.1, 1.1, 1.1])),
            want: &["motor.resistance[4]` = -2.5", "> 0 ohm"],
        },
        Case {
            what: "negative inductance",
            edit: Json(|v| v["motor"]["inductance"] = json!(-0.0017)),
            want: &["motor.inductance` = -0.0017", ">= 0 H"],
        },
        Case {
            what: "mixed zero and non-zero inductance",
            edit: Json(|v| v["motor"]["inductance"] = json!([0.0, 0.0017, 0.0017, 0.0017, 0.0017, 0.0017, 0.0017, 0.0017, 0.0017, 0.0017])),
            want: &["motor.inductance` = [0.0, 0.0017", "0 on every joint"],
        },
        Case {
            what: "per-joint array of the wrong length",
            edit: Json(|v| v["controller"]["kp"] = json!([500, 500])),
            want: &["controller.kp` = an array of 2", "one value per joint (10)"],
        },
        Case { what: "zero duration", edit: Json(|v| v["duration"] = json!(0)), want: &["duration` = 0", "> 0 s"] },
        Case {
            what: "huge duration",
            edit: Json(|v| v["duration"] = json!(1e300)),
            want: &["field `duration` = 1e300: duration = 1e300 s at output_rate = 1000 Hz gives 1.000e303 samples, more than the limit of 10^8 per run"],
        },
        Case {
            what: "huge output rate",
            edit: Json(|v| v["output_rate"] = json!(1e9)),
            want: &["field `output_rate` = 1e9: duration = 5 s at output_rate = 1e9 Hz gives 5.000e9 samples"],
        },
        Case {
            what: "a single sample",
            edit: Json(|v| v["output_rate"] = json!(0.001)),
            want: &["field `output_rate` = 0.001", "a single sample (t = 0) in duration = 5 s", "output_rate >= 1 / duration = 0.2 Hz"],
        },
        Case {
            what: "max_steps of 0",
            edit: Json(|v| v["integrator"]["max_steps"] = json!(0)),
            want: &["field `integrator.max_steps` = 0", "must be >= 1"],
        },
        Case {
            what: "rk4 step too small for the step budget",
            edit: Json(|v| v["integrator"] = json!({"method": "rk4", "step": 1e-12})),
            want: &["field `integrator.step` = 1e-12", "gives 5.000e12 steps", "limit of 100000000"],
        },
        Case { what: "negative gain", edit: Json(|v| v["controller"]["kd"] = json!(-20)), want: &["controller.kd` = -20", ">= 0"] },
        Case { what: "zero plane normal", edit: Json(|v| v["contacts"][0]["plane"]["normal"] = json!([0, 0, 0])), want: &["contacts[0].plane.normal", "non-zero"] },
        Case { what: "rtol of 1", edit: Json(|v| v["integrator"]["rtol"] = json!(1.0)), want: &["integrator.rtol` = 1", "[1e-14, 1)"] },
        Case { what: "bad name", edit: Json(|v| v["name"] = json!("a/b")), want: &["name` = \"a/b\"", "letters, digits"] },
        // contacts, runs and the target
        Case {
            what: "contact on a joint that does not exist",
            edit: Json(|v| v["contacts"][0]["point"]["joint"] = json!("joint42")),
            want: &["contacts[0].point.joint` = joint42", "no such joint"],
        },
        Case {
            what: "contact on a link that does not exist",
            edit: Json(|v| v["contacts"][1]["point"] = json!({"link": "link99"})),
            want: &["contacts[1].point.link` = link99", "no such link"],
        },
        Case {
            what: "contact with both joint and link",
            edit: Json(|v| v["contacts"][1]["point"]["link"] = json!("link7")),
            want: &["contacts[1].point", "exactly one of"],
        },
        Case {
            what: "duplicate contact",
            edit: Json(|v| {
                let c = v["contacts"][0].clone();
                v["contacts"].as_array_mut().unwrap().push(c);
            }),
            want: &["contacts[2].name` = elbow4", "used twice"],
        },
        Case {
            what: "run naming a missing contact",
            edit: Json(|v| v["runs"][1]["contacts"][0] = json!("elbow9")),
            want: &["runs[1].contacts[0]` = elbow9", "no contact of that name"],
        },
        Case {
            what: "unreachable target",
            edit: Json(|v| v["target"]["circle"]["center"] = json!([3.5, 3.5, 0.4])),
            want: &["target` = t = 0.0000 s", "outside its reach"],
        },
        Case {
            what: "IK joint that does not exist",
            edit: Json(|v| v["target"]["ik"]["planar_joints"][1] = json!("joint11")),
            want: &["target.ik.planar_joints[1]` = joint11", "no movable joint"],
        },
        Case {
            what: "missing URDF file",
            edit: Json(|v| v["urdf"] = json!("other.urdf")),
            want: &["urdf` = other.urdf", "no file `other.urdf`"],
        },
        // URDF: masses and inertias
        Case {
            what: "negative mass",
            edit: Urdf(|u| replace_nth(u, r#"<mass value="0.1"/>"#, r#"<mass value="-0.1"/>"#, 1)),
            want: &["paper_arm.urdf:29: <link name=\"link2\"><inertial>: <mass value=\"-0.1\">", "must be finite and >= 0"],
        },
        Case {
            what: "zero mass with an inertia",
            edit: Urdf(|u| replace_nth(u, r#"<mass value="0.1"/>"#, r#"<mass value="0"/>"#, 3)),
            want: &["paper_arm.urdf:49: <link name=\"link4\"><inertial>: <mass value=\"0\">", "zero mass"],
        },
        Case {
            what: "NaN mass",
            edit: Urdf(|u| replace_nth(u, r#"<mass value="0.1"/>"#, r#"<mass value="nan"/>"#, 2)),
            want: &["<link name=\"link3\"><inertial>: <mass value=\"NaN\">", "finite"],
        },
        Case {
            what: "inertia not positive definite",
            edit: Urdf(|u| {
                replace_nth(u, LINK2_INERTIA, r#"<inertia ixx="0.0007525" ixy="0.001" ixz="0" iyy="0.0007525" iyz="0" izz="5e-06"/>"#, 0)
            }),
            want: &["<link name=\"link2\"><inertial>: <inertia ixx=0.0007525 ixy=0.001", "not positive semi-definite", "\"robot\": {\"repair_inertia\": true}"],
        },
        Case {
            what: "negative moment",
            edit: Urdf(|u| replace_nth(u, LINK2_INERTIA, r#"<inertia ixx="-1e-3" ixy="0" ixz="0" iyy="0.0007525" iyz="0" izz="5e-06"/>"#, 0)),
            want: &["<link name=\"link2\"><inertial>: <inertia ixx=-0.001", "not positive semi-definite"],
        },
        Case {
            what: "inertia violating the triangle inequality",
            edit: Urdf(|u| replace_nth(u, LINK2_INERTIA, r#"<inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.005"/>"#, 0)),
            want: &["<link name=\"link2\"><inertial>: <inertia ixx=0.001 ixy=0 ixz=0 iyy=0.001 iyz=0 izz=0.005>: principal moments 0.001, 0.001, 0.005", "triangle inequality"],
        },
        Case {
            what: "infinite joint origin",
            edit: Urdf(|u| replace_nth(u, r#"<origin xyz="0 0 0.3" rpy="0 0 0"/>"#, r#"<origin xyz="0 0 inf" rpy="0 0 0"/>"#, 0)),
            want: &["paper_arm.urdf:33: <joint name=\"joint3\">: <origin xyz=\"0 0 inf\"", "finite"],
        },
        Case {
            what: "zero joint axis",
            edit: Urdf(|u| replace_nth(u, r#"<axis xyz="0 1 0"/>"#, r#"<axis xyz="0 0 0"/>"#, 0)),
            want: &["paper_arm.urdf:23: <joint name=\"joint2\">: <axis xyz=\"0 0 0\">", "non-zero"],
        },
        // URDF: structure
        Case { what: "URDF not XML", edit: Urdf(|_| "this is not XML {".into()), want: &["urdf` = paper_arm.urdf", "paper_arm.urdf:1: the URDF could not be parsed"] },
        Case { what: "URDF truncated", edit: Urdf(|u| u[..u.len() / 2].to_string()), want: &["paper_arm.urdf:60: the URDF could not be parsed"] },
        Case { what: "URDF empty", edit: Urdf(|_| String::new()), want: &["paper_arm.urdf:1: the URDF could not be parsed"] },
        Case {
            what: "missing link",
            edit: Urdf(|u| without_link(u, "link5")),
            want: &["paper_arm.urdf:53: <joint name=\"joint5\">: <child link=\"link5\">: the URDF defines no link `link5`"],
        },
        Case {
            what: "duplicate link",
            edit: Urdf(|u| insert_before_end(u, r#"<link name="link3"/>"#)),
            want: &["<link name=\"link3\">: defined twice (first on line 38)"],
        },
        Case {
            what: "kinematic loop",
            edit: Urdf(|u| {
                insert_before_end(
                    u,
                    r#"<joint name="closing" type="revolute"><parent link="link10"/><child link="link3"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>"#,
                )
            }),
            want: &["<joint name=\"closing\">: link `link3` is the child of both `joint3` (line 33) and this joint", "loops"],
        },
        Case {
            what: "planar joint",
            edit: Urdf(|u| u.replace(r#"<joint name="joint5" type="revolute">"#, r#"<joint name="joint5" type="planar">"#)),
            want: &["paper_arm.urdf:53: <joint name=\"joint5\">: type=\"planar\": only fixed-base arms are modelled"],
        },
        Case {
            what: "floating joint",
            edit: Urdf(|u| u.replace(r#"<joint name="joint8" type="revolute">"#, r#"<joint name="joint8" type="floating">"#)),
            want: &["paper_arm.urdf:83: <joint name=\"joint8\">: type=\"floating\": only fixed-base arms", "\"robot\": {\"locked\": {\"joint8\": 0.0}}"],
        },
        Case { what: "no joints", edit: Urdf(|_| r#"<robot name="r"><link name="base"/></robot>"#.into()), want: &["paper_arm.urdf: the URDF has no movable joint"] },
        Case {
            what: "two roots",
            edit: Urdf(|u| insert_before_end(u, r#"<link name="floating_box"/>"#)),
            want: &["one root", "\"base_link\", \"floating_box\""],
        },
        Case {
            what: "duplicate joint name",
            edit: Urdf(|u| u.replace(r#"<joint name="joint6" type="revolute">"#, r#"<joint name="joint5" type="revolute">"#)),
            want: &["paper_arm.urdf:63: <joint name=\"joint5\">: defined twice (first on line 53)"],
        },
        Case {
            what: "URDF nested too deep",
            edit: Urdf(|u| insert_before_end(u, &format!("{}{}", "<a>".repeat(200_000), "</a>".repeat(200_000)))),
            want: &["paper_arm.urdf: elements nested more than 100 deep", "refused before parsing"],
        },
        Case {
            what: "URDF with too many joints",
            edit: Urdf(|u| {
                let chain: String = (0..1000)
                    .map(|k| format!(r#"<link name="x{k}"/><joint name="xj{k}" type="fixed"><parent link="{}"/><child link="x{k}"/></joint>"#, if k == 0 { "hand".to_string() } else { format!("x{}", k - 1) }))
                    .collect();
                insert_before_end(u, &chain)
            }),
            want: &["paper_arm.urdf: 1011 joints, more than the limit of 1000"],
        },
        Case {
            what: "unknown joint type",
            edit: Urdf(|u| u.replace(r#"<joint name="joint2" type="revolute">"#, r#"<joint name="joint2" type="hinge">"#)),
            want: &["paper_arm.urdf:23: <joint name=\"joint2\">: unknown joint type `hinge`"],
        },
    ]
}

#[test]
fn table_of_bad_scenes() {
    let cases = cases();
    let mut failures = Vec::new();
    for case in &cases {
        let (json, urdf) = match &case.edit {
            Edit::Json(f) => {
                let mut v = paper_json();
                f(&mut v);
                (serde_json::to_string_pretty(&v).unwrap(), PAPER_URDF.to_string())
            }
            Edit::Text(f) => (f(PAPER_SCENE_JSON), PAPER_URDF.to_string()),
            Edit::Urdf(f) => (PAPER_SCENE_JSON.to_string(), f(PAPER_URDF)),
        };
        let result = catch_unwind(AssertUnwindSafe(|| build(&json, &urdf, FILE)));
        let msg = match result {
            Err(_) => {
                failures.push(format!("{}: panicked", case.what));
                continue;
            }
            Ok(Ok(_)) => {
                failures.push(format!("{}: accepted", case.what));
                continue;
            }
            Ok(Err(m)) => m,
        };
        if !msg.starts_with(&format!("{FILE}: ")) {
            failures.push(format!("{}: does not start with the file name: {msg}", case.what));
        }
        if matches!(case.edit, Edit::Urdf(_)) && !msg.contains("field `urdf` = paper_arm.urdf: paper_arm.urdf:") {
            failures.push(format!("{}: does not name the URDF file: {msg}", case.what));
        }
        for want in case.want {
            if !msg.contains(want) {
                failures.push(format!("{}: {want:?} not in: {msg}", case.what));
            }
        }
    }
    assert!(failures.is_empty(), "{} of {} cases wrong:\n{}", failures.len(), cases.len(), failures.join("\n"));
    assert!(cases.len() >= 50);
}

/// Files that are not files, or too large, are refused before they are read whole (a device
/// such as /dev/zero would otherwise be read until memory runs out), naming the file and the
/// limit; a URDF next to the scene likewise, naming the scene's `urdf` field.
#[test]
fn scene_and_urdf_files_are_bounded() {
    use std::path::Path;
    let dir = tempfile::tempdir().unwrap();
    let msg = |p: &Path| Scene::load(p).unwrap_err().to_string();
    #[cfg(unix)]
    {
        let m = msg(Path::new("/dev/zero"));
        assert_eq!(m, "/dev/zero: field `(file)`: not a regular file (it is a character device); give the path of a file");
    }
    let m = msg(dir.path());
    assert!(m.contains("not a regular file (it is a directory)"), "{m}");
    let big = dir.path().join("big.json");
    std::fs::File::create(&big).unwrap().set_len(20 << 30).unwrap(); // sparse
    let m = msg(&big);
    assert!(m.starts_with(&format!("{}: field `(file)`: more than the limit of 4194304 bytes", big.display())), "{m}");
    // the URDF: a device, then a sparse file above the limit
    let scene = dir.path().join("s.json");
    for (urdf, want) in [("/dev/zero", "not a regular file (it is a character device)"), ("big.urdf", "more than the limit of 4194304 bytes")] {
        let mut v = paper_json();
        v["urdf"] = json!(urdf);
        std::fs::write(&scene, v.to_string()).unwrap();
        if urdf == "big.urdf" {
            std::fs::File::create(dir.path().join(urdf)).unwrap().set_len(1 << 30).unwrap();
        } else if !cfg!(unix) {
            continue;
        }
        let m = msg(&scene);
        assert!(m.starts_with(&format!("{}: field `urdf` = {urdf}: cannot read ", scene.display())) && m.contains(want), "{m}");
    }
    // the same scene with the real URDF loads
    std::fs::write(dir.path().join("paper_arm.urdf"), PAPER_URDF).unwrap();
    std::fs::write(&scene, PAPER_SCENE_JSON).unwrap();
    Scene::load(&scene).unwrap();
}

/// The limits leave room: a URDF nested 100 deep and one with 1000 joints are accepted.
#[test]
fn urdf_limits_leave_room() {
    let deep = insert_before_end(PAPER_URDF, &format!("{}{}", "<a>".repeat(98), "</a>".repeat(98)));
    build(PAPER_SCENE_JSON, &deep, FILE).unwrap();
    let chain: String = (0..989)
        .map(|k| format!(r#"<link name="x{k}"/><joint name="xj{k}" type="fixed"><parent link="{}"/><child link="x{k}"/></joint>"#, if k == 0 { "hand".to_string() } else { format!("x{}", k - 1) }))
        .collect();
    let s = build(PAPER_SCENE_JSON, &insert_before_end(PAPER_URDF, &chain), FILE).unwrap();
    assert_eq!(s.model().urdf_joints.len(), 1000);
}

/// The unedited scene and URDF are valid (so every case above fails for its own edit).
#[test]
fn the_unedited_scene_is_valid() {
    build(PAPER_SCENE_JSON, PAPER_URDF, FILE).unwrap();
    let pretty = serde_json::to_string_pretty(&paper_json()).unwrap();
    build(&pretty, PAPER_URDF, FILE).unwrap();
}
