//! `sim sweep`: run a grid of scene variations (or one shard of it) on a work queue of threads,
//! with one progress bar, then print a summary with one row per recording. The sweep itself
//! (file, grid, shards, replacements, validation) is `sim::sweep`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use serde_json::Value;
use sim::run::run_to_file;
use sim::sweep::{compact, Shard, Sweep, Variant};

use crate::app::{print_out, EXIT_RUN_FAILED};
use crate::cli::Format;

/// Arguments of `sim sweep`.
#[derive(Debug, Clone, clap::Args)]
#[command(after_help = "Examples:\n  \
    sim sweep sim/scenes/sweeps/paper-gains.json                 the whole grid on this machine\n  \
    sim sweep sweep.json --shard 3/16 -o results/                 grid points k with k % 16 == 3\n  \
    sim sweep sweep.json --shard ${SLURM_ARRAY_TASK_ID}/16 -o results/\n  \
    analyze summary results/ --param controller.kp --format csv    merge the shards: one row per recording")]
pub struct SweepArgs {
    /// Sweep JSON file: a base scene, optional runs and duration, and the axes of the grid.
    pub sweep: PathBuf,
    /// Directory for the recordings `<sweep>-<k>-<run>.mcap` and the manifest
    /// (default: out/sweep-<name>).
    #[arg(short, long)]
    pub out: Option<PathBuf>,
    /// Run only shard INDEX/COUNT of the grid (0-based): the grid points k with
    /// k % COUNT == INDEX. File names do not depend on the sharding.
    #[arg(long, value_name = "INDEX/COUNT")]
    pub shard: Option<Shard>,
    /// Runs in parallel (default: the number of cores). Results do not depend on it.
    #[arg(short, long)]
    pub jobs: Option<usize>,
    /// How to print the summary.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    pub format: Format,
    /// Validate every variant of the shard and list them, without running.
    #[arg(long)]
    pub dry_run: bool,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

/// One recording of the manifest.
#[derive(Debug, Clone, Serialize)]
struct ManifestFile {
    run: String,
    file: String,
    status: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    error: Option<String>,
}

#[derive(Debug, Clone, Serialize)]
struct ManifestVariant {
    index: usize,
    name: String,
    replacements: Vec<Replacement>,
    files: Vec<ManifestFile>,
}

#[derive(Debug, Clone, Serialize)]
struct Replacement {
    field: String,
    value: Value,
}

#[derive(Debug, Clone, Serialize)]
struct Manifest {
    sweep: String,
    file: String,
    scene: String,
    tool: &'static str,
    shard: Shard,
    grid_size: usize,
    runs: Vec<String>,
    axes: Vec<String>,
    variants: Vec<ManifestVariant>,
}

/// One row of the summary: a recording.
#[derive(Debug, Clone, Serialize)]
struct Row {
    index: usize,
    variant: String,
    run: String,
    file: String,
    /// Axis values, in axis order (JSON: field -> value).
    #[serde(serialize_with = "ser_values")]
    values: Vec<(String, Value)>,
    status: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    error: Option<String>,
    electric_energy_total_j: Option<f64>,
    link_work_total_j: Option<f64>,
    hand_error_rms_m: Option<f64>,
    hand_error_max_m: Option<f64>,
    hand_error_z_rms_m: Option<f64>,
    /// Smallest normal force over all contacts, N (none without contacts).
    min_normal_force_n: Option<f64>,
}

fn ser_values<S: serde::Serializer>(v: &[(String, Value)], s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeMap;
    let mut m = s.serialize_map(Some(v.len()))?;
    for (k, x) in v {
        m.serialize_entry(k, x)?;
    }
    m.end()
}

/// The outcome of one run of one variant.
struct Done {
    path: Option<PathBuf>,
    error: Option<String>,
    metrics: Option<Result<analyze::RunMetrics, String>>,
}

pub fn run(args: &SweepArgs) -> Result<ExitCode> {
    let sweep = Sweep::load(&args.sweep)?;
    let shard = args.shard.unwrap_or(Shard::ALL);
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from(format!("out/sweep-{}", sweep.spec.name)));
    let variants = sweep.variants(shard);
    // every variant of this shard is validated before anything runs
    let scenes = variants.iter().map(|v| sweep.scene(v)).collect::<Result<Vec<_>, _>>()?;

    if args.dry_run {
        let mut o = String::new();
        writeln!(
            o,
            "sweep `{}` ({}): {} grid points x {} run(s) of {}; shard {shard}: {} variant(s), all valid",
            sweep.spec.name, sweep.file, sweep.grid_size, sweep.runs.len(), sweep.scene_source, variants.len()
        )?;
        for v in &variants {
            writeln!(o, "  {}: {}", v.name, v.describe())?;
        }
        print_out(&o)?;
        return Ok(ExitCode::SUCCESS);
    }

    std::fs::create_dir_all(&out).with_context(|| format!("cannot create output directory {}", out.display()))?;
    // the work queue: every (variant, run) of the shard, in grid order
    let work: Vec<(usize, usize)> =
        (0..variants.len()).flat_map(|v| (0..sweep.runs.len()).map(move |r| (v, r))).collect();
    let jobs = args.jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())).max(1).min(work.len().max(1));
    let bar = ProgressBar::with_draw_target(
        Some(work.len() as u64),
        if args.quiet { ProgressDrawTarget::hidden() } else { ProgressDrawTarget::stderr() },
    );
    bar.set_style(
        ProgressStyle::with_template("{prefix:>12} [{bar:30.cyan/blue}] {pos}/{len} runs  {elapsed_precise} (eta {eta})  {msg}")
            .expect("a valid template")
            .progress_chars("=> "),
    );
    bar.set_prefix(if shard == Shard::ALL { sweep.spec.name.clone() } else { format!("{} {shard}", sweep.spec.name) });

    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<Done>>> = Mutex::new((0..work.len()).map(|_| None).collect());
    let started = Instant::now();
    std::thread::scope(|s| {
        for _ in 0..jobs {
            s.spawn(|| loop {
                let w = next.fetch_add(1, Ordering::SeqCst);
                let Some(&(vi, ri)) = work.get(w) else { break };
                let (v, scene) = (&variants[vi], &scenes[vi]);
                let run_name = &sweep.runs[ri];
                let run = scene.run(run_name).expect("runs checked when the variant was validated");
                bar.set_message(format!("{} {run_name}", v.name));
                let path = out.join(Sweep::file_name(v, run_name));
                let done = match run_to_file(scene, run, &path, |_| {}) {
                    Ok(rep) => Done { metrics: Some(read_metrics(&rep.path)), path: Some(rep.path), error: None },
                    Err(e) => {
                        // a numerical failure still leaves a recording that says when and why
                        let written = e.time().is_some() && path.is_file();
                        let error = format!("{} run `{run_name}` ({}): {e}", v.name, v.describe());
                        bar.println(format!("sim: error: {error}"));
                        Done {
                            metrics: written.then(|| read_metrics(&path)),
                            path: written.then(|| path.clone()),
                            error: Some(error),
                        }
                    }
                };
                results.lock().expect("no panics while holding the lock")[w] = Some(done);
                bar.inc(1);
            });
        }
    });
    bar.finish_with_message("done");
    let wall = started.elapsed().as_secs_f64();
    let results: Vec<Done> = results
        .into_inner()
        .expect("threads joined")
        .into_iter()
        .map(|d| d.unwrap_or(Done { path: None, error: Some("did not run".into()), metrics: None }))
        .collect();

    // rows, manifest and failures, in grid order
    let mut rows = Vec::with_capacity(work.len());
    let mut failures = Vec::new();
    let mut manifest_variants: Vec<ManifestVariant> = variants
        .iter()
        .map(|v| ManifestVariant {
            index: v.index,
            name: v.name.clone(),
            replacements: v.replacements.iter().map(|(f, x)| Replacement { field: f.clone(), value: x.clone() }).collect(),
            files: Vec::new(),
        })
        .collect();
    for (&(vi, ri), d) in work.iter().zip(&results) {
        let v = &variants[vi];
        let run = &sweep.runs[ri];
        let file = Sweep::file_name(v, run);
        if let Some(e) = &d.error {
            failures.push(e.clone());
        }
        let status = match (&d.error, &d.path) {
            (None, _) => "complete",
            (Some(_), Some(_)) => "failed",
            (Some(_), None) => "not written",
        };
        manifest_variants[vi].files.push(ManifestFile { run: run.clone(), file: file.clone(), status: status.into(), error: d.error.clone() });
        rows.push(row(v, run, &file, status, d));
    }
    let manifest = Manifest {
        sweep: sweep.spec.name.clone(),
        file: sweep.file.clone(),
        scene: sweep.scene_source.clone(),
        tool: sim::record::TOOL,
        shard,
        grid_size: sweep.grid_size,
        runs: sweep.runs.clone(),
        axes: sweep.spec.axes.iter().map(|a| a.field.clone()).collect(),
        variants: manifest_variants,
    };
    let manifest_path = out.join(manifest_name(shard));
    std::fs::write(&manifest_path, serde_json::to_string_pretty(&manifest)? + "\n")
        .with_context(|| format!("cannot write {}", manifest_path.display()))?;
    if !args.quiet {
        eprintln!(
            "sweep `{}` shard {shard}: {} variant(s) of {}, {} run(s) in {wall:.2} s wall time on {jobs} thread(s); wrote {} and {}",
            sweep.spec.name,
            variants.len(),
            sweep.grid_size,
            work.len(),
            out.display(),
            manifest_path.display()
        );
    }

    let fields: Vec<String> = sweep.spec.axes.iter().map(|a| a.field.clone()).collect();
    print_out(&render(&rows, &fields, args.format)?)?;
    for f in &failures {
        eprintln!("sim: error: {f}");
    }
    Ok(if failures.is_empty() { ExitCode::SUCCESS } else { ExitCode::from(EXIT_RUN_FAILED) })
}

/// `sweep-manifest.json`, or `sweep-manifest.shard-<i>-of-<n>.json` for a shard (so that the
/// shards of a job array can share one output directory).
fn manifest_name(shard: Shard) -> String {
    if shard == Shard::ALL {
        "sweep-manifest.json".into()
    } else {
        format!("sweep-manifest.shard-{}-of-{}.json", shard.index, shard.count)
    }
}

fn read_metrics(p: &Path) -> Result<analyze::RunMetrics, String> {
    analyze::read_run_metrics(p).map_err(|e| format!("reading back {}: {e}", p.display()))
}

fn row(v: &Variant, run: &str, file: &str, status: &str, d: &Done) -> Row {
    let mut r = Row {
        index: v.index,
        variant: v.name.clone(),
        run: run.to_string(),
        file: file.to_string(),
        values: v.replacements.clone(),
        status: status.to_string(),
        error: d.error.clone(),
        electric_energy_total_j: None,
        link_work_total_j: None,
        hand_error_rms_m: None,
        hand_error_max_m: None,
        hand_error_z_rms_m: None,
        min_normal_force_n: None,
    };
    match &d.metrics {
        Some(Ok(m)) => {
            r.electric_energy_total_j = Some(m.electric_energy_total_j);
            r.link_work_total_j = Some(m.link_work_total_j);
            r.hand_error_rms_m = Some(m.hand_error.norm.rms_m);
            r.hand_error_max_m = Some(m.hand_error.norm.max_abs_m);
            r.hand_error_z_rms_m = Some(m.hand_error.z.rms_m);
            r.min_normal_force_n = m.contact_forces.iter().map(|c| c.min_normal_force_n).reduce(f64::min);
        }
        Some(Err(e)) => {
            r.error = Some(r.error.take().map_or(e.clone(), |x| format!("{x}; {e}")));
        }
        None => {}
    }
    r
}

/// A JSON value for a table cell: numbers and strings bare, objects as `method k=v …`.
fn short(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Object(m) => m
            .get("method")
            .map(short)
            .into_iter()
            .chain(m.iter().filter(|(k, _)| *k != "method").map(|(k, x)| format!("{k}={}", short(x))))
            .collect::<Vec<_>>()
            .join(" "),
        other => compact(other),
    }
}

fn csv_cell(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn opt(x: Option<f64>, f: impl Fn(f64) -> String) -> String {
    x.map_or_else(|| "-".into(), f)
}

/// `x` with `digits` decimals, or in exponent form when that would be unreadably long.
fn fixed(x: f64, digits: usize) -> String {
    if x.is_finite() && x.abs() >= 1e7 {
        format!("{x:.3e}")
    } else {
        format!("{x:.digits$}")
    }
}

fn render(rows: &[Row], fields: &[String], format: Format) -> Result<String> {
    match format {
        Format::Json => Ok(serde_json::to_string_pretty(rows)? + "\n"),
        Format::Csv => {
            let mut o = String::new();
            let mut head = vec!["index".to_string(), "variant".into(), "run".into()];
            head.extend(fields.iter().map(|f| csv_cell(f)));
            head.extend(
                [
                    "status", "electric_energy_total_j", "link_work_total_j", "hand_error_rms_m", "hand_error_max_m",
                    "hand_error_z_rms_m", "min_normal_force_n", "file", "error",
                ]
                .map(String::from),
            );
            writeln!(o, "{}", head.join(","))?;
            let num = |x: Option<f64>| x.map_or(String::new(), |x| format!("{x:e}"));
            for r in rows {
                let mut cells = vec![r.index.to_string(), csv_cell(&r.variant), csv_cell(&r.run)];
                cells.extend(r.values.iter().map(|(_, v)| csv_cell(&match v {
                    Value::String(s) => s.clone(),
                    other => compact(other),
                })));
                cells.extend([
                    r.status.clone(),
                    num(r.electric_energy_total_j),
                    num(r.link_work_total_j),
                    num(r.hand_error_rms_m),
                    num(r.hand_error_max_m),
                    num(r.hand_error_z_rms_m),
                    num(r.min_normal_force_n),
                    csv_cell(&r.file),
                    csv_cell(r.error.as_deref().unwrap_or("")),
                ]);
                writeln!(o, "{}", cells.join(","))?;
            }
            Ok(o)
        }
        Format::Table => {
            let mut head: Vec<String> = vec!["variant".into(), "run".into()];
            head.extend(fields.iter().cloned());
            let numeric_from = head.len();
            head.extend(
                ["E [J]", "W [J]", "|e| rms [mm]", "|e| max [mm]", "z rms [mm]", "min f_n [N]", "status"].map(String::from),
            );
            let cells: Vec<Vec<String>> = rows
                .iter()
                .map(|r| {
                    let mut c = vec![r.variant.clone(), r.run.clone()];
                    c.extend(r.values.iter().map(|(_, v)| short(v)));
                    c.extend([
                        opt(r.electric_energy_total_j, |x| fixed(x, 4)),
                        opt(r.link_work_total_j, |x| fixed(x, 4)),
                        opt(r.hand_error_rms_m, |x| fixed(x * 1e3, 3)),
                        opt(r.hand_error_max_m, |x| fixed(x * 1e3, 3)),
                        opt(r.hand_error_z_rms_m, |x| fixed(x * 1e3, 3)),
                        opt(r.min_normal_force_n, |x| fixed(x, 3)),
                        r.status.clone(),
                    ]);
                    c
                })
                .collect();
            let widths: Vec<usize> = (0..head.len())
                .map(|j| cells.iter().map(|c| c[j].chars().count()).chain([head[j].chars().count()]).max().unwrap_or(0))
                .collect();
            let line = |c: &[String]| {
                c.iter()
                    .enumerate()
                    .map(|(j, s)| {
                        let pad = widths[j] - s.chars().count();
                        // numbers right-aligned, the status and text left-aligned
                        if j >= numeric_from && j + 1 < head.len() { format!("{}{s}", " ".repeat(pad)) } else { format!("{s}{}", " ".repeat(pad)) }
                    })
                    .collect::<Vec<_>>()
                    .join("  ")
                    .trim_end()
                    .to_string()
            };
            let mut o = String::new();
            writeln!(o, "{}", line(&head))?;
            writeln!(o, "{}", widths.iter().map(|&w| "-".repeat(w)).collect::<Vec<_>>().join("  "))?;
            for c in &cells {
                writeln!(o, "{}", line(c))?;
            }
            Ok(o)
        }
    }
}
