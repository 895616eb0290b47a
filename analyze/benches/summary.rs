//! Throughput of `analyze summary`: recordings per second and MB/s read (MB of file), over a
//! folder of recordings, against the baseline of decoding every topic on one thread into
//! generic trees (what `analyze metrics` did before the summary existed). Prints a table;
//! speeds are stated as ratios to that baseline, measured in the same run, and per core.
//!
//! ```text
//! target/release/sim sweep sim/scenes/sweeps/summary-bench.json -o /tmp/corpus   # 200 recordings
//! cargo bench -p analyze --bench summary -- /tmp/corpus [REPEATS]
//! cargo bench -p analyze --no-default-features --bench summary -- /tmp/corpus   # without polars
//! cargo bench -p analyze --bench summary -- /tmp/corpus 3 typed   # rows with "typed" (ratios to the first)
//! ```
//!
//! The rows: the generic reader (every topic, then the metric topics only), the typed decoding
//! of the metric messages (`schemas::Visitor::typed`), and the same files rewritten with their
//! topics grouped per chunk (`schemas::regroup_chunks`: the transforms, hand points, joint
//! states and URDF in chunks of their own, 1 MiB, as a writer that groups topics writes them;
//! written once into `DIR-grouped`), where the reader decompresses only the chunks of the
//! metric topics. Each method reads the whole folder `REPEATS` times (default 3) and the best
//! time is kept (the folder is read once before, so every method sees the files in the page
//! cache). "MB/s/core" divides by the threads used; "MB/CPU-s" divides by the CPU time the
//! process used (user + system), which the other work on a shared machine does not inflate.

use std::path::{Path, PathBuf};
use std::time::Instant;

use analyze::metrics::{Reductions, METRIC_TOPICS};
use analyze::summary;
#[cfg(feature = "tables")]
use analyze::summary::Query;
use schemas::topics;

/// The reductions of `analyze metrics`, fed generic trees (the reader before typed decoding).
struct Generic(Reductions);

impl schemas::Visitor for Generic {
    fn message(&mut self, m: schemas::DecodedMessage<'_>) -> Result<(), schemas::Error> {
        schemas::Visitor::message(&mut self.0, m)
    }

    fn metadata(&mut self, name: &str, entries: &std::collections::BTreeMap<String, String>) {
        schemas::Visitor::metadata(&mut self.0, name, entries)
    }
}

fn generic_metrics(p: &Path) -> analyze::metrics::RunMetrics {
    let mut acc = Generic(Reductions::default());
    let rec = schemas::stream_recording(p, Some(&METRIC_TOPICS), &mut acc).unwrap();
    acc.0.finish(&rec, None).unwrap()
}

fn mcap_files(dir: &Path) -> Vec<PathBuf> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "mcap"))
        .collect();
    paths.sort();
    paths
}

fn megabytes(paths: &[PathBuf]) -> f64 {
    paths.iter().map(|p| std::fs::metadata(p).map_or(0, |m| m.len())).sum::<u64>() as f64 / 1e6
}

/// The files of `paths` with their topics grouped per chunk, in `dir` (written when missing).
fn grouped(paths: &[PathBuf], dir: &Path) -> Vec<PathBuf> {
    std::fs::create_dir_all(dir).unwrap();
    let bulk: &[&str] = &[topics::TF, topics::HAND_POINTS, topics::JOINT_STATES, topics::ROBOT_DESCRIPTION];
    paths
        .iter()
        .map(|p| {
            let out = dir.join(p.file_name().unwrap());
            if !out.exists() {
                let bytes = std::fs::read(p).unwrap();
                std::fs::write(&out, schemas::regroup_chunks(&bytes, &[bulk], 1 << 20, true).unwrap()).unwrap();
            }
            out
        })
        .collect()
}

fn main() {
    // `cargo bench` passes `--bench`; take the first other argument as the folder
    let args: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with("--")).collect();
    let Some(dir) = args.first() else {
        eprintln!(
            "usage: cargo bench -p analyze --bench summary -- DIR [REPEATS]\n\
             (make DIR with: target/release/sim sweep sim/scenes/sweeps/summary-bench.json -o DIR)"
        );
        return;
    };
    let repeats: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(3);
    let only = args.get(2).cloned().unwrap_or_default();
    let paths = mcap_files(Path::new(dir));
    let grouped = grouped(&paths, &PathBuf::from(format!("{}-grouped", dir.trim_end_matches('/'))));
    let (mb, mb_grouped) = (megabytes(&paths), megabytes(&grouped));
    let n = paths.len();
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    println!("{n} recordings, {mb:.1} MB ({mb_grouped:.1} MB grouped), {cores} cores, best of {repeats}\n");
    for p in paths.iter().chain(&grouped) {
        let _ = std::fs::read(p); // warm the page cache
    }
    // the fast paths give the numbers of the generic one (checked when every row is run)
    for (p, g) in paths.iter().zip(&grouped).filter(|_| only.is_empty()) {
        let (a, b, mut c) = (generic_metrics(p), analyze::read_run_metrics(p).unwrap(), analyze::read_run_metrics(g).unwrap());
        assert_eq!(a, b, "{}: typed decoding changed the metrics", p.display());
        c.file.clone_from(&a.file);
        assert_eq!(a, c, "{}: the grouped file reads differently", g.display());
    }

    // (wall s, CPU s of the whole process) of the fastest repeat
    let best = |f: &dyn Fn() -> usize| -> (f64, f64) {
        (0..repeats)
            .map(|_| {
                let (t0, c0) = (Instant::now(), cpu_seconds());
                let rows = f();
                assert_eq!(rows, n, "every recording must be summarised");
                (t0.elapsed().as_secs_f64(), cpu_seconds() - c0)
            })
            .fold((f64::INFINITY, f64::INFINITY), |a, b| if b.0 < a.0 { b } else { a })
    };
    let params = vec!["controller.kp".to_string(), "controller.kd".to_string()];
    #[cfg(feature = "tables")]
    let query = Query {
        sort: vec!["E_j".into()],
        ..Query::default()
    };
    // (name, threads, MB read, run)
    type Method<'a> = (&'a str, usize, f64, Box<dyn Fn() -> usize + 'a>);
    let methods: Vec<Method> = vec![
        (
            "baseline: every topic, generic trees",
            1,
            mb,
            Box::new(|| each(&paths, |p| analyze::run_metrics(&schemas::read_recording(p).unwrap()).unwrap())),
        ),
        ("metric topics, generic trees", 1, mb, Box::new(|| each(&paths, generic_metrics))),
        ("metric topics, typed", 1, mb, Box::new(|| each(&paths, |p| analyze::read_run_metrics(p).unwrap()))),
        ("summary rows, typed", 1, mb, Box::new(|| rows(&paths, &params, 1))),
        ("summary rows, typed, all cores", cores, mb, Box::new(|| rows(&paths, &params, 0))),
        ("grouped: metric topics, generic trees", 1, mb_grouped, Box::new(|| each(&grouped, generic_metrics))),
        ("grouped: metric topics, typed", 1, mb_grouped, Box::new(|| each(&grouped, |p| analyze::read_run_metrics(p).unwrap()))),
        ("grouped: summary rows, typed, all cores", cores, mb_grouped, Box::new(|| rows(&grouped, &params, 0))),
        #[cfg(feature = "tables")]
        ("summary, 1 thread (+ polars table, sort)", 1, mb, Box::new(|| summarise(&paths, &params, 1, &query))),
        #[cfg(feature = "tables")]
        ("summary, all cores (+ polars table, sort)", cores, mb, Box::new(|| summarise(&paths, &params, 0, &query))),
    ];
    let mut base = None;
    println!(
        "{:<44} {:>8} {:>8} {:>8} {:>10} {:>8} {:>11} {:>12}",
        "method", "time [s]", "rec/s", "MB/s", "MB/s/core", "CPU [s]", "MB/CPU-s", "vs baseline"
    );
    for (name, threads, mbytes, f) in methods.iter().filter(|(name, ..)| name.contains(&only)) {
        let (t, cpu) = best(f.as_ref());
        let b = *base.get_or_insert(t);
        let rate = mbytes / t;
        println!(
            "{name:<44} {t:>8.3} {:>8.1} {rate:>8.1} {:>10.1} {cpu:>8.2} {:>11.1} {:>11.2}x",
            n as f64 / t,
            rate / *threads as f64,
            mbytes / cpu,
            b / t
        );
    }
}

/// Runs `f` on every path (its result kept from the optimiser); the number of paths.
fn each<T>(paths: &[PathBuf], f: impl Fn(&Path) -> T) -> usize {
    for p in paths {
        std::hint::black_box(f(p));
    }
    paths.len()
}

/// CPU time of this process so far (user + system, every thread), s, from `/proc/self/stat`
/// (clock ticks, `_SC_CLK_TCK` = 100 on Linux): NaN where there is none.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else { return f64::NAN };
    // fields after the command name (which may hold spaces) in parentheses: utime is the 14th
    // field of the line, stime the 15th
    let after = stat.rsplit_once(')').map_or("", |(_, rest)| rest);
    let fields: Vec<&str> = after.split_whitespace().collect();
    let tick = |k: usize| fields.get(k).and_then(|s| s.parse::<f64>().ok()).unwrap_or(f64::NAN);
    (tick(11) + tick(12)) / 100.0
}

fn rows(paths: &[PathBuf], params: &[String], threads: usize) -> usize {
    summary::read_rows(paths, params, threads, &|| {}).into_iter().map(Result::unwrap).count()
}

#[cfg(feature = "tables")]
fn summarise(paths: &[PathBuf], params: &[String], threads: usize, query: &Query) -> usize {
    let rows: Vec<_> = summary::read_rows(paths, params, threads, &|| {})
        .into_iter()
        .map(Result::unwrap)
        .collect();
    let df = summary::summary_frame(&rows, params).unwrap();
    query.run(df).unwrap().height()
}
