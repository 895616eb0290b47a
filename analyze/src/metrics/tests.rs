//! Metrics of synthetic recordings with known answers (written by `schemas::synth`).

use std::f64::consts::PI;

use super::signal::negative_time;
use super::*;
use schemas::synth::{contact_forces, currents, hand_error, linear_energy, Synth};
use schemas::{EnergyState, RunResult, RunStatus};

mod contacts;

fn read(s: &Synth) -> (tempfile::TempDir, RunMetrics) {
    let dir = tempfile::tempdir().unwrap();
    let m = read_run_metrics(&s.write_in(dir.path())).unwrap();
    (dir, m)
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

/// x = A sin(2πt/T), y = B cos(2πt/T), z = c over 5 whole periods (20 samples each) plus the
/// end point t = 1 s. Over the 100 samples of whole periods Σ sin² = Σ cos² = 50 exactly, so
/// with the end point RMS_x = A sqrt(50/101), RMS_y = B sqrt(51/101) (to 1e-12 relative); both
/// are within 1/N (N = 101) of the continuous A/√2, B/√2. Peaks fall on the grid: max = A, B.
#[test]
fn hand_error_rms_and_max_of_whole_period_sines() {
    let (a, b, c, period) = (0.02, 0.01, -0.003, 0.2);
    let mut s = Synth::new("sines", &[], 2);
    s.hand = Some(hand_error(move |t| {
        let w = 2.0 * PI * t / period;
        [a * w.sin(), b * w.cos(), c]
    }));
    let (_d, m) = read(&s);
    let e = m.hand_error.as_ref().unwrap();
    assert_eq!(m.samples, 101);
    assert!(close(m.t_end_s.unwrap(), 1.0, 1e-12));
    assert!(
        close(e.x.rms_m, a * (50.0f64 / 101.0).sqrt(), 1e-12 * a),
        "{e:?}"
    );
    assert!(
        close(e.y.rms_m, b * (51.0f64 / 101.0).sqrt(), 1e-12 * b),
        "{e:?}"
    );
    assert!(close(e.x.rms_m, a / 2f64.sqrt(), a / 2f64.sqrt() / 101.0));
    assert!(close(e.y.rms_m, b / 2f64.sqrt(), b / 2f64.sqrt() / 101.0));
    assert!(close(e.x.max_abs_m, a, 1e-12) && close(e.y.max_abs_m, b, 1e-12));
    assert!(close(
        (2.0 * PI * e.x.t_max_s / period).sin().abs(),
        1.0,
        1e-9
    ));
    assert!(close(e.y.t_max_s, 0.0, 1e-12));
    assert!(close(e.z.rms_m, 0.003, 1e-15) && close(e.z.max_abs_m, 0.003, 1e-15));
    // the norm: mean of |e|² is the sum of the axes' means of squares
    let sum_sq = e.x.rms_m.powi(2) + e.y.rms_m.powi(2) + e.z.rms_m.powi(2);
    assert!(close(e.norm.rms_m, sum_sq.sqrt(), 1e-12 * e.norm.rms_m));
    assert!(close(
        e.norm.max_abs_m,
        (a * a + c * c).sqrt().max((b * b + c * c).sqrt()),
        1e-9
    ));
}

/// Trapezoid rule on 1[f < 0]: a lone negative sample counts dt, a negative run from t_a to
/// t_b counts t_b - t_a + dt, uneven intervals count by their length. Exact to 1e-12.
#[test]
fn pull_time_counts_sample_intervals() {
    let t = [0.0, 1.0, 2.0, 3.0, 4.0];
    assert_eq!(negative_time(&t, &[1.0, -1.0, 1.0, 1.0, 1.0]), 1.0);
    assert_eq!(negative_time(&t, &[1.0, -1.0, -2.0, -1.0, 1.0]), 3.0);
    assert_eq!(negative_time(&t, &[-1.0; 5]), 4.0);
    assert_eq!(negative_time(&t, &[0.0, 1.0, 0.0, 2.0, 0.0]), 0.0); // zero is not pulling
    assert_eq!(
        negative_time(&[0.0, 0.5, 2.0], &[-1.0, 1.0, -1.0]),
        0.25 + 0.75
    );
    assert_eq!(negative_time(&[0.0], &[-1.0]), 0.0);
}

/// elbow4 pulls on the samples t = 0.20..=0.50 s (f_n = -1 - 10 (t - 0.2), minimum -4 N at
/// 0.5 s), elbow7 always pushes with 3 N. Pull time 0.30 + dt = 0.31 s (to 1e-9).
#[test]
fn normal_force_negative_on_a_known_interval() {
    let mut s = Synth::new("pull", &["elbow4", "elbow7"], 3);
    s.constraints = Some(contact_forces(|t| {
        let k = (t / 0.01).round() as i64;
        let f4 = if (20..=50).contains(&k) {
            -1.0 - 10.0 * (t - 0.2)
        } else {
            2.0
        };
        let c = if k == 60 { -2e-6 } else { 1e-6 * t };
        let cd = if k == 30 { 5e-5 } else { 0.0 };
        vec![[f4, c, cd], [3.0, 0.0, -1e-7]]
    }));
    let (_d, m) = read(&s);
    let [e4, e7] = &m.contact_forces[..] else {
        panic!("{:?}", m.contact_forces)
    };
    assert_eq!(
        (e4.contact.as_str(), e7.contact.as_str()),
        ("elbow4", "elbow7")
    );
    assert!(close(e4.pull_time_s, 0.31, 1e-9), "{e4:?}");
    assert!(close(e4.first_pull_s.unwrap(), 0.2, 1e-9));
    assert!(close(e4.min_normal_force_n, -4.0, 1e-9) && close(e4.t_min_normal_force_s, 0.5, 1e-9));
    assert!(
        close(e4.max_abs_position_m, 2e-6, 1e-18) && close(e4.max_abs_velocity_m_s, 5e-5, 1e-18)
    );
    assert_eq!((e7.pull_time_s, e7.first_pull_s), (0.0, None));
    assert!(close(e7.min_normal_force_n, 3.0, 0.0) && close(e7.max_abs_velocity_m_s, 1e-7, 1e-20));
}

/// joint1 = sin(2πt) (peak 1 A at 0.25 s), joint2 = -3 A at t = 0.7 s else 0.5 A, joint3 =
/// 2 cos(2πt) (peak 2 A at 0 s): the overall peak is joint2's 3 A at 0.7 s (exact to 1e-12).
#[test]
fn current_peaks_per_motor_and_overall() {
    let mut s = Synth::new("currents", &[], 3);
    s.motors = Some(currents(|t| {
        let k = (t / 0.01).round() as i64;
        let w = 2.0 * PI * t;
        vec![w.sin(), if k == 70 { -3.0 } else { 0.5 }, 2.0 * w.cos()]
    }));
    let (_d, m) = read(&s);
    let p: Vec<(f64, f64)> = m
        .links
        .iter()
        .map(|l| (l.peak_current_a, l.t_peak_current_s))
        .collect();
    assert!(
        close(p[0].0, 1.0, 1e-12) && close(p[0].1, 0.25, 1e-12),
        "{p:?}"
    );
    assert!(
        close(p[1].0, 3.0, 0.0) && close(p[1].1, 0.7, 1e-12),
        "{p:?}"
    );
    assert!(
        close(p[2].0, 2.0, 1e-12) && close(p[2].1, 0.0, 0.0),
        "{p:?}"
    );
    let peak = m.peak_current.unwrap();
    assert_eq!(peak.joint, "joint2");
    assert!(close(peak.current_a, 3.0, 0.0) && close(peak.t_s, 0.7, 1e-12));
}

/// Energies known at t = 1 s: W = [1, 2, 3] J, E = [2, 4, 6] J; T = 5 + t², V = -2 + 3t,
/// L i²/2 = 0.5 t, losses 4t and 2t, residual 1e-3 sin(2πt) (max 1e-3 J at 0.25 s). Tolerance
/// 1e-12 J (sums of a few doubles).
#[test]
fn energy_audit_at_the_end() {
    let mut s = Synth::new("energy", &[], 3);
    s.energy = Some(Box::new(|t| EnergyState {
        kinetic: 5.0 + t * t,
        potential: -2.0 + 3.0 * t,
        magnetic: 0.5 * t,
        resistive_loss: 4.0 * t,
        friction_loss: 2.0 * t,
        balance_residual: 1e-3 * (2.0 * PI * t).sin(),
        ..linear_energy(t, 3, 1.0, 2.0)
    }));
    let (_d, m) = read(&s);
    let w: Vec<f64> = m.links.iter().map(|l| l.work_j).collect();
    let e: Vec<f64> = m.links.iter().map(|l| l.electric_energy_j).collect();
    let tol = 1e-12;
    assert!(
        w.iter()
            .zip([1.0, 2.0, 3.0])
            .all(|(a, b)| close(*a, b, tol)),
        "{w:?}"
    );
    assert!(
        e.iter()
            .zip([2.0, 4.0, 6.0])
            .all(|(a, b)| close(*a, b, tol)),
        "{e:?}"
    );
    assert!(close(m.link_work_total_j.unwrap(), 6.0, tol) && close(m.electric_energy_total_j.unwrap(), 12.0, tol));
    let a = m.energy.as_ref().unwrap();
    assert!(
        close(a.electric_j, 12.0, tol) && close(a.kinetic_change_j, 1.0, tol),
        "{a:?}"
    );
    assert!(close(a.potential_change_j, 3.0, tol) && close(a.magnetic_change_j, 0.5, tol));
    assert!(close(a.resistive_loss_j, 4.0, tol) && close(a.friction_loss_j, 2.0, tol));
    assert!(close(a.residual_j, 0.0, 1e-15) && close(a.max_abs_residual_j, 1e-3, 1e-15));
    assert!(close(a.t_max_abs_residual_s, 0.25, 1e-12));
    assert!(close(a.max_abs_residual_rel.unwrap(), 1e-3 / 12.0, 1e-15));
}

#[test]
fn metadata_is_read_and_a_failed_run_says_when_and_why() {
    let mut s = Synth::new("broken", &["elbow4"], 2);
    s.result = Some(schemas::RunResult::failed("step size too small".into(), Some(0.42)));
    let (_d, m) = read(&s);
    assert_eq!((m.scene.as_str(), m.run.as_str()), ("synthetic", "broken"));
    assert_eq!(m.contacts, ["elbow4"]);
    assert_eq!(m.joint_names, ["joint1", "joint2"]);
    assert_eq!(m.status, Status::Failed);
    assert_eq!(m.error.as_deref(), Some("step size too small"));
    assert_eq!(m.error_time_s, Some(0.42));
}

/// Each broken input gives an error whose message names the file and what is wrong (a
/// malformed metadata record is the reader's error: `schemas` tests those).
#[test]
fn incomplete_recordings_give_errors_naming_file_and_cause() {
    type Breaker = fn(&mut Synth);
    let cases: [(Breaker, &str); 5] = [
        (|s| s.names = None, "run"),
        (|s| s.result = None, "result"),
        (|s| s.motors = Some(currents(|_| vec![0.0; 2])), "/motors"),
        (|s| s.energy = None, "/energy"),
        (|s| s.hand = None, "/hand"),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (k, (brk, what)) in cases.into_iter().enumerate() {
        let mut s = Synth::new(&format!("case{k}"), &["elbow4"], 3);
        brk(&mut s);
        let path = s.write(&dir.path().join(format!("case{k}.mcap")));
        let msg = read_run_metrics(&path).unwrap_err().to_string();
        assert!(msg.contains(&path.display().to_string()) && msg.contains(what), "case {k}: {msg}");
    }
}

/// Empty, not MCAP, and truncated files are errors naming the file, never panics.
#[test]
fn bad_files_give_errors_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let good = Synth::new("good", &[], 2).write_in(dir.path());
    let bytes = std::fs::read(&good).unwrap();
    let cases: [(&str, &[u8]); 3] = [
        ("empty.mcap", b""),
        ("text.mcap", b"time,x\n0,1\n"),
        ("truncated.mcap", &bytes[..bytes.len() / 2]),
    ];
    for (name, content) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, content).unwrap();
        let msg = read_run_metrics(&path).unwrap_err().to_string();
        assert!(msg.contains(&path.display().to_string()), "{name}: {msg}");
    }
    let missing = dir.path().join("missing.mcap");
    assert!(read_run_metrics(&missing)
        .unwrap_err()
        .to_string()
        .contains("missing.mcap"));
}

#[test]
fn json_round_trips() {
    let (_d, m) = read(&Synth::new("json", &["elbow4"], 2));
    let text = serde_json::to_string(&m).unwrap();
    assert_eq!(serde_json::from_str::<RunMetrics>(&text).unwrap(), m);
    assert!(text.contains(r#""status":"complete""#), "{text}");
}

fn read_err(s: &Synth) -> String {
    let dir = tempfile::tempdir().unwrap();
    read_run_metrics(&s.write_in(dir.path())).unwrap_err().to_string()
}

/// A NaN or an infinity in any field of a metric topic is an error naming the topic, the
/// field, the message and the time, never a `null` peak.
#[test]
fn non_finite_values_are_errors_naming_topic_field_and_time() {
    let mut s = Synth::new("nan", &["elbow"], 2);
    s.motors = Some(currents(|t| vec![1.0, if (t - 0.5).abs() < 1e-9 { f64::NAN } else { t }]));
    let e = read_err(&s);
    assert!(e.contains("topic /motors, field current[1], message #50 (t = 0.5 s): NaN is not a finite number"), "{e}");
    let mut s = Synth::new("inf", &["elbow"], 2);
    s.constraints = Some(contact_forces(|t| vec![[if t > 0.25 { f64::INFINITY } else { 1.0 }, 0.0, 0.0]]));
    let e = read_err(&s);
    assert!(e.contains("topic /constraints, field normal_force[0], message #26") && e.contains("inf is not a finite number"), "{e}");
}

/// With the `run` record's output grid (`sim` writes it), every sample must lie on it: a clock
/// scaled by 1000 (another producer's ms for s) or a missing sample is an error naming the
/// first sample off the grid; a complete run must reach its duration. Without a setup (other
/// producers) only the order of time is checked.
#[test]
fn samples_off_the_recorded_grid_are_errors() {
    let (_d, m) = read(&Synth::new("on-grid", &["elbow"], 2).with_setup());
    assert_eq!(m.samples, 101);
    let mut s = Synth::new("scaled", &["elbow"], 2).with_setup();
    s.time_scale = 1000.0;
    let e = read_err(&s);
    assert!(e.contains("message #1: t = 10 s, but the run's output grid (100 Hz) puts sample #1 at 0.01 s"), "{e}");
    let mut s = Synth::new("gap", &["elbow"], 2).with_setup();
    s.drop_sample = Some(40);
    let e = read_err(&s);
    assert!(e.contains("message #40: t = 0.41 s") && e.contains("samples missing"), "{e}");
    let mut s = Synth::new("short", &["elbow"], 2).with_setup();
    s.n = 50;
    s.setup.as_mut().unwrap().duration_s = 1.0;
    let e = read_err(&s);
    assert!(e.contains("recorded as complete, but its 51 samples end at t = 0.5 s, before the duration 1 s"), "{e}");
    // a failed run may stop early
    s.result = Some(RunResult { status: RunStatus::Failed, error: Some("step size underflow".into()), error_time_s: Some(0.5), ..RunResult::complete(0, 0, 0) });
    let (_d, m) = read(&s);
    assert_eq!((m.status, m.samples), (Status::Failed, 51));
    let mut s = Synth::new("foreign", &["elbow"], 2);
    s.time_scale = 1000.0;
    let (_d, m) = read(&s);
    assert_eq!(m.t_end_s, Some(1000.0));
}

/// Two joints (or contacts) with one name would make a joint disappear from every table.
#[test]
fn duplicate_joint_or_contact_names_are_refused() {
    let mut s = Synth::new("dup", &["elbow", "elbow"], 2);
    let e = read_err(&s);
    assert!(e.contains("metadata run.contact names = \"elbow\": named twice"), "{e}");
    s.names.as_mut().unwrap().contacts = vec!["a".into(), "b".into()];
    s.names.as_mut().unwrap().joint_names = Some(vec!["j".into(), "j".into()]);
    let e = read_err(&s);
    assert!(e.contains("run.joint names = \"j\": named twice"), "{e}");
}

/// The reductions fed generic trees (the reader's path before typed decoding).
struct Generic(Reductions);

impl schemas::Visitor for Generic {
    fn message(&mut self, m: schemas::DecodedMessage<'_>) -> Result<(), schemas::Error> {
        schemas::Visitor::message(&mut self.0, m)
    }

    fn metadata(&mut self, name: &str, entries: &std::collections::BTreeMap<String, String>) {
        schemas::Visitor::metadata(&mut self.0, name, entries)
    }
}

pub(super) fn generic_metrics(path: &Path) -> Result<RunMetrics, Error> {
    let mut acc = Generic(Reductions::default());
    let rec = schemas::stream_recording(path, Some(&METRIC_TOPICS), &mut acc).map_err(|e| acc.0.take_error(e))?;
    acc.0.finish(&rec, None)
}

/// Typed decoding (what `read_run_metrics` uses for `schemas`' own messages) gives the metrics
/// of the generic trees, number for number, and the same errors.
#[test]
fn typed_and_generic_decoding_give_the_same_metrics_and_errors() {
    let dir = tempfile::tempdir().unwrap();
    let mut runs = vec![Synth::new("plain", &["elbow"], 2).with_setup(), Synth::new("two", &["left", "right"], 3)];
    runs[1].motors = Some(currents(|t| vec![t.sin(), -2.0 * t, (3.0 * t).cos()]));
    runs[1].constraints = Some(contact_forces(|t| vec![[t - 0.5, 1e-9 * t, -1e-6], [0.25 - t, 0.0, 1e-3 * t]]));
    let mut nan = Synth::new("nan", &["elbow"], 2);
    nan.motors = Some(currents(|t| vec![1.0, if (t - 0.5).abs() < 1e-9 { f64::NAN } else { t }]));
    runs.push(nan);
    for s in &runs {
        let path = s.write_in(dir.path());
        match (read_run_metrics(&path), generic_metrics(&path)) {
            (Ok(typed), Ok(generic)) => assert_eq!(serde_json::to_string(&typed).unwrap(), serde_json::to_string(&generic).unwrap()),
            (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string()),
            (a, b) => panic!("{}: typed {a:?}, generic {b:?}", path.display()),
        }
    }
}
