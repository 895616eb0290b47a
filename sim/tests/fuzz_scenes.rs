//! Fuzzing the scene reader and the runs (issue 12: no panic, every run ends):
//!
//! - `fuzzed_scenes_never_panic`: [`FUZZ_CASES`] = 10,000 generated scenes (random JSON-node
//!   replacements, key deletions, duplicated contacts, textual edits of the JSON, random byte and
//!   attribute edits of the URDF), fixed seed, each built under `catch_unwind`: the result is
//!   `Ok` or an error whose text starts with the file name. Every accepted scene is then RUN
//!   (one of its runs, picked by the generator) within a wall budget of [`RUN_WALL`] and a
//!   step budget of [`RUN_MAX_STEPS`]: it must complete or fail with a typed error, never panic,
//!   and end within its budget plus [`RUN_SLACK`].
//! - `fuzzed_urdfs_never_panic`: [`URDF_CASES`] = 2,000 generated bad URDFs (deep nesting up to
//!   200,000 levels, chains of up to 5,000 joints, duplicate joint and link names, random
//!   elements inserted and repeated, the byte edits above), and `input_files_are_bounded`:
//!   devices, FIFOs, directories, sparse files of 1 TB and files just over the size limit, as a
//!   scene and as its URDF.
//!
//! The counts are printed (`-- --nocapture`). About 1 min in the test profile on 2 cores.
//! Larger runs (another seed, more cases):
//! `FUZZ_CASES=100000 FUZZ_SEED=7 cargo test --profile test -p sim --test all fuzz_scenes -- --nocapture`
//! (`FUZZ_CASES` scales both generators: URDF cases are a fifth of it).
//! (The table of hand-written bad inputs is in `bad_input.rs`; the runaway cases in
//! `runaway.rs`.)

use std::panic::{catch_unwind, AssertUnwindSafe};

use std::time::{Duration, Instant};

use serde_json::{json, Value};
use sim::error::RunError;
use sim::run::Budget;
use sim::scene::spec::IntegratorSpec;
use sim::scene::{Scene, PAPER_SCENE_JSON, PAPER_URDF};


fn paper_json() -> Value {
    serde_json::from_str(PAPER_SCENE_JSON).expect("the built-in scene is JSON")
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

// ---------------------------------------------------------------------------------------------
// fuzzing

/// Generated scenes in `fuzzed_scenes_never_panic` (fixed seed, so the run is deterministic);
/// the environment variable `FUZZ_CASES` overrides it.
const FUZZ_CASES: usize = 10_000;
const FUZZ_SEED: u64 = 0x5EED_E1B0_0000_0001;
/// Generated URDFs in `fuzzed_urdfs_never_panic` (`FUZZ_CASES / 5` when that is set).
const URDF_CASES: usize = 2_000;
/// Wall budget of each run of an accepted scene.
const RUN_WALL: Duration = Duration::from_millis(30);
/// Step budget of each run of an accepted scene (`integrator.max_steps` lowered to it).
const RUN_MAX_STEPS: u64 = 20_000;
/// What a run may take beyond its wall budget before it counts as a hang: the steps between
/// two looks at the clock, on a loaded core.
const RUN_SLACK: Duration = Duration::from_secs(5);

/// `FUZZ_CASES` from the environment, else `default`.
fn cases(default: usize, divisor: usize) -> usize {
    std::env::var("FUZZ_CASES").ok().and_then(|v| v.parse::<usize>().ok()).map_or(default, |n| (n / divisor).max(1))
}

/// `FUZZ_SEED` from the environment (mixed into the fixed seed), else the fixed seed.
fn seed(base: u64) -> u64 {
    std::env::var("FUZZ_SEED").ok().and_then(|v| v.parse::<u64>().ok()).map_or(base, |s| base ^ s.wrapping_mul(0x9E37_79B9_7F4A_7C15))
}

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
                        if r.chance(0.5) && c.is_object() {
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

/// The outcomes of running the accepted scenes, by kind.
#[derive(Debug, Default)]
struct RunCounts {
    complete: usize,
    out_of_time: usize,
    too_many_steps: usize,
    stiff: usize,
    step_size: usize,
    other_failure: usize,
    /// Shortened to 2 ms, the scene was refused (e.g. fewer than 2 samples).
    refused_short: usize,
    /// Longest wall time of one run.
    longest: Duration,
}

/// Runs one of `scene`'s runs (the `pick`-th) within [`RUN_WALL`] and [`RUN_MAX_STEPS`]: it must
/// not panic and must end within its budget; counts the outcome.
fn run_bounded(scene: &Scene, pick: usize, counts: &mut RunCounts, case: usize, json: &str) {
    // the step budget: the scene's max_steps lowered (the validation may then refuse it)
    let scene = match scene.vary(|s| match &mut s.integrator {
        IntegratorSpec::Dopri45(a) | IntegratorSpec::Imex(a) => a.max_steps = Some(a.max_steps.unwrap_or(u64::MAX).min(RUN_MAX_STEPS)),
        IntegratorSpec::Rosenbrock(r) | IntegratorSpec::Rodas5p(r) | IntegratorSpec::Rodas4(r) => r.max_steps = Some(r.max_steps.unwrap_or(u64::MAX).min(RUN_MAX_STEPS)),
        IntegratorSpec::Rk4(_) => {}
    }) {
        Ok(s) => s,
        Err(_) => {
            counts.too_many_steps += 1; // refused up front: needs more steps than the budget
            return;
        }
    };
    // half the runs shortened to 2 ms (most complete, or stop on a detector), half at their
    // full duration (most reach the wall budget)
    let scene = if pick >= 3 {
        match scene.vary(|s| s.duration = s.duration.min(0.002)) {
            Ok(s) => s,
            Err(_) => {
                counts.refused_short += 1;
                return;
            }
        }
    } else {
        scene
    };
    let run = scene.runs()[pick % scene.runs().len()].clone();
    let t0 = Instant::now();
    let res = catch_unwind(AssertUnwindSafe(|| sim::run::simulate_within(&scene, &run, Budget::wall_time(RUN_WALL), |_| Ok(()))));
    let wall = t0.elapsed();
    counts.longest = counts.longest.max(wall);
    assert!(wall <= RUN_WALL + RUN_SLACK, "case {case}: the run took {wall:?} with a budget of {RUN_WALL:?}\nscene: {json}");
    match res {
        Err(_) => panic!("case {case}: the run of an accepted scene panicked\nscene: {json}"),
        Ok(Ok(_)) => counts.complete += 1,
        Ok(Err(e)) => {
            assert!(e.time().is_some(), "case {case}: a failure without its time: {e}");
            match e {
                RunError::OutOfTime { .. } => counts.out_of_time += 1,
                RunError::TooManySteps { .. } => counts.too_many_steps += 1,
                RunError::Stiff { .. } => counts.stiff += 1,
                RunError::StepSizeTooSmall { .. } => counts.step_size += 1,
                _ => counts.other_failure += 1,
            }
        }
    }
}

/// [`FUZZ_CASES`] generated scenes (see the module docs): `Scene::from_json` never panics and
/// every error starts with the file name; every accepted scene runs to its end or to a typed
/// failure within its budgets.
#[test]
fn fuzzed_scenes_never_panic() {
    let n_cases = cases(FUZZ_CASES, 1);
    let base = paper_json();
    let mut r = Rng(seed(FUZZ_SEED));
    let (mut ok, mut err) = (0usize, 0usize);
    let mut kinds = [0usize; 4];
    let mut runs = RunCounts::default();
    let started = Instant::now();
    for case in 0..n_cases {
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
        let pick = r.below(6);
        let file = "fuzz.json";
        match catch_unwind(AssertUnwindSafe(|| build(&json, &urdf, file))) {
            Ok(Ok(scene)) => {
                ok += 1;
                run_bounded(&scene, pick, &mut runs, case, &json);
            }
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
    eprintln!(
        "fuzzed_scenes_never_panic: {n_cases} cases ({kinds:?} by kind), {ok} accepted, {err} rejected; \
         the {ok} accepted ran within {RUN_WALL:?} and {RUN_MAX_STEPS} steps each: {runs:?}; {:.1} s",
        started.elapsed().as_secs_f64()
    );
    assert_eq!(ok + err, n_cases);
    let ran = runs.complete + runs.out_of_time + runs.too_many_steps + runs.stiff + runs.step_size + runs.other_failure + runs.refused_short;
    assert_eq!(ran, ok);
    // the generator reaches both outcomes
    if n_cases >= FUZZ_CASES {
        assert!(ok > 100 && err > n_cases / 2, "{ok} accepted, {err} rejected");
    }
}

// ---------------------------------------------------------------------------------------------
// bad URDFs

/// A serial chain of `n` links `c0..` hanging from the paper's hand by fixed or revolute
/// joints named `cj0..`.
fn chain(r: &mut Rng, n: usize) -> String {
    let mut s = String::with_capacity(n * 200);
    // all fixed (the scene's per-joint settings still fit), or some revolute (they do not)
    let all_fixed = r.chance(0.5);
    for k in 0..n {
        let parent = if k == 0 { "hand".to_string() } else { format!("c{}", k - 1) };
        let kind = if all_fixed || r.chance(0.5) { "fixed" } else { "revolute" };
        s.push_str(&format!(
            r#"<link name="c{k}"><inertial><mass value="0.01"/><inertia ixx="1e-6" ixy="0" ixz="0" iyy="1e-6" iyz="0" izz="1e-6"/></inertial></link><joint name="cj{k}" type="{kind}"><parent link="{parent}"/><child link="c{k}"/><origin xyz="0 0 0.01"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>"#
        ));
    }
    s
}

fn before_end(urdf: &str, xml: &str) -> String {
    urdf.replace("</robot>", &format!("{xml}</robot>"))
}

const TAGS: &[&str] = &["a", "link", "joint", "visual", "geometry", "origin", "gazebo", "plugin", "x:y", "robot", "inertial"];

/// One generated bad (or borderline) URDF: its kind, its text, and what its error must say
/// when it must be refused.
fn bad_urdf(r: &mut Rng) -> (&'static str, String, Option<&'static str>) {
    match r.below(6) {
        0 => {
            // deep nesting, around the limit or far beyond it, at the top or inside a link
            let depth = *r.pick(&[50usize, 97, 98, 99, 100, 150, 1_000, 20_000, 200_000]);
            let tag = *r.pick(TAGS);
            let nest = format!("{}{}", format!("<{tag}>").repeat(depth), format!("</{tag}>").repeat(depth));
            let top = r.chance(0.5);
            let urdf = if top { before_end(PAPER_URDF, &nest) } else { PAPER_URDF.replacen("</link>", &format!("{nest}</link>"), 1) };
            // the nest sits at depth 2 (in <robot>) or 3 (in a <link>)
            let deepest = depth + if top { 1 } else { 2 };
            ("deep", urdf, (deepest > sim::limits::MAX_URDF_DEPTH).then_some("elements nested more than 100 deep"))
        }
        1 => {
            // long chains, around the joint limit or beyond it
            let n = *r.pick(&[10usize, 200, 989, 990, 1_001, 1_500, 5_000]);
            // the paper's URDF has 11 joints
            ("chain", before_end(PAPER_URDF, &chain(r, n)), (n + 11 > sim::limits::MAX_URDF_JOINTS).then_some("joints, more than the limit of 1000"))
        }
        2 => {
            // a joint or a link defined twice (the copy renamed where needed to stay a tree)
            let k = 1 + r.below(10);
            let urdf = if r.chance(0.5) {
                before_end(PAPER_URDF, &format!(r#"<link name="extra"/><joint name="joint{k}" type="fixed"><parent link="hand"/><child link="extra"/></joint>"#))
            } else {
                before_end(PAPER_URDF, &format!(r#"<link name="link{k}"/>"#))
            };
            ("duplicate", urdf, Some("defined twice"))
        }
        3 => {
            // random elements inserted, repeated
            let mut urdf = PAPER_URDF.to_string();
            for _ in 0..1 + r.below(4) {
                let tag = *r.pick(TAGS);
                let el = match r.below(3) {
                    0 => format!("<{tag}/>"),
                    1 => format!(r#"<{tag} name="{}">{}</{tag}>"#, r.pick(&["joint3", "link3", "hand", "", "z"]), "<b/>".repeat(r.below(1000))),
                    _ => format!("<{tag}>").repeat(1 + r.below(300)),
                };
                let at: Vec<usize> = urdf.match_indices('<').map(|(i, _)| i).collect();
                let i = *r.pick(&at);
                urdf.insert_str(i, &el);
            }
            ("elements", urdf, None)
        }
        _ => ("bytes", mutate_urdf(r, PAPER_URDF), None),
    }
}

/// [`URDF_CASES`] generated bad URDFs with the paper scene: never a panic or a stack overflow
/// (which would abort the test process), every error starts with the file name; deep nesting
/// and long chains beyond the limits are refused for that reason, duplicates too, and those
/// within the limits are not refused for it.
#[test]
fn fuzzed_urdfs_never_panic() {
    let n_cases = cases(URDF_CASES, 5);
    let mut r = Rng(seed(FUZZ_SEED ^ 0x0DF0));
    let mut counts: std::collections::BTreeMap<&str, (usize, usize, Duration)> = Default::default();
    let started = Instant::now();
    for case in 0..n_cases {
        let t0 = Instant::now();
        let (kind, urdf, must_refuse) = bad_urdf(&mut r);
        let file = "fuzz.json";
        let res = catch_unwind(AssertUnwindSafe(|| build(PAPER_SCENE_JSON, &urdf, file)));
        let c = counts.entry(kind).or_default();
        c.2 += t0.elapsed();
        match res {
            Ok(Ok(scene)) => {
                c.0 += 1;
                assert!(scene.model().urdf_joints.len() <= sim::limits::MAX_URDF_JOINTS, "case {case}");
                assert!(must_refuse.is_none(), "case {case} ({kind}): accepted, but must be refused with {must_refuse:?}");
            }
            Ok(Err(msg)) => {
                c.1 += 1;
                assert!(msg.starts_with(&format!("{file}: field `")), "case {case}: {msg}");
                if let Some(want) = must_refuse {
                    assert!(msg.starts_with(&format!("{file}: field `urdf` = paper_arm.urdf: paper_arm.urdf:")), "case {case}: {msg}");
                    assert!(msg.contains(want), "case {case} ({kind}): {want:?} not in {msg}");
                } else if kind == "deep" || kind == "chain" {
                    assert!(!msg.contains("nested more than") && !msg.contains("more than the limit"), "case {case} ({kind}): within the limits, yet {msg}");
                }
            }
            Err(_) => panic!("case {case} ({kind}): Scene::from_json panicked\nurdf: {}", &urdf[..urdf.len().min(2000)]),
        }
    }
    let summary: Vec<String> = counts.iter().map(|(k, (a, e, t))| format!("{k}: {a} accepted, {e} rejected, {:.1} s", t.as_secs_f64())).collect();
    eprintln!("fuzzed_urdfs_never_panic: {n_cases} cases ({}); {:.1} s", summary.join("; "), started.elapsed().as_secs_f64());
    let total: usize = counts.values().map(|(a, e, _)| a + e).sum();
    assert_eq!(total, n_cases);
}

/// Inputs that are not files, or too large, as the scene and as its URDF: refused before they
/// are read, naming the file (and the limit); never a hang on a FIFO or /dev/zero.
#[test]
fn input_files_are_bounded() {
    use std::path::Path;
    let dir = tempfile::tempdir().unwrap();
    let limit = sim::limits::MAX_INPUT_BYTES;
    let sparse = |name: &str, len: u64| {
        let p = dir.path().join(name);
        std::fs::File::create(&p).unwrap().set_len(len).unwrap();
        p
    };
    let mut inputs: Vec<(std::path::PathBuf, &str)> = vec![
        (dir.path().to_path_buf(), "not a regular file (it is a directory)"),
        (sparse("tb.json", 1 << 40), "more than the limit of 4194304 bytes"),
        (sparse("over.json", limit + 1), "more than the limit of 4194304 bytes"),
    ];
    if cfg!(unix) {
        inputs.push((Path::new("/dev/zero").to_path_buf(), "character device"));
        inputs.push((Path::new("/dev/urandom").to_path_buf(), "character device"));
        let fifo = dir.path().join("fifo");
        if std::process::Command::new("mkfifo").arg(&fifo).status().is_ok_and(|s| s.success()) {
            inputs.push((fifo, "(it is a FIFO)"));
        }
    }
    let mut checked = 0;
    for (path, want) in &inputs {
        // as the scene
        let t0 = Instant::now();
        let m = Scene::load(path).unwrap_err().to_string();
        assert!(m.starts_with(&format!("{}: field `(file)`: ", path.display())) && m.contains(want), "{m}");
        // as its URDF
        let scene = dir.path().join("scene.json");
        let mut v = paper_json();
        v["urdf"] = json!(path.to_str().unwrap());
        std::fs::write(&scene, v.to_string()).unwrap();
        let m = Scene::load(&scene).unwrap_err().to_string();
        assert!(m.starts_with(&format!("{}: field `urdf` = {}: cannot read ", scene.display(), path.display())) && m.contains(want), "{m}");
        assert!(t0.elapsed() < Duration::from_secs(5), "{}: {:?}", path.display(), t0.elapsed());
        checked += 2;
    }
    eprintln!("input_files_are_bounded: {checked} bad files refused (as scene and as URDF)");
}
