//! Fuzzing the reading path: 10,000 inputs by default (`FUZZ_CASES=100000 cargo test -p
//! analyze --test fuzz_read` for more, `FUZZ_SEED` for another sequence) derived from a real
//! small recording (several chunks) — random bytes, random bytes behind the MCAP magic,
//! truncations, 1-8 bit flips, and record-level mutations (a top-level record's length or
//! opcode changed, a record deleted, duplicated or swapped with the next) — each written to a
//! file and read as users read it: `schemas::read_recording` (+ `analyze::run_metrics`),
//! the streamed `analyze::read_run_metrics`, and `analyze::read_run_metrics_recover`, under
//! `catch_unwind`: no panic may escape, every error names the input, and **no wrong answer**: a
//! damaged file whose metrics compute without `--recover` gives exactly the intact file's
//! metrics, and the streamed metrics are the in-memory ones. Panics that the reader catches
//! itself (mcap 0.26 and prost-reflect 0.16 on corrupt input no CRC covers; see
//! `schemas/src/reader.rs`) are errors, not failures; the panic hook is silenced meanwhile.

use std::panic::{catch_unwind, AssertUnwindSafe};

use schemas::synth::Synth;

/// `FUZZ_CASES` (default 10,000) and `FUZZ_SEED` from the environment.
fn config() -> (usize, u64) {
    let var = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<u64>().ok());
    (var("FUZZ_CASES").map_or(10_000, |n| n as usize), var("FUZZ_SEED").unwrap_or(0xF022_0000_2EAD_0001))
}

/// The tests below silence the process-wide panic hook meanwhile: they take turns.
static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());

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
}

/// Top-level records after the magic: (offset, total length incl. the 9-byte head).
fn records(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut at = 8;
    while at + 9 <= b.len() {
        let len = u64::from_le_bytes(b[at + 1..at + 9].try_into().unwrap()) as usize;
        if at + 9 + len > b.len() {
            break;
        }
        out.push((at, 9 + len));
        at += 9 + len;
    }
    out
}

fn mutate(r: &mut Rng, base: &[u8], recs: &[(usize, usize)]) -> Vec<u8> {
    match r.below(8) {
        0 => (0..r.below(3000)).map(|_| r.next() as u8).collect(),
        1 => {
            let mut b = base[..8].to_vec();
            b.extend((0..r.below(3000)).map(|_| r.next() as u8));
            b
        }
        2 | 3 => base[..r.below(base.len() + 1)].to_vec(),
        4 | 5 => {
            let mut b = base.to_vec();
            for _ in 0..1 + r.below(8) {
                let i = r.below(b.len());
                b[i] ^= 1 << r.below(8);
            }
            if r.below(3) == 0 {
                b.truncate(r.below(b.len() + 1));
            }
            b
        }
        _ => {
            let mut b = base.to_vec();
            let k = r.below(recs.len());
            let (at, len) = recs[k];
            match r.below(5) {
                0 => {
                    let v: u64 = match r.below(5) {
                        0 => 0,
                        1 => u64::MAX,
                        2 => (len as u64).wrapping_sub(9 + 1 + r.below(20) as u64),
                        3 => len as u64 + r.below(100) as u64,
                        _ => r.next() % (base.len() as u64 * 2),
                    };
                    b[at + 1..at + 9].copy_from_slice(&v.to_le_bytes());
                }
                1 => b[at] = r.next() as u8,
                2 => {
                    b.drain(at..at + len);
                }
                3 => {
                    let copy = b[at..at + len].to_vec();
                    b.splice(at..at, copy);
                }
                _ => {
                    if k + 1 < recs.len() {
                        let (at2, len2) = recs[k + 1];
                        let mut swapped = b[at2..at2 + len2].to_vec();
                        swapped.extend_from_slice(&b[at..at + len]);
                        b.splice(at..at2 + len2, swapped);
                    }
                }
            }
            b
        }
    }
}

#[test]
fn reading_path_never_panics() {
    let _turn = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().unwrap();
    let mut s = Synth::new("one-elbow", &["elbow4"], 2);
    (s.dt, s.n, s.chunk_size) = (1e-3, 39, Some(1024));
    let path = s.write(&dir.path().join("small.mcap"));
    let base = std::fs::read(path).unwrap();
    let recs = records(&base);
    assert!(
        recs.iter().filter(|(at, _)| base[*at] == 0x06).count() >= 4,
        "want several chunks"
    );
    let full = schemas::read_recording_bytes(&base, "base").unwrap();
    let intact = analyze::run_metrics(&full).unwrap();
    let (cases, seed) = config();

    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let mut r = Rng(seed);
    let mut escaped = Vec::new();
    let (mut read_ok, mut metrics_ok, mut recovered_metrics_ok) = (0, 0, 0);
    for case in 0..cases {
        let input = mutate(&mut r, &base, &recs);
        let file = dir.path().join(format!("case{case}.mcap"));
        std::fs::write(&file, &input).unwrap();
        let label = file.display().to_string();
        // the metrics of a file the normal reader accepts: the intact file's, whatever the damage
        let same = |m: &analyze::RunMetrics, how: &str| -> Result<(), String> {
            let m = analyze::RunMetrics { file: intact.file.clone(), ..m.clone() };
            if format!("{m:?}") == format!("{intact:?}") {
                Ok(())
            } else {
                Err(format!("{how}: a damaged file read without error gives other metrics"))
            }
        };
        let outcome = catch_unwind(AssertUnwindSafe(
            || -> Result<(usize, usize, usize), String> {
                let named = |e: String| {
                    if e.contains(&label) {
                        Ok(())
                    } else {
                        Err(format!("error without the file name: {e}"))
                    }
                };
                let mut n = (0, 0, 0);
                let in_memory = match schemas::read_recording(&file) {
                    Ok(rec) => {
                        n.0 = 1;
                        match analyze::run_metrics(&rec) {
                            Ok(m) => {
                                n.1 = 1;
                                same(&m, "read_recording + run_metrics")?;
                                Some(m)
                            }
                            Err(e) => {
                                named(e.to_string())?;
                                None
                            }
                        }
                    }
                    Err(e) => {
                        named(e.to_string())?;
                        None
                    }
                };
                match analyze::read_run_metrics(&file) {
                    Ok(m) => {
                        same(&m, "read_run_metrics")?;
                        if in_memory.is_none() {
                            return Err("the streamed metrics read a file the in-memory reader refuses".into());
                        }
                    }
                    Err(e) => named(e.to_string())?,
                }
                match analyze::read_run_metrics_recover(&file) {
                    Ok((m, report)) => {
                        named(report.to_string())?;
                        if report.complete != (n.0 == 1) {
                            return Err(format!(
                                "recover says complete = {}: {report}",
                                report.complete
                            ));
                        }
                        if report.complete {
                            same(&m, "read_run_metrics_recover of a complete file")?;
                        }
                        n.2 = 1;
                    }
                    Err(e) => named(e.to_string())?,
                }
                Ok(n)
            },
        ));
        match outcome {
            Ok(Ok((a, b, c))) => {
                read_ok += a;
                metrics_ok += b;
                recovered_metrics_ok += c;
            }
            Ok(Err(why)) => escaped.push(format!("case {case} ({} bytes): {why}", input.len())),
            Err(_) => escaped.push(format!("case {case} ({} bytes): panicked", input.len())),
        }
        std::fs::remove_file(&file).unwrap();
    }
    std::panic::set_hook(hook);
    eprintln!(
        "reading_path_never_panics: {cases} inputs (seed {seed:#x}); read {read_ok}, metrics {metrics_ok}, \
         metrics after recovery {recovered_metrics_ok}"
    );
    assert!(
        escaped.is_empty(),
        "{} failures:\n{}",
        escaped.len(),
        escaped[..escaped.len().min(20)].join("\n")
    );
    // the generator reaches the deep paths: recovery yields metrics far more often than a full read
    assert!(
        recovered_metrics_ok > metrics_ok && recovered_metrics_ok > cases / 10,
        "{recovered_metrics_ok}"
    );
}

/// What one command's reading path gave for a damaged file: `Ok(true)` it read, with exactly
/// the intact file's result; `Ok(false)` a refusal naming the file; `Err` a failure.
type Outcome = Result<bool, String>;

/// The reading paths behind the other commands (issue 29): `diff` (`analyze::read_input`),
/// `figures` (`figures::read_run`), `export` (`frames::streamed`: the plan and each topic's batches), `layout` (the streamed
/// reader + `LayoutInput`), `view` (`view::read_input`); `metrics`, `compare`, `summary` and
/// `report` read through `read_run_metrics` and `--recover` through `read_run_metrics_recover`
/// (both in [`reading_path_never_panics`]). The same generator and rule: no panic, an error
/// naming the file, or the intact file's result exactly. Default 2,000 cases (`FUZZ_CASES`
/// sets it, as for the test above); the counts per command are printed.
#[test]
fn every_commands_reading_path_never_panics() {
    let _turn = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().unwrap();
    let mut s = Synth::new("one-elbow", &["elbow4"], 2);
    (s.dt, s.n, s.chunk_size) = (1e-3, 39, Some(1024));
    let path = s.write(&dir.path().join("small.mcap"));
    let base = std::fs::read(&path).unwrap();
    let recs = records(&base);
    let (cases, seed) = config();
    let cases = std::env::var("FUZZ_CASES").ok().map_or(2_000, |_| cases);

    // the intact file's results, each command's own way
    // (errors as their text: what is checked is that they name the file)
    let diff_of = |p: &std::path::Path| {
        analyze::read_input(p).map(|i| i.runs.into_iter().map(|r| format!("{:?}", r.values)).collect::<Vec<_>>()).map_err(|e| e.to_string())
    };
    let figures_of =
        |p: &std::path::Path| analyze::figures::read_run(p).map(|r| analyze::figures::RunSeries { name: String::new(), ..r }).map_err(|e| e.to_string());
    // export's path: the plan, then each topic's batches, stacked
    let frames_of = |p: &std::path::Path| -> Result<Vec<(String, polars::prelude::DataFrame)>, String> {
        let s = analyze::frames::streamed::plan(p, analyze::frames::Selection::default()).map_err(|e| e.to_string())?;
        let mut out = Vec::new();
        for (k, t) in s.topics.iter().enumerate() {
            let mut df: Option<polars::prelude::DataFrame> = None;
            s.batches(k, analyze::frames::streamed::MAX_CELLS, |b| {
                match df.as_mut() {
                    Some(d) => drop(d.vstack_mut(&b.frame)),
                    None => df = Some(b.frame),
                }
                Ok(())
            })
            .map_err(|e| e.to_string())?;
            out.extend(df.map(|d| (t.topic.clone(), d)));
        }
        Ok(out)
    };
    let layout_of = |p: &std::path::Path| -> Result<serde_json::Value, String> {
        let rec = schemas::read_recording_topics(p, Some(&[schemas::topics::HAND])).map_err(|e| e.to_string())?;
        Ok(schemas::layout::foxglove(&schemas::layout::LayoutInput::from_recording(&rec).map_err(|e| e.to_string())?))
    };
    // `view` needs the feature `rerun` (`cargo test -p analyze --all-features --test fuzz_read`)
    #[cfg(feature = "rerun")]
    let view_of = |p: &std::path::Path| {
        // the survey and the windowed drawing: the whole `.rrd` (recording id made
        // independent of the file's bytes)
        let mut input = analyze::view::read_input(p).map_err(|e| e.to_string())?;
        input.hash = 0;
        analyze::view::encode(&[input], "fuzz").map(|b| vec![format!("{b:?}")]).map_err(|e| e.to_string())
    };
    #[cfg(not(feature = "rerun"))]
    let view_of = |_: &std::path::Path| -> Result<Vec<String>, String> { Ok(Vec::new()) };
    let intact = (diff_of(&path).unwrap(), figures_of(&path).unwrap(), frames_of(&path).unwrap(), layout_of(&path).unwrap(), view_of(&path).unwrap());

    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let mut r = Rng(seed ^ 0x29);
    let names = ["diff", "figures", "export", "layout", "view"];
    let mut read = [0usize; 5];
    let mut refused = [0usize; 5];
    let mut escaped = Vec::new();
    for case in 0..cases {
        let input = mutate(&mut r, &base, &recs);
        let file = dir.path().join(format!("case{case}.mcap"));
        std::fs::write(&file, &input).unwrap();
        let label = file.display().to_string();
        let judge = |result: Result<bool, String>| -> Outcome {
            match result {
                Ok(same) if same => Ok(true),
                Ok(_) => Err("read without error, with another result than the intact file's".into()),
                Err(e) if e.contains(&label) => Ok(false),
                Err(e) => Err(format!("error without the file name: {e}")),
            }
        };
        let paths: [Box<dyn Fn() -> Outcome>; 5] = [
            Box::new(|| judge(diff_of(&file).map(|v| v == intact.0))),
            Box::new(|| judge(figures_of(&file).map(|v| v == intact.1))),
            Box::new(|| {
                judge(
                    frames_of(&file)
                        .map(|v| v.len() == intact.2.len() && v.iter().zip(&intact.2).all(|(a, b)| a.0 == b.0 && a.1.equals_missing(&b.1))),
                )
            }),
            Box::new(|| judge(layout_of(&file).map(|v| v == intact.3))),
            Box::new(|| judge(view_of(&file).map(|v| v == intact.4))),
        ];
        for (k, run) in paths.iter().enumerate() {
            match catch_unwind(AssertUnwindSafe(run)) {
                Ok(Ok(true)) => read[k] += 1,
                Ok(Ok(false)) => refused[k] += 1,
                Ok(Err(why)) => escaped.push(format!("case {case} ({} bytes), {}: {why}", input.len(), names[k])),
                Err(_) => escaped.push(format!("case {case} ({} bytes), {}: panicked", input.len(), names[k])),
            }
        }
        std::fs::remove_file(&file).unwrap();
    }
    std::panic::set_hook(hook);
    let counts: Vec<String> = (0..5).map(|k| format!("{} read {} refused {}", names[k], read[k], refused[k])).collect();
    eprintln!("every_commands_reading_path_never_panics: {cases} inputs (seed {seed:#x}); {}", counts.join("; "));
    assert!(escaped.is_empty(), "{} failures:\n{}", escaped.len(), escaped[..escaped.len().min(20)].join("\n"));
    assert!((0..5).all(|k| read[k] + refused[k] == cases));
    if cfg!(not(feature = "rerun")) {
        eprintln!("every_commands_reading_path_never_panics: `view` not covered: build with --all-features (feature rerun)");
    }
}
