//! Fuzzing the scene reader: [`FUZZ_CASES`] = 10,000 generated scenes (random JSON-node
//! replacements, key deletions, duplicated contacts, textual edits of the JSON, random byte and
//! attribute edits of the URDF), fixed seed, each built under `catch_unwind`: the result is `Ok`
//! or an error whose text starts with the file name. About 10 s in the test profile on 2 cores.
//! (The table of hand-written bad inputs is in `bad_input.rs`.)

use std::panic::{catch_unwind, AssertUnwindSafe};

use serde_json::{json, Value};
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
