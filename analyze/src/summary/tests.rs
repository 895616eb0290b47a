//! The fast path of `analyze summary` (metric topics only, chunks of other topics skipped by
//! the summary's chunk index, typed messages decoded by reference into kept storage) against a
//! straightforward decode of the same file: every topic, every chunk decompressed, generic
//! trees ([`schemas::read_recording`] then [`super::row`]). The rows must be equal to the bit
//! (compared through `{:?}`, which prints each f64 in its shortest round-trip form).

use std::path::Path;

use schemas::synth::{contact_forces, currents, hand_error, Synth};
use schemas::{Compression, RecordingWriter, WriterOptions};

use super::{read_row, row, SummaryRow};

/// The synthetic unilateral run (`/contacts`, `/contact_events` beside the four metric
/// topics) with signals that change every sample, joint states and hand points (topics the
/// summary skips), 1 s at 1 kHz.
fn several_channels() -> Synth {
    let (mut s, _) = schemas::synth::unilateral();
    s.dt = 1e-3;
    s.n = 1000;
    s = s.with_setup();
    s.hand = Some(hand_error(|t| [1e-3 * (7.0 * t).sin(), -2e-3 * t * t, 5e-4 * (3.0 * t).cos()]));
    s.motors = Some(currents(|t| vec![(13.0 * t).sin(), -2.0 * (5.0 * t).cos(), 3.0 * t - 1.0]));
    s.constraints = Some(contact_forces(|t| vec![[10.0 - 30.0 * (t - 0.5).abs(), 1e-6 * t, -1e-5 * t], [20.0 * (4.0 * t).cos(), 0.0, 2e-6]]));
    s.joint_states = Some(Box::new(|t| schemas::JointState { name: vec!["joint1".into(), "joint2".into(), "joint3".into()], position: vec![t, 2.0 * t, -t], velocity: vec![1.0, 2.0, -1.0], effort: vec![0.5; 3], ..Default::default() }));
    s.hand_points = true;
    s
}

/// The fast row and the reference row of the recording at `path`, and how many chunks the
/// fast path skipped.
fn both(path: &Path) -> (String, String, usize) {
    let params = vec!["controller.kp".to_string(), "run".to_string()];
    let bytes = std::fs::metadata(path).unwrap().len();
    let fast = read_row(path, &params).unwrap();
    let (_, streamed) = crate::metrics::stream_run_metrics(path).unwrap();
    let all = schemas::read_recording(path).unwrap();
    assert_eq!(all.chunks_skipped(), 0);
    let reference = row(&all, bytes, &params).unwrap();
    let show = |r: &SummaryRow| format!("{:?} {:?} {} {:?}", r.metrics, r.integrator, r.bytes, r.params);
    (show(&fast), show(&reference), streamed.chunks_skipped())
}

/// One chunk per topic (the writer's default) and topics mixed in chunks, zstd and
/// uncompressed, in chunks of 4 KiB (many per topic): the same row as the straightforward
/// decode, and the per-topic files have chunks skipped. A metric chunk skipped wrongly loses
/// samples (and changes every sum); a bulk chunk read wrongly changes nothing here, but the
/// count of skipped chunks says none was.
#[test]
fn the_fast_path_gives_the_rows_of_a_straightforward_decode() {
    let dir = tempfile::tempdir().unwrap();
    let s = several_channels();
    let layouts = [
        ("per-topic-zstd", WriterOptions { chunk_size: 4 << 10, ..WriterOptions::default() }),
        ("per-topic-none", WriterOptions { chunk_size: 4 << 10, compression: Compression::None, ..WriterOptions::default() }),
        ("mixed-zstd", WriterOptions { chunk_size: 4 << 10, chunk_per_topic: false, ..WriterOptions::default() }),
    ];
    for (name, options) in layouts {
        let path = dir.path().join(format!("{name}.mcap"));
        s.write_with(RecordingWriter::create_with(&path, options).unwrap());
        let (fast, reference, skipped) = both(&path);
        assert_eq!(fast, reference, "{name}: the fast path and the straightforward decode differ");
        assert!(fast.contains("samples: 1001"), "{name}: {fast}");
        assert!(fast.contains("contact_states: [ContactStateMetrics"), "{name}: the /contacts topic was read");
        if name.starts_with("per-topic") {
            // the joint states and hand points: many chunks of their own
            assert!(skipped >= 10, "{name}: {skipped} chunks skipped");
        }
    }
}
