//! Throughput of `analyze summary`: recordings per second and MB/s read, over a folder of
//! recordings, against the baseline of decoding every topic on one thread (what
//! `analyze metrics` did before the summary existed). Prints a table; speeds are stated as
//! ratios to that baseline, measured in the same run.
//!
//! ```text
//! target/release/sim sweep sim/scenes/sweeps/summary-bench.json -o /tmp/corpus   # 200 recordings
//! cargo bench -p analyze --bench summary -- /tmp/corpus [REPEATS]
//! ```
//!
//! Each method reads the whole folder `REPEATS` times (default 3) and the best time is kept
//! (the folder is read once before, so every method sees the files in the page cache).

use std::path::PathBuf;
use std::time::Instant;

use analyze::metrics::METRIC_TOPICS;
use analyze::summary;
#[cfg(feature = "tables")]
use analyze::summary::Query;

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
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{dir}: {e}"))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "mcap"))
        .collect();
    paths.sort();
    let bytes: u64 = paths.iter().map(|p| std::fs::metadata(p).map_or(0, |m| m.len())).sum();
    let mb = bytes as f64 / 1e6;
    let n = paths.len();
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    println!("{n} recordings, {mb:.1} MB, {cores} cores, best of {repeats}\n");
    for p in &paths {
        let _ = std::fs::read(p); // warm the page cache
    }

    let best = |f: &dyn Fn() -> usize| -> f64 {
        (0..repeats)
            .map(|_| {
                let t0 = Instant::now();
                let rows = f();
                assert_eq!(rows, n, "every recording must be summarised");
                t0.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min)
    };
    let params = vec!["controller.kp".to_string(), "controller.kd".to_string()];
    #[cfg(feature = "tables")]
    let query = Query {
        sort: vec!["E_j".into()],
        ..Query::default()
    };
    let methods: Vec<(&str, Box<dyn Fn() -> usize>)> = vec![
        (
            "baseline: every topic decoded, 1 thread",
            Box::new(|| {
                paths
                    .iter()
                    .map(|p| analyze::run_metrics(&schemas::read_recording(p).unwrap()).unwrap())
                    .count()
            }),
        ),
        (
            "metric topics only, 1 thread",
            Box::new(|| {
                paths
                    .iter()
                    .map(|p| {
                        let rec = schemas::read_recording_topics(p, Some(&METRIC_TOPICS)).unwrap();
                        analyze::run_metrics(&rec).unwrap()
                    })
                    .count()
            }),
        ),
        ("summary rows, 1 thread", Box::new(|| rows(&paths, &params, 1))),
        ("summary rows, all cores", Box::new(|| rows(&paths, &params, 0))),
        #[cfg(feature = "tables")]
        ("summary, 1 thread (+ polars table, sort)", Box::new(|| summarise(&paths, &params, 1, &query))),
        #[cfg(feature = "tables")]
        ("summary, all cores (+ polars table, sort)", Box::new(|| summarise(&paths, &params, 0, &query))),
    ];
    let mut base = None;
    println!("{:<44} {:>9} {:>10} {:>9} {:>12}", "method", "time [s]", "rec/s", "MB/s", "vs baseline");
    for (name, f) in &methods {
        let t = best(f.as_ref());
        let b = *base.get_or_insert(t);
        println!("{name:<44} {t:>9.3} {:>10.1} {:>9.1} {:>11.2}x", n as f64 / t, mb / t, b / t);
    }
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
