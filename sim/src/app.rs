//! What the `sim` commands do: load the scene, run the selected runs in parallel with progress
//! bars, then read the recordings back and print the comparison table (through the `analyze`
//! library, so the numbers shown are those any reader of the files gets).

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use sim::run::run_to_file;
use sim::scene::{Scene, PAPER_SCENE_JSON, PAPER_URDF};

use crate::cli::{Format, PrecisionArgs, ReplayArgs, RunArgs};

/// Exit status for a run that failed numerically (bad input exits with 2).
pub const EXIT_RUN_FAILED: u8 = 1;

pub fn load_scene(path: Option<&Path>) -> Result<Scene> {
    Ok(match path {
        Some(p) => Scene::load(p)?,
        None => Scene::paper()?,
    })
}

/// Write to stdout; a closed pipe (`sim ... | head`) ends the output quietly.
pub fn print_out(text: &str) -> Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        r => Ok(r.context("writing to stdout")?),
    }
}

/// `sim check`: validate and describe.
pub fn check(scene: Option<&Path>) -> Result<()> {
    use std::fmt::Write;
    let s = load_scene(scene)?;
    let mut o = String::new();
    let joints = s.model.joint_names();
    let joints = if joints.len() <= 12 { joints.join(", ") } else { format!("{} … {}", joints[..3].join(", "), joints[joints.len() - 2..].join(", ")) };
    writeln!(o, "scene `{}` ({}) is valid", s.spec.name, s.source)?;
    writeln!(o, "  robot `{}`: {} joints ({joints}), {:.3} kg moving", s.model.name, s.model.nv, s.model.total_mass())?;
    writeln!(o, "  contacts: {}", s.contacts.iter().map(|c| c.name.as_str()).collect::<Vec<_>>().join(", "))?;
    for r in &s.runs {
        let names: Vec<&str> = r.contacts.iter().map(|&k| s.contacts[k].name.as_str()).collect();
        writeln!(o, "  run `{}`: contacts [{}]", r.name, names.join(", "))?;
    }
    writeln!(
        o,
        "  {} s at {} Hz output; integrator {:?}; mass matrix {:?}; solver {:?}; stabilisation {:?}; motors {}",
        s.duration, s.output_rate, s.integrator, s.mass_matrix, s.solver, s.stabilization,
        if s.drives.quasi_static { "quasi-static (L = 0)" } else { "with inductance" }
    )?;
    print_out(&o)
}

/// `sim export-scene DIR`.
pub fn export_scene(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    for (name, text) in [("paper.json", PAPER_SCENE_JSON), ("paper_arm.urdf", PAPER_URDF)] {
        let p = dir.join(name);
        if p.exists() {
            bail!("{} exists; not overwriting it", p.display());
        }
        std::fs::write(&p, text).with_context(|| format!("cannot write {}", p.display()))?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}

/// The outcome of `sim run`: paths written, and whether every run completed.
pub struct RunOutcome {
    pub written: Vec<PathBuf>,
    pub failures: Vec<String>,
}

/// `sim [run]`.
pub fn run(args: &RunArgs) -> Result<RunOutcome> {
    let scene = load_scene(args.scene.as_deref())?;
    let runs: Vec<_> = if args.runs.is_empty() {
        scene.runs.clone()
    } else {
        args.runs
            .iter()
            .map(|n| {
                scene.run(n).cloned().with_context(|| {
                    format!("no run `{n}` in scene `{}` (runs: {})", scene.spec.name, scene.runs.iter().map(|r| r.name.as_str()).collect::<Vec<_>>().join(", "))
                })
            })
            .collect::<Result<_>>()?
    };
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create output directory {}", args.out.display()))?;

    let multi = MultiProgress::with_draw_target(if args.quiet { ProgressDrawTarget::hidden() } else { ProgressDrawTarget::stderr() });
    let style = ProgressStyle::with_template("{prefix:>12} [{bar:30.cyan/blue}] {msg:>9} simulated  {elapsed_precise}")
        .expect("a valid template")
        .progress_chars("=> ");
    let total_ms = (scene.duration * 1e3).round() as u64;
    let bars: Vec<ProgressBar> = runs
        .iter()
        .map(|r| {
            let b = multi.add(ProgressBar::new(total_ms));
            b.set_style(style.clone());
            b.set_prefix(r.name.clone());
            b.set_message("0.000 s");
            b
        })
        .collect();

    let jobs = args.jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())).max(1).min(runs.len());
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<(Result<PathBuf, String>, f64)>>> = Mutex::new(vec![None; runs.len()]);
    let started = Instant::now();
    std::thread::scope(|s| {
        for _ in 0..jobs {
            s.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::SeqCst);
                let Some(run) = runs.get(k) else { break };
                let path = args.out.join(format!("{}-{}.mcap", scene.spec.name, run.name));
                let bar = &bars[k];
                let t0 = Instant::now();
                let mut count = 0u32;
                let res = run_to_file(&scene, run, &path, |t| {
                    count += 1;
                    if count % 64 == 0 {
                        bar.set_position((t * 1e3).round() as u64);
                        bar.set_message(format!("{t:.3} s"));
                    }
                });
                let wall = t0.elapsed().as_secs_f64();
                match &res {
                    Ok(_) => bar.finish_with_message(format!("{:.3} s", scene.duration)),
                    Err(e) => bar.abandon_with_message(format!("failed at {}", e.time().map_or("?".into(), |t| format!("{t:.3} s")))),
                }
                let res = res.map(|r| r.path).map_err(|e| format!("run `{}`: {e}", run.name));
                results.lock().expect("no panics while holding the lock")[k] = Some((res, wall));
            });
        }
    });
    let wall_total = started.elapsed().as_secs_f64();
    let mut written = Vec::new();
    let mut failures = Vec::new();
    for (k, r) in results.into_inner().expect("threads joined").into_iter().enumerate() {
        match r {
            Some((Ok(p), wall)) => {
                if !args.quiet {
                    eprintln!("wrote {} ({:.0}x real time)", p.display(), scene.duration / wall.max(1e-9));
                }
                written.push(p);
            }
            Some((Err(e), _)) => failures.push(e),
            None => failures.push(format!("run `{}` did not start", runs[k].name)),
        }
    }
    if !args.quiet {
        eprintln!("{} run(s) in {:.2} s wall time on {} thread(s)", runs.len(), wall_total, jobs);
    }
    Ok(RunOutcome { written, failures })
}

/// Read the recordings back and print the comparison of the runs.
pub fn print_comparison(paths: &[PathBuf], format: Format, baseline: Option<&str>) -> Result<()> {
    let mut metrics = Vec::with_capacity(paths.len());
    for p in paths {
        metrics.push(analyze::read_run_metrics(p).with_context(|| format!("reading back {}", p.display()))?);
    }
    let cmp = analyze::Comparison::new(&metrics, baseline)?;
    let fmt = match format {
        Format::Table => analyze::Format::Table,
        Format::Json => analyze::Format::Json,
        Format::Csv => analyze::Format::Csv,
    };
    print_out(&analyze::render_comparison(&cmp, fmt)?)
}

/// `sim precision`: the work–precision table and plot of one run of a scene.
pub fn precision(args: &PrecisionArgs) -> Result<()> {
    use std::fmt::Write;
    let mut scene = load_scene(args.scene.as_deref())?;
    if let Some(d) = args.duration {
        if !(d > 0.0 && d.is_finite()) {
            bail!("--duration {d}: must be a positive number of seconds");
        }
        scene.duration = d;
    }
    let run = match &args.run {
        Some(n) => scene.run(n).cloned().with_context(|| format!("no run `{n}` in scene `{}`", scene.spec.name))?,
        None => scene.runs[0].clone(),
    };
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let ladder = sim::precision::default_ladder(&scene);
    let bar = if args.quiet { ProgressBar::hidden() } else { ProgressBar::new(ladder.len() as u64 + 1) };
    bar.set_style(ProgressStyle::with_template("{prefix:>10} [{bar:30.cyan/blue}] {pos}/{len} {msg}").expect("a valid template").progress_chars("=> "));
    bar.set_prefix("precision");
    bar.set_message("reference (dopri45, rtol 1e-12)");
    let reference = sim::precision::reference(&scene, &run)?;
    bar.inc(1);
    let mut rows = Vec::with_capacity(ladder.len());
    for v in &ladder {
        bar.set_message(format!("{} {}", v.series, v.setting));
        rows.push(sim::precision::measure(&scene, &run, v, &reference, args.repeats));
        bar.inc(1);
    }
    bar.finish_and_clear();

    // files for machines
    let json = serde_json::to_string_pretty(&rows)?;
    std::fs::write(args.out.join("precision.json"), json)?;
    let mut csv = String::from("series,setting,status,wall_s,rhs_evals,steps,rejected,max_hand_error_m,max_link_energy_error_j,max_drift_m,speed_vs_real_time\n");
    for r in &rows {
        writeln!(csv, "\"{}\",\"{}\",\"{}\",{:e},{},{},{},{:e},{:e},{:e},{:e}", r.series, r.setting, r.status.replace('"', "'"), r.wall_s, r.rhs_evals, r.steps, r.rejected, r.max_hand_error_m, r.max_link_energy_error_j, r.max_drift_m, r.speed_vs_real_time)?;
    }
    std::fs::write(args.out.join("precision.csv"), csv)?;
    let title = format!("{} / {}: {} s simulated", scene.spec.name, run.name, scene.duration);
    sim::plot::work_precision(&rows, &title, &args.out.join("work-precision")).map_err(anyhow::Error::msg)?;

    // the table for people
    let mut o = String::new();
    writeln!(o, "Speed against error: scene `{}`, run `{}`, {} s simulated; reference dopri45 rtol 1e-12", scene.spec.name, run.name, scene.duration)?;
    writeln!(o, "{:<42} {:<12} {:>10} {:>9} {:>9} {:>7} {:>11} {:>11} {:>10} {:>9}", "method", "setting", "wall [ms]", "RHS", "steps", "rejected", "hand [m]", "energy [J]", "drift [m]", "x real")?;
    for r in &rows {
        if r.status == "ok" {
            writeln!(o, "{:<42} {:<12} {:>10.2} {:>9} {:>9} {:>7} {:>11.2e} {:>11.2e} {:>10.1e} {:>9.0}", r.series, r.setting, r.wall_s * 1e3, r.rhs_evals, r.steps, r.rejected, r.max_hand_error_m, r.max_link_energy_error_j, r.max_drift_m, r.speed_vs_real_time)?;
        } else {
            writeln!(o, "{:<42} {:<12} {}", r.series, r.setting, r.status)?;
        }
    }
    let target = 1e-6;
    let best = sim::precision::cheapest_within(&rows, target);
    let baseline = best.iter().find(|r| r.series.starts_with("paper baseline")).map(|r| r.wall_s);
    writeln!(o, "\nCheapest run per method with max hand error <= {target:.0e} m:")?;
    for r in &best {
        let ratio = baseline.map_or(String::from("-"), |b| format!("{:.1}x faster than the paper baseline", b / r.wall_s));
        writeln!(o, "  {:<42} {:<12} {:>9.2} ms  {:>6.0}x real time  {ratio}", r.series, r.setting, r.wall_s * 1e3, r.speed_vs_real_time)?;
    }
    writeln!(o, "wrote {}/precision.csv, precision.json, work-precision.svg, work-precision.png", args.out.display())?;
    print_out(&o)
}

/// `sim replay`: rebuild the scene from a recording's metadata and run it again.
pub fn replay(args: &ReplayArgs) -> Result<()> {
    let (scene, run_name) = sim::replay::scene_from_recording(&args.recording)?;
    let run = scene
        .run(&run_name)
        .cloned()
        .with_context(|| format!("{}: the embedded scene has no run `{run_name}`", args.recording.display()))?;
    let name = args.recording.file_name().context("the recording path has no file name")?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let path = args.out.join(name);
    if path.canonicalize().ok() == args.recording.canonicalize().ok() {
        bail!("{}: replaying into the same file would overwrite the original; choose another -o", path.display());
    }
    let t0 = Instant::now();
    let written = run_to_file(&scene, &run, &path, |_| {})?;
    if !args.quiet {
        eprintln!("replayed run `{}` of scene `{}` into {} in {:.2} s", run.name, scene.spec.name, written.path.display(), t0.elapsed().as_secs_f64());
    }
    Ok(())
}
