//! Bad input to `sim`: scene JSON and URDF mutations of the built-in paper scene.
//!
//! - `table_of_bad_scenes`: one case per kind of mistake; each must be an `Err` from
//!   [`Scene::from_json`] whose message starts with the file name and names the field (or the
//!   URDF item) and the offending value.
//! - `cli_rejects_bad_scenes_with_status_2`: the same through the `sim` binary (`sim check` and
//!   a run): exit status 2, the message on stderr, no panic.
//! - `fuzzed_scenes_never_panic`: [`FUZZ_CASES`] = 10,000 generated scenes (random JSON-node
//!   replacements, key deletions, duplicated contacts, textual edits of the JSON, random byte and
//!   attribute edits of the URDF), fixed seed, each run under `catch_unwind`: the result is `Ok`
//!   or an error whose text starts with the file name. About 10 s in the test profile on 2 cores.

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

fn cases() -> Vec<Case> {
    use Edit::*;
    vec![
        // malformed JSON
        Case { what: "truncated JSON", edit: Text(|t| t[..t.len() / 2].to_string()), want: &["field `initial.q`", "EOF while parsing a list at line 54"] },
        Case {
            what: "trailing comma",
            edit: Text(|t| replace_nth(t, "\"offset\": 0.0\n", "\"offset\": 0.0,\n", 0)),
            want: &["field `contacts[0].plane`", "trailing comma at line 78"],
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
            want: &["field `duration` = 1e999", "number out of range"],
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
            want: &["target.ik.planar_joints[1]` = joint11", "no revolute joint"],
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
            want: &["paper_arm.urdf: link `link2`: inertial/mass = -0.1", "must be finite and >= 0"],
        },
        Case {
            what: "zero mass with an inertia",
            edit: Urdf(|u| replace_nth(u, r#"<mass value="0.1"/>"#, r#"<mass value="0"/>"#, 3)),
            want: &["paper_arm.urdf: link `link4`: inertial/mass = 0", "zero mass"],
        },
        Case {
            what: "NaN mass",
            edit: Urdf(|u| replace_nth(u, r#"<mass value="0.1"/>"#, r#"<mass value="nan"/>"#, 2)),
            want: &["link `link3`: inertial/mass = NaN", "finite"],
        },
        Case {
            what: "inertia not positive definite",
            edit: Urdf(|u| {
                replace_nth(u, LINK2_INERTIA, r#"<inertia ixx="0.0007525" ixy="0.001" ixz="0" iyy="0.0007525" iyz="0" izz="5e-06"/>"#, 0)
            }),
            want: &["link `link2`: inertial/inertia = ixx=0.0007525 ixy=0.001", "not positive semi-definite"],
        },
        Case {
            what: "negative moment",
            edit: Urdf(|u| replace_nth(u, LINK2_INERTIA, r#"<inertia ixx="-1e-3" ixy="0" ixz="0" iyy="0.0007525" iyz="0" izz="5e-06"/>"#, 0)),
            want: &["link `link2`: inertial/inertia = ixx=-0.001", "not positive semi-definite"],
        },
        Case {
            what: "inertia violating the triangle inequality",
            edit: Urdf(|u| replace_nth(u, LINK2_INERTIA, r#"<inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.005"/>"#, 0)),
            want: &["link `link2`: inertial/inertia = principal moments 0.001, 0.001, 0.005", "triangle inequality"],
        },
        Case {
            what: "infinite joint origin",
            edit: Urdf(|u| replace_nth(u, r#"<origin xyz="0 0 0.3" rpy="0 0 0"/>"#, r#"<origin xyz="0 0 inf" rpy="0 0 0"/>"#, 0)),
            want: &["joint `joint3`: origin = [0.0, 0.0, inf]", "finite"],
        },
        Case {
            what: "zero joint axis",
            edit: Urdf(|u| replace_nth(u, r#"<axis xyz="0 1 0"/>"#, r#"<axis xyz="0 0 0"/>"#, 0)),
            want: &["joint `joint2`: axis = [0.0, 0.0, 0.0]", "non-zero"],
        },
        // URDF: structure
        Case { what: "URDF not XML", edit: Urdf(|_| "this is not XML {".into()), want: &["urdf` = paper_arm.urdf", "paper_arm.urdf: the URDF could not be parsed"] },
        Case { what: "URDF truncated", edit: Urdf(|u| u[..u.len() / 2].to_string()), want: &["paper_arm.urdf: the URDF could not be parsed"] },
        Case { what: "URDF empty", edit: Urdf(|_| String::new()), want: &["paper_arm.urdf: the URDF could not be parsed"] },
        Case {
            what: "missing link",
            edit: Urdf(|u| without_link(u, "link5")),
            want: &["joint `joint5` refers to link `link5`", "does not define"],
        },
        Case {
            what: "duplicate link",
            edit: Urdf(|u| insert_before_end(u, r#"<link name="link3"/>"#)),
            want: &["link `link3`: name = link3", "defined twice"],
        },
        Case {
            what: "kinematic loop",
            edit: Urdf(|u| {
                insert_before_end(
                    u,
                    r#"<joint name="closing" type="revolute"><parent link="link10"/><child link="link3"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>"#,
                )
            }),
            want: &["link `link3` is the child of both `joint3` and `closing`", "loops"],
        },
        Case {
            what: "prismatic joint",
            edit: Urdf(|u| u.replace(r#"<joint name="joint5" type="revolute">"#, r#"<joint name="joint5" type="prismatic">"#)),
            want: &["joint `joint5` is of type `prismatic`", "not modelled"],
        },
        Case {
            what: "floating joint",
            edit: Urdf(|u| u.replace(r#"<joint name="joint8" type="revolute">"#, r#"<joint name="joint8" type="floating">"#)),
            want: &["joint `joint8` is of type `floating`", "not modelled"],
        },
        Case { what: "no joints", edit: Urdf(|_| r#"<robot name="r"><link name="base"/></robot>"#.into()), want: &["paper_arm.urdf: the URDF has no movable joint"] },
        Case {
            what: "two roots",
            edit: Urdf(|u| insert_before_end(u, r#"<link name="floating_box"/>"#)),
            want: &["one root", "\"base_link\", \"floating_box\""],
        },
        Case {
            what: "unknown joint type",
            edit: Urdf(|u| u.replace(r#"<joint name="joint2" type="revolute">"#, r#"<joint name="joint2" type="hinge">"#)),
            want: &["paper_arm.urdf: the URDF could not be parsed", "hinge"],
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
        if matches!(case.edit, Edit::Urdf(_)) && !msg.contains("field `urdf` = paper_arm.urdf: paper_arm.urdf: ") {
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

/// The unedited scene and URDF are valid (so every case above fails for its own edit).
#[test]
fn the_unedited_scene_is_valid() {
    build(PAPER_SCENE_JSON, PAPER_URDF, FILE).unwrap();
    let pretty = serde_json::to_string_pretty(&paper_json()).unwrap();
    build(&pretty, PAPER_URDF, FILE).unwrap();
}

fn sim(args: &[&std::ffi::OsStr]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_sim")).args(args).output().unwrap()
}

/// Through the binary: exit status 2, the file, field and value on stderr, no panic, no output.
#[test]
fn cli_rejects_bad_scenes_with_status_2() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, json: &str, urdf: &str| {
        let d = dir.path().join(name);
        std::fs::create_dir(&d).unwrap();
        std::fs::write(d.join("paper_arm.urdf"), urdf).unwrap();
        let p = d.join("scene.json");
        std::fs::write(&p, json).unwrap();
        p
    };
    let mut v = paper_json();
    v["motor"]["resistance"] = json!(-1.1);
    let negative_r = write("negative-r", &v.to_string(), PAPER_URDF);
    let truncated = write("truncated", &PAPER_SCENE_JSON[..300], PAPER_URDF);
    let infinite = write("infinite", &PAPER_SCENE_JSON.replace("\"duration\": 5.0", "\"duration\": 1e999"), PAPER_URDF);
    let prismatic = write(
        "prismatic",
        PAPER_SCENE_JSON,
        &PAPER_URDF.replace(r#"<joint name="joint5" type="revolute">"#, r#"<joint name="joint5" type="prismatic">"#),
    );
    let not_xml = write("not-xml", PAPER_SCENE_JSON, "<<<");
    let missing = dir.path().join("missing.json");
    let out_dir = dir.path().join("out");
    let cases: [(&std::path::Path, &[&str]); 6] = [
        (&negative_r, &["field `motor.resistance` = -1.1", "must be > 0 ohm"]),
        (&truncated, &["field `(document)`", "EOF while parsing"]),
        (&infinite, &["field `duration` = 1e999", "number out of range"]),
        (&prismatic, &["paper_arm.urdf: joint `joint5` is of type `prismatic`"]),
        (&not_xml, &["the URDF could not be parsed"]),
        (&missing, &["(file)"]),
    ];
    for (k, (path, want)) in cases.iter().enumerate() {
        // `sim check FILE` and, for some, a run (`sim FILE -o DIR`): nothing may be written
        let mut commands: Vec<Vec<&std::ffi::OsStr>> = vec![vec!["check".as_ref(), path.as_os_str()]];
        if k % 2 == 0 {
            commands.push(vec![path.as_os_str(), "-o".as_ref(), out_dir.as_os_str(), "--quiet".as_ref()]);
        }
        for args in commands {
            let out = sim(&args);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
            assert!(stderr.starts_with(&format!("sim: error: {}", path.display())), "{args:?}: {stderr}");
            for w in *want {
                assert!(stderr.contains(w), "{args:?}: {w:?} not in {stderr}");
            }
            assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
            assert!(out.stdout.is_empty(), "{args:?}: {}", String::from_utf8_lossy(&out.stdout));
        }
    }
    assert!(!out_dir.exists() || std::fs::read_dir(&out_dir).unwrap().next().is_none());
}

// ---------------------------------------------------------------------------------------------
// fuzzing

/// Generated scenes in `fuzzed_scenes_never_panic` (fixed seed, so the run is deterministic).
const FUZZ_CASES: usize = 10_000;
const FUZZ_SEED: u64 = 0x5EED_E1B0_0000_0001;

/// splitmix64: small, deterministic.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    fn chance(&mut self, p: f64) -> bool {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64 <= p
    }
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

const WORDS: &[&str] = &[
    "", "x", "joint1", "joint4", "joint7", "joint9", "joint10", "joint11", "link3", "hand", "base_link", "elbow4",
    "elbow7", "paper_arm.urdf", "dopri45", "rk4", "rosenbrock", "imex", "crba", "walker-orin", "schur", "kkt",
    "none", "baumgarte", "projection", "counter-clockwise", "clockwise", "positive", "negative", "NaN", "1e999",
    "é∑ü\u{0}", "two-elbow",
];
const KEYS: &[&str] = &[
    "name", "urdf", "duration", "output_rate", "motor", "resistance", "inductance", "kp", "joint", "link", "offset",
    "normal", "method", "rtol", "atol", "step", "h_max", "max_steps", "jacobian_reuse", "alpha", "beta", "contacts",
    "unknown", "",
];

fn random_number(r: &mut Rng) -> Value {
    match r.below(12) {
        0 => json!(0),
        1 => json!(-0.0),
        2 => json!(-1),
        3 => json!(1e300),
        4 => json!(-1e300),
        5 => json!(f64::MAX),
        6 => json!(5e-324),
        7 => json!(u64::MAX),
        8 => json!(i64::MIN),
        9 => json!(r.below(20)),
        _ => json!((r.next() as f64 / u64::MAX as f64 - 0.5) * 20.0),
    }
}

fn random_value(r: &mut Rng, depth: usize) -> Value {
    let kinds = if depth >= 3 { 5 } else { 7 };
    match r.below(kinds) {
        0 => Value::Null,
        1 => Value::Bool(r.chance(0.5)),
        2 | 3 => random_number(r),
        4 => {
            let w = *r.pick(WORDS);
            if r.chance(0.05) {
                json!(w.repeat(500))
            } else {
                json!(w)
            }
        }
        5 => {
            let n = *r.pick(&[0usize, 1, 2, 3, 3, 9, 10, 10, 11, 40]);
            let numeric = r.chance(0.7);
            Value::Array((0..n).map(|_| if numeric { random_number(r) } else { random_value(r, depth + 1) }).collect())
        }
        _ => {
            let n = r.below(4);
            Value::Object((0..n).map(|_| (r.pick(KEYS).to_string(), random_value(r, depth + 1))).collect())
        }
    }
}

/// Every node's path (object keys and array indices), the root included.
fn paths(v: &Value, prefix: &mut Vec<PathStep>, out: &mut Vec<Vec<PathStep>>) {
    out.push(prefix.clone());
    match v {
        Value::Object(m) => {
            for (k, c) in m {
                prefix.push(PathStep::Key(k.clone()));
                paths(c, prefix, out);
                prefix.pop();
            }
        }
        Value::Array(a) => {
            for (i, c) in a.iter().enumerate() {
                prefix.push(PathStep::Index(i));
                paths(c, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

#[derive(Clone, Debug)]
enum PathStep {
    Key(String),
    Index(usize),
}

fn node<'a>(v: &'a mut Value, path: &[PathStep]) -> &'a mut Value {
    path.iter().fold(v, |v, s| match s {
        PathStep::Key(k) => &mut v[k.as_str()],
        PathStep::Index(i) => &mut v[*i],
    })
}

fn mutate_json(r: &mut Rng, v: &mut Value) {
    for _ in 0..1 + r.below(3) {
        let mut all = Vec::new();
        paths(v, &mut Vec::new(), &mut all);
        match r.below(10) {
            // replace a random node (rarely the root)
            0..=5 => {
                let p = r.pick(&all).clone();
                if p.is_empty() && !r.chance(0.02) {
                    continue;
                }
                *node(v, &p) = random_value(r, 0);
            }
            // delete a random key, or a random array element
            6 | 7 => {
                let p = r.pick(&all).clone();
                if let Some((last, parent)) = p.split_last() {
                    match (node(v, parent), last) {
                        (Value::Object(m), PathStep::Key(k)) => {
                            m.remove(k);
                        }
                        (Value::Array(a), PathStep::Index(i)) => {
                            a.remove(*i);
                        }
                        _ => {}
                    }
                }
            }
            // duplicate a contact (same name, or renamed), or add an unknown key
            8 => {
                if let Some(cs) = v.get_mut("contacts").and_then(Value::as_array_mut) {
                    if !cs.is_empty() {
                        let mut c = cs[r.below(cs.len())].clone();
                        if r.chance(0.5) {
                            c["name"] = json!(format!("copy{}", r.below(100)));
                        }
                        cs.push(c);
                    }
                }
            }
            _ => {
                let p = r.pick(&all).clone();
                if let Value::Object(m) = node(v, &p) {
                    m.insert(r.pick(KEYS).to_string(), random_value(r, 1));
                }
            }
        }
    }
}

/// Textual edits the JSON model cannot express: huge exponents, truncation, trailing commas.
fn mutate_text(r: &mut Rng, text: &str) -> String {
    let mut t = text.to_string();
    match r.below(4) {
        0 => {
            // a number literal becomes out of range
            let nums: Vec<usize> = t.match_indices(": ").map(|(i, _)| i + 2).filter(|&i| t.as_bytes()[i].is_ascii_digit()).collect();
            if !nums.is_empty() {
                let i = *r.pick(&nums);
                t.insert_str(i, *r.pick(&["1e999", "-1e999", "1e999, ", "NaN", "-", "0x"]));
            }
        }
        1 => {
            let n = r.below(t.len());
            if t.is_char_boundary(n) {
                t.truncate(n);
            }
        }
        2 => {
            let closers: Vec<usize> = t.match_indices(['}', ']']).map(|(i, _)| i).collect();
            if !closers.is_empty() {
                t.insert(*r.pick(&closers), ',');
            }
        }
        _ => {
            let i = r.below(t.len());
            if t.is_char_boundary(i) {
                t.insert(i, *r.pick(&['"', '{', '[', ':', ',', '\\', 'e', '\u{0}']));
            }
        }
    }
    t
}

const ATTR_VALUES: &[&str] = &[
    "-1", "0", "1", "nan", "NaN", "inf", "-inf", "1e999", "", "abc", "1 2", "0 0 0", "0 0 0 0", "1e-300", "1e300",
    "joint3", "link5", "link10", "base_link", "hand", "prismatic", "floating", "continuous", "fixed", "planar",
    "revolute", "0.0007525", "-0.0007525", "5e-06",
];

fn mutate_urdf(r: &mut Rng, urdf: &str) -> String {
    let mut b = urdf.as_bytes().to_vec();
    for _ in 0..1 + r.below(3) {
        if b.is_empty() {
            break;
        }
        match r.below(5) {
            // an attribute value replaced
            0 | 1 => {
                let text = String::from_utf8_lossy(&b).into_owned();
                let starts: Vec<usize> = text.match_indices("=\"").map(|(i, _)| i + 2).collect();
                if let Some(&s) = (!starts.is_empty()).then(|| r.pick(&starts)) {
                    let e = s + text[s..].find('"').unwrap_or(0);
                    let val = if r.chance(0.3) { format!("{}", (r.next() as f64 / u64::MAX as f64 - 0.5) * 10.0) } else { r.pick(ATTR_VALUES).to_string() };
                    b.splice(s..e, val.into_bytes());
                }
            }
            // a byte replaced
            2 => {
                let i = r.below(b.len());
                b[i] = *r.pick(b"<>/\"= abcz019.-e\n");
            }
            // a range deleted
            3 => {
                let i = r.below(b.len());
                let n = (1 + r.below(60)).min(b.len() - i);
                b.drain(i..i + n);
            }
            // a range duplicated (repeats elements: links, joints, attributes)
            _ => {
                let i = r.below(b.len());
                let n = (1 + r.below(400)).min(b.len() - i);
                let copy = b[i..i + n].to_vec();
                let at = r.below(b.len());
                b.splice(at..at, copy);
            }
        }
    }
    String::from_utf8_lossy(&b).into_owned()
}

/// [`FUZZ_CASES`] generated scenes (see the module docs): `Scene::from_json` never panics and
/// every error starts with the file name.
#[test]
fn fuzzed_scenes_never_panic() {
    let base = paper_json();
    let mut r = Rng(FUZZ_SEED);
    let (mut ok, mut err) = (0usize, 0usize);
    let mut kinds = [0usize; 4];
    for case in 0..FUZZ_CASES {
        let kind = r.below(4);
        kinds[kind] += 1;
        let (json, urdf) = match kind {
            0 | 1 => {
                let mut v = base.clone();
                mutate_json(&mut r, &mut v);
                (v.to_string(), PAPER_URDF.to_string())
            }
            2 => {
                let text = if r.chance(0.5) { PAPER_SCENE_JSON.to_string() } else { base.to_string() };
                (mutate_text(&mut r, &text), PAPER_URDF.to_string())
            }
            _ => (PAPER_SCENE_JSON.to_string(), mutate_urdf(&mut r, PAPER_URDF)),
        };
        let file = "fuzz.json";
        match catch_unwind(AssertUnwindSafe(|| build(&json, &urdf, file))) {
            Ok(Ok(_)) => ok += 1,
            Ok(Err(msg)) => {
                assert!(
                    msg.starts_with(&format!("{file}: ")) && msg.len() > file.len() + 2,
                    "case {case}: error without the file name: {msg}\nscene: {json}\nurdf: {urdf}"
                );
                err += 1;
            }
            Err(_) => panic!("case {case}: Scene::from_json panicked\nscene: {json}\nurdf: {urdf}"),
        }
    }
    eprintln!("fuzzed_scenes_never_panic: {FUZZ_CASES} cases ({kinds:?} by kind), {ok} accepted, {err} rejected");
    assert_eq!(ok + err, FUZZ_CASES);
    // the generator reaches both outcomes
    assert!(ok > 100 && err > FUZZ_CASES / 2, "{ok} accepted, {err} rejected");
}
