//! The cost of recording one paper run (two elbows, 5 s at 1 kHz: 5 001 samples on 8 topics)
//! with each writer setting, with no simulation: the samples are computed once, kept in
//! memory, and written again and again (the floor of `sim`'s per-run recording cost).
//!
//! `cargo bench -p sim --bench record [-- ROUNDS]` prints one row per setting: the wall time of
//! a whole recording (create … finish, fsync and rename included) and the time the caller's
//! thread spends in `record` (what the integration waits for), their medians over the rounds
//! (settings interleaved within each round, so every setting sees the same machine load), the
//! file size, the throughput in MB/s of message bytes (the uncompressed file's size), and the
//! ratios to today's writer (`inline mixed zstd-3`: zstd level 3, 1 MiB interleaved chunks, on
//! the caller's thread), computed in the same run. Absolute times depend on the load (`uptime`).

// the sink closure must return `sim::error::RunError`, whose size is the library's choice
#![allow(clippy::result_large_err)]

use std::path::Path;
use std::time::Instant;

use schemas::{Compression, Tap, WriterOptions};
use sim::ode::Outputs;
use sim::record::Recorder;
use sim::scene::Scene;

/// (label, options, tap the metric topics)
fn settings() -> Vec<(&'static str, WriterOptions, bool)> {
    let today = WriterOptions::INLINE_MIXED_ZSTD3;
    let bg = WriterOptions::default();
    let inline_mixed = |compression| WriterOptions { compression, ..today };
    let bg_topic = |compression| WriterOptions { compression, ..bg };
    vec![
        ("inline mixed zstd-3 (today)", today, false),
        ("inline mixed zstd-1", inline_mixed(Compression::Zstd { level: 1 }), false),
        ("inline mixed lz4", inline_mixed(Compression::Lz4), false),
        ("inline mixed none", inline_mixed(Compression::None), false),
        ("inline per-topic zstd-1", WriterOptions { background: false, ..bg_topic(Compression::Zstd { level: 1 }) }, false),
        ("thread mixed zstd-1", WriterOptions { chunk_per_topic: false, ..bg_topic(Compression::Zstd { level: 1 }) }, false),
        ("thread per-topic zstd-1", bg_topic(Compression::Zstd { level: 1 }), false),
        ("thread per-topic zstd-3", bg_topic(Compression::Zstd { level: 3 }), false),
        ("thread per-topic zstd-6", bg_topic(Compression::Zstd { level: 6 }), false),
        ("thread per-topic lz4", bg_topic(Compression::Lz4), false),
        ("thread per-topic none", bg_topic(Compression::None), false),
        ("thread per-topic zstd-1 256 KiB", WriterOptions { chunk_size: 256 << 10, ..bg_topic(Compression::Zstd { level: 1 }) }, false),
        ("thread per-topic zstd-1 4 MiB", WriterOptions { chunk_size: 4 << 20, ..bg_topic(Compression::Zstd { level: 1 }) }, false),
        ("default + tap of 4 metric topics", bg, true),
    ]
}

/// The rows after the settings: today's writer, then the file read back for the metric topics
/// (what `sim` did to print its table), with the same no-op visitor as the tap.
const READ_BACK: &str = "today + read back 4 metric topics";

fn read_back(path: &Path) -> f64 {
    let t0 = Instant::now();
    let topics = [schemas::topics::HAND, schemas::topics::MOTORS, schemas::topics::CONSTRAINTS, schemas::topics::ENERGY];
    schemas::stream_recording(path, Some(&topics), &mut |_: schemas::DecodedMessage<'_>| Ok(())).expect("reads back");
    t0.elapsed().as_secs_f64()
}

/// Writes `samples` to `path` with `options`: (wall s, caller's time in `record` s, bytes).
fn write(scene: &Scene, run: &sim::scene::Run, samples: &[Outputs], path: &Path, options: WriterOptions, tap: bool) -> (f64, f64, u64) {
    let _ = std::fs::remove_file(path);
    let t0 = Instant::now();
    let tap = tap.then(|| {
        let topics = [schemas::topics::HAND, schemas::topics::MOTORS, schemas::topics::CONSTRAINTS, schemas::topics::ENERGY];
        Tap::new(path.display().to_string(), Some(&topics), Box::new(|_: schemas::DecodedMessage<'_>| Ok(())))
    });
    let mut rec = Recorder::create_with(path, scene, run, options, tap).expect("create");
    let mut caller = 0.0;
    for o in samples {
        let t = Instant::now();
        rec.record(o).expect("record");
        caller += t.elapsed().as_secs_f64();
    }
    let stats = sim::integrate::Stats::default();
    let (path, tapped) = rec.finish(Ok(&stats)).expect("finish");
    if let Some(t) = tapped {
        t.recording.expect("the tap read every message");
    }
    let wall = t0.elapsed().as_secs_f64();
    (wall, caller, std::fs::metadata(path).expect("written").len())
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let rounds: usize = std::env::args().skip(1).find_map(|a| a.parse().ok()).unwrap_or(7);
    let scene = Scene::paper().expect("the built-in scene is valid");
    let run = scene.runs().iter().find(|r| r.contacts.len() == 2).expect("a two-elbow run").clone();
    let mut samples = Vec::new();
    sim::run::simulate(&scene, &run, |o| {
        samples.push(o.clone());
        Ok(())
    })
    .expect("the run completes");
    let dir = tempfile::tempdir().expect("a temporary directory");
    let settings = settings();
    let n = settings.len() + 1;
    let mut wall = vec![Vec::new(); n];
    let mut caller = vec![Vec::new(); n];
    let mut size = vec![0u64; n];
    for _ in 0..rounds {
        for (k, (_, options, tap)) in settings.iter().enumerate() {
            let path = dir.path().join(format!("{k}.mcap"));
            let (w, c, b) = write(&scene, &run, &samples, &path, *options, *tap);
            if k == 0 {
                // today: the write, then the read back
                let r = read_back(&path);
                wall[n - 1].push(w + r);
                caller[n - 1].push(c + r);
                size[n - 1] = b;
            }
            wall[k].push(w);
            caller[k].push(c);
            size[k] = b;
        }
    }
    // message bytes: the uncompressed file (interleaved chunks, no compression)
    let raw = settings.iter().position(|s| s.0 == "inline mixed none").map_or(1, |k| size[k]) as f64;
    let w: Vec<f64> = wall.iter_mut().map(|v| median(v)).collect();
    let c: Vec<f64> = caller.iter_mut().map(|v| median(v)).collect();
    println!("{} samples of the paper's two-elbow run ({:.1} MB of messages), {rounds} rounds, medians", samples.len(), raw / 1e6);
    println!("{:<34} {:>9} {:>10} {:>8} {:>10} {:>9} {:>10} {:>9}", "setting", "wall ms", "caller ms", "MB/s", "size MB", "wall x", "caller x", "size x");
    let names: Vec<&str> = settings.iter().map(|s| s.0).chain([READ_BACK]).collect();
    for (k, name) in names.iter().enumerate() {
        println!(
            "{name:<34} {:>9.1} {:>10.1} {:>8.0} {:>10.3} {:>9.3} {:>10.3} {:>9.3}",
            w[k] * 1e3,
            c[k] * 1e3,
            raw / w[k] / 1e6,
            size[k] as f64 / 1e6,
            w[k] / w[0],
            c[k] / c[0],
            size[k] as f64 / size[0] as f64
        );
    }
    println!("(x: ratio to the first row, same run; wall: create to finish incl. fsync and rename; caller: time inside record())");
}
