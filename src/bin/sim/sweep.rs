//! `sim sweep`: run a grid of scene variations (or one shard of it) on a work queue of threads,
//! with one progress bar, then print a summary with one row per recording. The sweep itself
//! (file, grid, shards, replacements, validation) is `sim::sweep`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use analyze::Format;
use anyhow::Result;
use cli::{exit, print_out, Jobs, TableFormat, Verbosity};
use rayon::prelude::*;
use serde::Serialize;
use serde_json::Value;
use sim::run::run_to_file_tapped;

use crate::run::MetricsTap;
use sim::sweep::{compact, Shard, Sweep, Variant};

/// Run a grid of scene variations in parallel (optionally one shard of it, for job arrays).
#[derive(Debug, Clone, clap::Args)]
#[command(after_help = "\
Output: DIR/<sweep>-<k>-<run>.mcap per grid point and run, DIR/sweep-manifest.json (variants,
replacements, files, status); on stdout one row per recording (axis values, E and W totals, hand
error, min normal force, status), -f json|csv for machines. --dry-run lists the variants
(-f json: as JSON) without running.

Examples:
  sim sweep sim/scenes/sweeps/paper-gains.json                 the whole grid on this machine
  sim sweep sim/scenes/sweeps/paper-gains.json --dry-run -f json
  sim sweep sweep.json --shard 3/16 -o results/                 grid points k with k % 16 == 3
  sim sweep sweep.json --shard ${SLURM_ARRAY_TASK_ID}/16 -o results/ -q
  analyze summary results/ --param controller.kp                merge the shards: one row per recording")]
pub struct SweepArgs {
    /// Sweep JSON file: a base scene, optional runs and duration, and the axes of the grid.
    #[arg(value_name = "SWEEP")]
    pub sweep: PathBuf,
    /// Directory for the recordings `<sweep>-<k>-<run>.mcap` and the manifest
    /// [default: out/sweep-<name>].
    #[arg(short = 'o', long = "out", value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Run only shard INDEX/COUNT of the grid (0-based): the grid points k with
    /// k % COUNT == INDEX. File names do not depend on the sharding.
    #[arg(long, value_name = "INDEX/COUNT")]
    pub shard: Option<Shard>,
    #[command(flatten)]
    pub jobs: Jobs,
    #[command(flatten)]
    pub format: TableFormat,
    /// Validate every variant of the shard and list them, without running.
    #[arg(long)]
    pub dry_run: bool,
    #[command(flatten)]
    pub wall_time: crate::run::WallTime,
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
    #[serde(rename = "E_total_j")]
    electric_energy_total_j: Option<f64>,
    #[serde(rename = "W_total_j")]
    link_work_total_j: Option<f64>,
    #[serde(rename = "err_norm_rms_m")]
    hand_error_rms_m: Option<f64>,
    #[serde(rename = "err_norm_max_m")]
    hand_error_max_m: Option<f64>,
    #[serde(rename = "err_z_rms_m")]
    hand_error_z_rms_m: Option<f64>,
    /// Smallest normal force over all contacts, N (none without contacts).
    #[serde(rename = "fn_min_n")]
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
    /// The failure is an I/O error (the recording could not be written), not a numerical one.
    io_error: bool,
    metrics: Option<Result<analyze::RunMetrics, String>>,
}

pub fn run(args: &SweepArgs, v: Verbosity) -> Result<u8> {
    let sweep = Sweep::load(&args.sweep)?;
    let shard = args.shard.unwrap_or(Shard::ALL);
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from(format!("out/sweep-{}", sweep.spec.name)));
    let variants = sweep.variants(shard);
    // every variant of this shard is validated before anything runs
    let scenes = variants.iter().map(|v| sweep.scene(v)).collect::<Result<Vec<_>, _>>()?;

    if args.dry_run {
        print_out(&dry_run(&sweep, shard, &variants, args.format.format)?)?;
        return Ok(exit::SUCCESS);
    }

    cli::create_dir(&out)?;
    // the work: every (variant, run) of the shard, in grid order
    let work: Vec<(usize, usize)> = (0..variants.len()).flat_map(|v| (0..sweep.runs.len()).map(move |r| (v, r))).collect();
    let threads = args.jobs.threads(work.len());
    let prefix = if shard == Shard::ALL { sweep.spec.name.clone() } else { format!("{} {shard}", sweep.spec.name) };
    let bar = cli::progress::count(work.len(), &prefix, "runs", v.quiet);
    let started = Instant::now();
    let budget = args.wall_time.budget();
    let one = |&(vi, ri): &(usize, usize)| -> Done {
        let (var, scene) = (&variants[vi], &scenes[vi]);
        let run_name = &sweep.runs[ri];
        let run = scene.run(run_name).expect("runs checked when the variant was validated");
        bar.set_message(format!("{} {run_name}", var.name));
        let path = out.join(Sweep::file_name(var, run_name));
        let (tap, metrics) = MetricsTap::new(&path);
        let done = match run_to_file_tapped(scene, run, &path, budget, Some(tap), |_| {}) {
            // the metrics from what the run wrote (as `analyze` reads them from the file)
            Ok((rep, tapped)) => {
                let metrics = metrics.metrics(tapped).map_err(|e| format!("the metrics of {}: {e}", rep.path.display()));
                // as `sim run`: a run whose contacts broke their laws is not a result (exit 1)
                let error = match &metrics {
                    Ok(m) => m.contact_law_failure().map(|why| {
                        format!("{} run `{run_name}` ({}): the contact laws do not hold: {why}", var.name, var.describe())
                    }),
                    Err(_) => None,
                };
                if let Some(e) = &error {
                    bar.println(format!("sim: error: {e}"));
                }
                Done { metrics: Some(metrics), path: Some(rep.path), error, io_error: false }
            }
            Err(e) => {
                // a numerical failure still leaves a recording that says when and why
                let written = e.time().is_some() && path.is_file();
                let error = format!("{} run `{run_name}` ({}): {e}", var.name, var.describe());
                bar.println(format!("sim: error: {error}"));
                Done { metrics: written.then(|| read_metrics(&path)), path: written.then(|| path.clone()), error: Some(error), io_error: e.is_io() }
            }
        };
        bar.inc(1);
        done
    };
    let results: Vec<Done> = match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
        Ok(pool) => pool.install(|| work.par_iter().map(one).collect()),
        Err(_) => work.iter().map(one).collect(),
    };
    bar.finish_with_message("done");
    let wall = started.elapsed().as_secs_f64();

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
    cli::write_file(&manifest_path, serde_json::to_string_pretty(&manifest)? + "\n")?;
    if !v.quiet {
        eprintln!(
            "sweep `{}` shard {shard}: {} variant(s) of {}, {} run(s) in {wall:.2} s wall time on {threads} thread(s); wrote {} and {}",
            sweep.spec.name,
            variants.len(),
            sweep.grid_size,
            work.len(),
            out.display(),
            manifest_path.display()
        );
    }

    let fields: Vec<String> = sweep.spec.axes.iter().map(|a| a.field.clone()).collect();
    print_out(&render(&rows, &fields, args.format.format)?)?;
    for f in &failures {
        eprintln!("sim: error: {f}");
    }
    // as `sim run`: 2 if a recording could not be written, 1 if a run failed numerically
    Ok(if results.iter().any(|d| d.io_error) {
        exit::BAD_INPUT
    } else if failures.is_empty() {
        exit::SUCCESS
    } else {
        exit::FAILED
    })
}

/// `--dry-run`: the variants of the shard, for people or as JSON.
fn dry_run(sweep: &Sweep, shard: Shard, variants: &[Variant], format: Format) -> Result<String> {
    if format == Format::Json {
        #[derive(Serialize)]
        struct DryRun<'a> {
            sweep: &'a str,
            file: &'a str,
            scene: &'a str,
            grid_size: usize,
            runs: &'a [String],
            shard: Shard,
            variants: &'a [Variant],
        }
        let d = DryRun { sweep: &sweep.spec.name, file: &sweep.file, scene: &sweep.scene_source, grid_size: sweep.grid_size, runs: &sweep.runs, shard, variants };
        return Ok(serde_json::to_string_pretty(&d)? + "\n");
    }
    let mut o = String::new();
    writeln!(
        o,
        "sweep `{}` ({}): {} grid points x {} run(s) of {}; shard {shard}: {} variant(s), all valid",
        sweep.spec.name, sweep.file, sweep.grid_size, sweep.runs.len(), sweep.scene_source, variants.len()
    )?;
    for v in variants {
        writeln!(o, "  {}: {}", v.name, v.describe())?;
    }
    Ok(o)
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

/// The metrics of a failed run's recording (a complete run's come from its writer).
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
            r.electric_energy_total_j = m.electric_energy_total_j;
            r.link_work_total_j = m.link_work_total_j;
            r.hand_error_rms_m = m.hand_error.as_ref().map(|h| h.norm.rms_m);
            r.hand_error_max_m = m.hand_error.as_ref().map(|h| h.norm.max_abs_m);
            r.hand_error_z_rms_m = m.hand_error.as_ref().map(|h| h.z.rms_m);
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
            let mut w = csv::Writer::from_writer(Vec::new());
            let mut head = vec!["index".to_string(), "variant".into(), "run".into()];
            head.extend(fields.iter().cloned());
            head.extend(
                ["status", "E_total_j", "W_total_j", "err_norm_rms_m", "err_norm_max_m", "err_z_rms_m", "fn_min_n", "file", "error"]
                    .map(String::from),
            );
            w.write_record(&head)?;
            let num = |x: Option<f64>| x.map_or(String::new(), |x| format!("{x:e}"));
            for r in rows {
                let mut cells = vec![r.index.to_string(), r.variant.clone(), r.run.clone()];
                cells.extend(r.values.iter().map(|(_, v)| match v {
                    Value::String(s) => s.clone(),
                    other => compact(other),
                }));
                cells.extend([
                    r.status.clone(),
                    num(r.electric_energy_total_j),
                    num(r.link_work_total_j),
                    num(r.hand_error_rms_m),
                    num(r.hand_error_max_m),
                    num(r.hand_error_z_rms_m),
                    num(r.min_normal_force_n),
                    r.file.clone(),
                    r.error.clone().unwrap_or_default(),
                ]);
                w.write_record(&cells)?;
            }
            Ok(String::from_utf8(w.into_inner()?)?)
        }
        Format::Table => {
            let mut head: Vec<String> = vec!["variant".into(), "run".into()];
            head.extend(fields.iter().cloned());
            let mut t = analyze::render::TextTable::new(&head.iter().map(String::as_str).collect::<Vec<_>>());
            t.head.extend(["E [J]", "W [J]", "|e| rms [mm]", "|e| max [mm]", "z rms [mm]", "min f_n [N]", "status"].map(String::from));
            t.left = head.len();
            t.rows = rows
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
            Ok(t.aligned())
        }
    }
}
