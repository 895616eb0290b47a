//! `sim optimize`: a design study (`sim::study`): ask the optimiser for a generation of
//! candidates, run them in parallel (rayon) at the evaluations' tolerance, tell it their
//! objective (+∞ and the reason for an infeasible one), write the state; at the end re-run the
//! optimum and the baseline at the tight tolerance (their recordings kept) and write the
//! outputs: the optimum as a scene, the best designs, every evaluation, the convergence, the map
//! of the objective over the first continuous variable, the Pareto front of energy against
//! hand error, and a report.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use cli::{exit, print_out, Jobs, Verbosity};
use rayon::prelude::*;
use serde_json::Value;
use sim::run::{run_to_file_tapped, Budget};
use sim::study::optimizer::{Optimizer, Point};
use sim::study::calibration::{self, Calibration, CalibrationDesign, Job, JobResult, ERROR_BAR_FACTOR};
use sim::study::state::{shard_file, Evaluation, ShardResult, State, STATE_FILE};
use sim::study::Study;
use sim::sweep::{Shard, Sweep, Variant};

use crate::run::MetricsTap;

/// Find the design that minimises a run's electric energy: a study file names a base scene, the
/// design variables (any scene field by its dot path: a contact's place on a link, the table's
/// height, which elbows rest, gains, ...), the objective, the constraints and the method
/// (CMA-ES over the continuous variables, discrete ones enumerated, then compass search).
#[derive(Debug, Clone, clap::Args)]
#[command(after_help = "\
Output (in --out, default out/study-<name>): study-state.json (the optimiser's state and every
evaluation, written after each generation: run the same command again to resume after a kill),
optimum.json (the best design as a scene `sim run` runs), best.csv, evaluations.csv,
pareto.csv, convergence/map/pareto .svg and .png, report.md (also printed), and the recordings
of the optimum and of the baseline at the tight tolerance (optimum-<run>.mcap,
baseline-<run>.mcap). Every other candidate's recording is deleted once its metrics are read.
The same study file and seed give byte-identical outputs.

A job array: each task runs `sim optimize STUDY --shard $I/$N -o DIR` (its part of the pending
generation, written to DIR/gen-<g>.shard-<i>-of-<n>.json), then one `sim optimize STUDY -o DIR
--generations 1` takes them, tells the optimiser and writes the state; repeat.

Exit status: 0 the study finished (or stopped at --generations), 1 no feasible design was
found, 2 bad input.

With --seeds N the study runs N times, with the study's seed, seed + 1, ..., each in
DIR/seed-<s>/ (each a whole study: resumable, byte-identical for its seed), then DIR/seeds.md
(also printed) and DIR/seeds.csv give every combination's best design per seed, the best over
the seeds and their spread (max - min): how well the search pins the optimum down, beside the
tolerance's error bar.

Examples:
  sim optimize sim/scenes/studies/which-elbow.json -j 2
  sim optimize sim/scenes/studies/small-kd.json --seeds 3   the optimum's spread over 3 seeds
  sim optimize my-study.json --generations 3       three generations, then stop (resume later)
  sim optimize my-study.json --shard 0/3 -o /scratch/s   one shard of the pending generation")]
pub struct OptimizeArgs {
    /// The study file (JSON; `sim schema study` gives its schema).
    #[arg(value_name = "STUDY")]
    pub study: PathBuf,
    /// Output directory [default: out/study-<name>].
    #[arg(short = 'o', long = "out", value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Evaluate only this shard (INDEX/COUNT, 0-based) of the pending generation, write it, stop.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<Shard>,
    /// Stop after this many generations (the state resumes the study).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    pub generations: Option<u32>,
    /// Run the study with N seeds (its seed, seed + 1, ...), each in DIR/seed-<s>/, and write
    /// the spread of their optima (DIR/seeds.md, seeds.csv).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=100), conflicts_with_all = ["shard", "generations"])]
    pub seeds: Option<u64>,
    #[command(flatten)]
    pub jobs: Jobs,
    #[command(flatten)]
    pub wall_time: crate::run::WallTime,
}

/// The metrics of one candidate (all runs).
struct Outcome {
    energy_j: Option<f64>,
    hand_error_rms_m: Option<f64>,
    hand_error_max_m: Option<f64>,
    peak_current_a: Option<f64>,
    min_normal_force_n: Option<f64>,
    objective: Option<f64>,
    infeasible: Option<String>,
}

fn max_opt(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(x), Some(y)) => Some(x.max(y)),
        (x, None) | (None, x) => x,
    }
}

/// Run every run of `variant` at `rtol` into `dir`; the recordings are kept only if `keep`.
fn evaluate(study: &Study, variant: &Variant, rtol: Option<f64>, dir: &Path, keep: bool, budget: Budget) -> Outcome {
    let mut o = Outcome { energy_j: Some(0.0), hand_error_rms_m: None, hand_error_max_m: None, peak_current_a: None, min_normal_force_n: None, objective: None, infeasible: None };
    let fail = |mut o: Outcome, why: String| {
        o.infeasible = Some(why);
        o.objective = None;
        o
    };
    let scene = match study.scene(variant, rtol) {
        Ok(s) => s,
        Err(e) => return fail(o, format!("the scene does not validate: {e}")),
    };
    let (s, c) = (&study.spec.objective, &study.spec.constraints);
    for run_name in &study.base.runs {
        let run = scene.run(run_name).expect("runs checked when the study was read");
        let path = dir.join(Sweep::file_name(variant, run_name));
        let (tap, metrics) = MetricsTap::new(&path);
        let result = run_to_file_tapped(&scene, run, &path, budget, Some(tap), |_| {});
        let m = match result {
            Ok((_, tapped)) => metrics.metrics(tapped),
            Err(e) => {
                if !keep {
                    let _ = std::fs::remove_file(&path);
                }
                return fail(o, format!("run `{run_name}` failed: {e}"));
            }
        };
        if !keep {
            let _ = std::fs::remove_file(&path);
        }
        let m = match m {
            Ok(m) => m,
            Err(e) => return fail(o, format!("run `{run_name}`: its metrics: {e}")),
        };
        if let Some(why) = m.contact_law_failure() {
            return fail(o, format!("run `{run_name}`: the contact laws do not hold: {why}"));
        }
        match m.electric_energy_total_j {
            Some(e) => o.energy_j = o.energy_j.map(|x| x + e),
            None => return fail(o, format!("run `{run_name}` has no electric energy")),
        }
        if let Some(h) = &m.hand_error {
            o.hand_error_rms_m = max_opt(o.hand_error_rms_m, Some(h.norm.rms_m));
            o.hand_error_max_m = max_opt(o.hand_error_max_m, Some(h.norm.max_abs_m));
        }
        o.peak_current_a = max_opt(o.peak_current_a, m.peak_current.as_ref().map(|p| p.current_a));
        if let Some(f) = m.contact_forces.iter().map(|c| c.min_normal_force_n).reduce(f64::min) {
            o.min_normal_force_n = Some(o.min_normal_force_n.map_or(f, |x| x.min(f)));
        }
        if c.drive_limits {
            if let Some(l) = m.limits.as_ref().filter(|l| l.exceeded > 0) {
                return fail(o, format!("run `{run_name}` exceeds its drive limits {} time(s)", l.exceeded));
            }
        }
    }
    if let (Some(b), Some(x)) = (c.hand_error_max, o.hand_error_max_m) {
        if x > b {
            return fail(o, format!("hand error {:.3} mm > the bound {:.3} mm", x * 1e3, b * 1e3));
        }
    }
    if let (Some(b), Some(x)) = (c.peak_current, o.peak_current_a) {
        if x > b {
            return fail(o, format!("peak current {x:.3} A > the bound {b:.3} A"));
        }
    }
    if let Some(b) = c.min_normal_force {
        match o.min_normal_force_n {
            Some(x) if x >= b => {}
            Some(x) => return fail(o, format!("a contact's normal force falls to {x:.3} N < {b:.3} N (it must stay closed)")),
            None => return fail(o, "no contact to keep closed".into()),
        }
    }
    let e = o.energy_j.unwrap_or(f64::NAN);
    let obj = e + s.hand_error_rms * o.hand_error_rms_m.unwrap_or(0.0) + s.hand_error_max * o.hand_error_max_m.unwrap_or(0.0) + s.peak_current * o.peak_current_a.unwrap_or(0.0);
    o.objective = obj.is_finite().then_some(obj);
    if o.objective.is_none() {
        o.infeasible = Some("the objective is not finite".into());
    }
    o
}

fn record(index: usize, generation: usize, point: &Point, variant: &Variant, o: Outcome) -> Evaluation {
    Evaluation {
        index,
        generation,
        point: point.clone(),
        values: variant.replacements.clone(),
        energy_j: o.energy_j.filter(|_| o.infeasible.is_none() || o.energy_j.is_some_and(|e| e > 0.0)),
        hand_error_rms_m: o.hand_error_rms_m,
        hand_error_max_m: o.hand_error_max_m,
        peak_current_a: o.peak_current_a,
        min_normal_force_n: o.min_normal_force_n,
        objective: o.objective,
        infeasible: o.infeasible,
    }
}

/// The evaluations' tolerance and error bar (`sim::study::calibration`'s rules), its runs in
/// parallel on `pool`.
fn calibrate(study: &Study, dir: &Path, budget: Budget, pool: &rayon::ThreadPool) -> std::result::Result<Option<Calibration>, String> {
    let mut run = |jobs: &[Job]| -> Vec<JobResult> {
        pool.install(|| {
            jobs.par_iter()
                .map(|j| {
                    let o = evaluate(study, &j.variant, Some(j.rtol), dir, false, budget);
                    o.objective.ok_or_else(|| o.infeasible.unwrap_or_else(|| "infeasible".into()))
                })
                .collect()
        })
    };
    calibration::calibrate(study, &mut run)
}

fn read_json<T: serde::de::DeserializeOwned>(p: &Path) -> Result<T> {
    let text = std::fs::read_to_string(p).with_context(|| format!("cannot read {}", p.display()))?;
    serde_json::from_str(&text).with_context(|| format!("{}: not a state this version of sim wrote", p.display()))
}

fn write_json<T: serde::Serialize>(p: &Path, x: &T) -> Result<()> {
    cli::write_file(p, serde_json::to_string_pretty(x)? + "\n")
}

pub fn run(args: &OptimizeArgs, v: Verbosity) -> Result<u8> {
    let study = Study::load(&args.study)?;
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from(format!("out/study-{}", study.spec.name)));
    let Some(n) = args.seeds.filter(|&n| n > 1) else { return run_study(args, study, out, v) };
    cli::create_dir(&out)?;
    let mut runs = Vec::new();
    for i in 0..n {
        let seed = study.settings.seed.wrapping_add(i);
        let mut s = study.clone();
        s.spec.method.seed = seed;
        s.settings.seed = seed;
        let dir = out.join(format!("seed-{seed}"));
        let code = run_study(args, s, dir.clone(), v)?;
        if code != exit::SUCCESS {
            return Ok(code);
        }
        let state: State = read_json(&dir.join(STATE_FILE))?;
        runs.push((seed, state));
    }
    crate::optimize_seeds::summary(&study, &runs, &out, v)
}

/// One study, in `out`: calibrate (or resume), run the generations, finish.
fn run_study(args: &OptimizeArgs, study: Study, out: PathBuf, v: Verbosity) -> Result<u8> {
    let spec_value = serde_json::to_value(&study.spec)?;
    cli::create_dir(&out)?;
    let evals_dir = out.join("candidates");
    cli::create_dir(&evals_dir)?;
    let budget = args.wall_time.budget();
    let state_path = out.join(STATE_FILE);
    let threads = args.jobs.threads(study.settings.population.max(study.settings.combos));
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
    let mut state: State = if state_path.is_file() {
        let s: State = read_json(&state_path)?;
        if s.spec != spec_value {
            bail!("{} is the state of another study (or of an edited study file) than {}: give another --out, or delete it to start over", state_path.display(), study.file);
        }
        s
    } else {
        let started = Instant::now();
        let calibration = match calibrate(&study, &evals_dir, budget, &pool) {
            Ok(c) => c,
            Err(why) => {
                // a run failed (not the input): status 1, nothing written
                eprintln!("sim: study `{}` ({}): {why}", study.spec.name, study.file);
                return Ok(exit::FAILED);
            }
        };
        if let (Some(c), false) = (&calibration, v.quiet) {
            eprintln!(
                "tolerance: evaluations at rtol {:e}; error bar {:.3e} J ({ERROR_BAR_FACTOR} x the largest loose - tight of {} design(s) at rtol {:e}; {} lost and replaced; {:.1} s)",
                c.loose,
                c.error_j,
                c.designs.iter().filter(|d| d.error().is_some()).count(),
                c.tight,
                c.designs.iter().filter(|d| d.lost.is_some()).count(),
                started.elapsed().as_secs_f64()
            );
        }
        State { study: study.spec.name.clone(), spec: spec_value, calibration, optimizer: Optimizer::with_start(study.settings, study.start.clone()), evaluations: Vec::new() }
    };
    let rtol = state.calibration.as_ref().map(|c| c.loose);
    let bar = cli::progress::count(study.settings.evaluations, &study.spec.name, "evaluations", v.quiet);
    bar.set_position(state.evaluations.len() as u64);
    let started = Instant::now();
    let mut evaluated_here = 0usize;
    let mut generations = 0u32;
    while !state.optimizer.done() && args.generations.is_none_or(|g| generations < g) {
        let mut next = state.optimizer.clone();
        let points = next.ask();
        let g = state.optimizer.generation;
        let first = state.evaluations.len();
        let shard = args.shard.unwrap_or(Shard::ALL);
        // what shards of this generation already evaluated
        let mut done: Vec<Option<Evaluation>> = vec![None; points.len()];
        if args.shard.is_none() {
            for entry in std::fs::read_dir(&out)?.flatten() {
                let name = entry.file_name().to_string_lossy().to_string();
                if name.starts_with(&format!("gen-{g:04}.shard-")) && name.ends_with(".json") {
                    let r: ShardResult = read_json(&entry.path())?;
                    for e in r.evaluations {
                        let k = e.index.wrapping_sub(first);
                        if r.study == study.spec.name && k < points.len() && e.point == points[k] {
                            done[k] = Some(e);
                        }
                    }
                }
            }
        }
        let todo: Vec<usize> = (0..points.len()).filter(|&k| shard.contains(k) && done[k].is_none()).collect();
        bar.inc((points.len() - todo.len()) as u64 * u64::from(args.shard.is_none()));
        let fresh: Vec<(usize, Evaluation)> = pool.install(|| {
            todo.par_iter()
                .map(|&k| {
                    let var = study.variant(first + k, &points[k]);
                    bar.set_message(var.name.clone());
                    let o = evaluate(&study, &var, rtol, &evals_dir, false, budget);
                    bar.inc(1);
                    (k, record(first + k, g, &points[k], &var, o))
                })
                .collect()
        });
        evaluated_here += fresh.len();
        if let Some(shard) = args.shard {
            let r = ShardResult { study: study.spec.name.clone(), generation: g, shard, evaluations: fresh.into_iter().map(|(_, e)| e).collect() };
            let p = out.join(shard_file(g, shard));
            write_json(&p, &r)?;
            bar.finish_and_clear();
            if !v.quiet {
                eprintln!("study `{}` generation {g} shard {shard}: {} evaluation(s) in {:.1} s; wrote {}", study.spec.name, r.evaluations.len(), started.elapsed().as_secs_f64(), p.display());
            }
            return Ok(exit::SUCCESS);
        }
        for (k, e) in fresh {
            done[k] = Some(e);
        }
        let evals: Vec<Evaluation> = done.into_iter().map(|e| e.expect("every candidate evaluated")).collect();
        let f: Vec<f64> = evals.iter().map(Evaluation::told).collect();
        next.tell(&points, &f);
        state.optimizer = next;
        state.evaluations.extend(evals);
        write_json(&state_path, &state)?;
        generations += 1;
    }
    bar.finish_and_clear();
    let wall = started.elapsed().as_secs_f64();
    if !v.quiet && evaluated_here > 0 {
        eprintln!(
            "study `{}`: {evaluated_here} evaluation(s) in {wall:.1} s on {threads} thread(s): {:.1} evaluations per minute",
            study.spec.name,
            evaluated_here as f64 / wall * 60.0
        );
    }
    if !state.optimizer.done() {
        if !v.quiet {
            eprintln!("study `{}`: stopped after {generations} generation(s), {} evaluation(s) so far; run again to go on", study.spec.name, state.evaluations.len());
        }
        return Ok(exit::SUCCESS);
    }
    finish(&study, &state, &out, budget, v)
}

/// The optimum and the baseline re-run at the tight tolerance, and every output.
fn finish(study: &Study, state: &State, out: &Path, budget: Budget, v: Verbosity) -> Result<u8> {
    let best = state.evaluations.iter().filter(|e| e.objective.is_some()).min_by(|a, b| a.told().total_cmp(&b.told()).then(a.index.cmp(&b.index)));
    let tight = state.calibration.as_ref().map(|c| c.tight);
    let base = study.baseline();
    let base_o = evaluate(study, &base, tight, out, true, budget);
    let mut report = String::new();
    let name = &study.spec.name;
    writeln!(report, "# Study `{name}`\n")?;
    if !study.spec.description.is_empty() {
        writeln!(report, "{}\n", study.spec.description)?;
    }
    writeln!(
        report,
        "Scene: {}; runs: {}; {} evaluation(s) in {} generation(s), {} infeasible; method: CMA-ES (λ = {}) over {} continuous variable(s) for each of {} discrete combination(s), then compass search; seed {}.\n",
        study.base.scene_source,
        study.base.runs.join(", "),
        state.evaluations.len(),
        state.optimizer.generation,
        state.evaluations.iter().filter(|e| e.objective.is_none()).count(),
        study.settings.population,
        study.settings.dims,
        study.settings.combos,
        study.settings.seed
    )?;
    let Some(best) = best else {
        writeln!(report, "No feasible design: every candidate failed a constraint.")?;
        write_tables(study, state, out)?;
        cli::write_file(&out.join("report.md"), &report)?;
        print_out(&report)?;
        return Ok(exit::FAILED);
    };
    let var = Variant { index: best.index, name: format!("{name}-optimum"), replacements: best.values.clone() };
    let opt_o = evaluate(study, &var, tight, out, true, budget);
    // the optimum as a scene file `sim run` runs, its URDF beside it
    let var_t = study.with_tolerance(&var, tight);
    let mut doc = study.base.variant_json(&var_t);
    if let Some(Value::String(u)) = doc.get("urdf").cloned() {
        let file = Path::new(&u).file_name().map(|f| f.to_string_lossy().to_string()).unwrap_or(u.clone());
        let text = study.base.read_urdf(&u).map_err(anyhow::Error::msg)?;
        cli::write_file(&out.join(&file), text)?;
        sim::sweep::set_path(&mut doc, "urdf", Value::from(file)).map_err(anyhow::Error::msg)?;
    }
    write_json(&out.join("optimum.json"), &doc)?;
    writeln!(report, "## Optimum\n")?;
    for (c, x) in study.columns().iter().zip(study.cells(&best.point)) {
        writeln!(report, "- `{c}` = {x}")?;
    }
    let loose = best.objective.unwrap_or(f64::NAN);
    writeln!(report, "\n| | objective [J] | energy [J] | hand error RMS [mm] | hand error max [mm] | peak current [A] |")?;
    writeln!(report, "|---|---|---|---|---|---|")?;
    let row = |label: &str, o: &Outcome| {
        let mm = |x: Option<f64>| x.map_or("-".into(), |x| format!("{:.3}", x * 1e3));
        let j = |x: Option<f64>| x.map_or("-".into(), |x| format!("{x:.5}"));
        format!("| {label} | {} | {} | {} | {} | {} |", j(o.objective), j(o.energy_j), mm(o.hand_error_rms_m), mm(o.hand_error_max_m), o.peak_current_a.map_or("-".into(), |x| format!("{x:.3}")))
    };
    writeln!(report, "| optimum (loose, as evaluated) | {loose:.5} | {} | | | |", best.energy_j.map_or("-".into(), |x| format!("{x:.5}")))?;
    writeln!(report, "{}", row("optimum (tight)", &opt_o))?;
    writeln!(report, "{}", row("baseline (tight)", &base_o))?;
    writeln!(report)?;
    match (&state.calibration, opt_o.objective) {
        (Some(c), Some(t)) => {
            let err = (loose - t).abs();
            let counted: Vec<&CalibrationDesign> = c.designs.iter().filter(|d| d.error().is_some()).collect();
            let lost = c.designs.iter().filter(|d| d.lost.is_some()).count();
            writeln!(
                report,
                "Error bar: ±{:.2e} J, stated before the search: {ERROR_BAR_FACTOR} × the largest |loose − tight| of the objective over {} design(s) (the baseline, the centre and the ends of every continuous variable in every discrete combination, and the replacements of the lost ones). {lost} design(s) infeasible at a tolerance (lost), each replaced by the midpoint towards the nearest feasible design of its combination (at most {} times; a design still lost fails the calibration). The optimum's objective at rtol {:e} (evaluations) and {:e} (re-run) differ by {err:.2e} J ({:.3} %). Tolerance rule: the loosest rtol (from {:e}, in steps of 10) at which {}'s objective is within 0.1 % of its tight value: {}.",
                c.error_j,
                counted.len(),
                calibration::MAX_REPLACEMENTS,
                c.loose,
                c.tight,
                100.0 * err / t.abs(),
                study.spec.tolerance.as_ref().map_or(f64::NAN, |t| t.loose),
                if c.reference.is_empty() { "the baseline".to_string() } else { format!("the design {} (the baseline is infeasible)", c.reference) },
                c.ladder.iter().map(|(r, j)| format!("rtol {r:e}: {j:.6} J")).collect::<Vec<_>>().join("; ")
            )?;
            if !c.designs.is_empty() {
                writeln!(report, "\n| # | calibration design | objective, loose [J] | objective, tight [J] | loose − tight [J] | lost: why |\n|---|---|---|---|---|---|")?;
                let j = |x: Option<f64>| x.map_or("infeasible".into(), |x| format!("{x:.6}"));
                for (k, d) in c.designs.iter().enumerate() {
                    let design = d.replaces.map_or(d.design.clone(), |r| format!("{} (replaces #{r})", d.design));
                    let why = d.lost.as_deref().unwrap_or("").replace('|', "\\|").replace('\n', " ");
                    writeln!(report, "| {k} | {design} | {} | {} | {} | {why} |", j(d.loose), j(d.tight), d.error().map_or("-".into(), |e| format!("{e:.2e}")))?;
                }
            }
            // the stated error bar holds for the optimum?
            writeln!(
                report,
                "\nThe optimum's value as evaluated {} its tight re-run within the stated error bar ({err:.2e} J {} {:.2e} J).",
                if err <= c.error_j { "matches" } else { "does NOT match" },
                if err <= c.error_j { "<=" } else { ">" },
                c.error_j
            )?;
            // is the optimum resolved? the runner-up design against the error bar
            let second = state.evaluations.iter().filter(|e| e.objective.is_some() && e.values != best.values).map(Evaluation::told).min_by(f64::total_cmp);
            if let Some(s) = second {
                let gap = s - loose;
                writeln!(report, "\nThe best other design is {gap:.2e} J worse: {} the stated error bar.", if gap > c.error_j { "larger than" } else { "within" })?;
            }
        }
        (_, None) => writeln!(report, "The optimum's re-run at the tight tolerance is infeasible: {}.", opt_o.infeasible.clone().unwrap_or_default())?,
        (None, _) => writeln!(report, "No `tolerance` in the study: the optimum ran at the scene's tolerance only (no error bar).")?,
    }
    if let (Some(b), Some(o)) = (base_o.objective, opt_o.objective) {
        writeln!(report, "\nAgainst the baseline (the scene as is): {:+.5} J ({:+.2} %).", o - b, 100.0 * (o - b) / b)?;
    }
    if study.settings.combos > 1 {
        per_combination(study, state, &mut report)?;
    }
    writeln!(report, "\nRecordings: {} and {}.", study.base.runs.iter().map(|r| format!("{name}-optimum-{r}.mcap")).collect::<Vec<_>>().join(", "), study.base.runs.iter().map(|r| format!("{name}-baseline-{r}.mcap")).collect::<Vec<_>>().join(", "))?;
    write_tables(study, state, out)?;
    figures(study, state, out)?;
    writeln!(report, "\nFiles: optimum.json, best.csv, evaluations.csv, pareto.csv, convergence.svg, map.svg, pareto.svg.")?;
    cli::write_file(&out.join("report.md"), &report)?;
    if !v.quiet {
        print_out(&report)?;
    }
    Ok(exit::SUCCESS)
}

fn csv_rows(study: &Study, evals: &[&Evaluation]) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut head = vec!["index".to_string(), "generation".into()];
    head.extend(study.columns());
    head.extend(["objective_j", "E_total_j", "err_norm_rms_m", "err_norm_max_m", "peak_current_a", "fn_min_n", "infeasible"].map(String::from));
    w.write_record(&head)?;
    let num = |x: Option<f64>| x.map_or(String::new(), |x| format!("{x:e}"));
    for e in evals {
        let mut c = vec![e.index.to_string(), e.generation.to_string()];
        c.extend(study.cells(&e.point));
        c.extend([num(e.objective), num(e.energy_j), num(e.hand_error_rms_m), num(e.hand_error_max_m), num(e.peak_current_a), num(e.min_normal_force_n), e.infeasible.clone().unwrap_or_default()]);
        w.write_record(&c)?;
    }
    Ok(String::from_utf8(w.into_inner()?)?)
}

fn write_tables(study: &Study, state: &State, out: &Path) -> Result<()> {
    let all: Vec<&Evaluation> = state.evaluations.iter().collect();
    cli::write_file(&out.join("evaluations.csv"), csv_rows(study, &all)?)?;
    let mut feasible: Vec<&Evaluation> = state.evaluations.iter().filter(|e| e.objective.is_some()).collect();
    feasible.sort_by(|a, b| a.told().total_cmp(&b.told()).then(a.index.cmp(&b.index)));
    feasible.dedup_by(|a, b| a.values == b.values);
    cli::write_file(&out.join("best.csv"), csv_rows(study, &feasible[..feasible.len().min(10)])?)?;
    let pts: Vec<(f64, f64)> = state.evaluations.iter().filter(|e| e.objective.is_some()).filter_map(|e| Some((e.energy_j?, e.hand_error_rms_m?))).collect();
    let front = analyze::figures::pareto_front(&pts);
    let on_front: Vec<&Evaluation> = front
        .iter()
        .filter_map(|p| state.evaluations.iter().find(|e| e.objective.is_some() && e.energy_j == Some(p.0) && e.hand_error_rms_m == Some(p.1)))
        .collect();
    cli::write_file(&out.join("pareto.csv"), csv_rows(study, &on_front)?)?;
    Ok(())
}

fn figures(study: &Study, state: &State, out: &Path) -> Result<()> {
    use analyze::figures::{pareto_front, study_figure, Mark, StudySeries};
    let name = &study.spec.name;
    let ev = &state.evaluations;
    let feasible = |e: &&Evaluation| e.objective.is_some();
    // convergence: every feasible objective, and the best so far
    let mut best = f64::INFINITY;
    let mut so_far = Vec::new();
    for e in ev {
        if e.told() < best {
            best = e.told();
        }
        if best.is_finite() {
            so_far.push(((e.index + 1) as f64, best));
        }
    }
    let each: Vec<(f64, f64)> = ev.iter().filter(feasible).map(|e| ((e.index + 1) as f64, e.told())).collect();
    let s = [StudySeries { name: "each evaluation".into(), points: each, mark: Mark::Dots }, StudySeries { name: "best so far".into(), points: so_far, mark: Mark::Line }];
    study_figure(&s, [&format!("{name}: convergence"), "evaluations", "objective [J]"], &out.join("convergence")).map_err(anyhow::Error::msg)?;
    // the map over the first continuous variable (the discrete combinations as series),
    // infeasible designs as crosses at the top
    if let Some(dim) = study.continuous.first() {
        let field = dim.name.as_str();
        let x_of = |e: &Evaluation| e.point.u.first().map_or(f64::NAN, |&u| dim.at(u));
        let top = ev.iter().filter(feasible).map(Evaluation::told).fold(f64::NEG_INFINITY, f64::max);
        let mut s: Vec<StudySeries> = (0..study.settings.combos)
            .map(|k| StudySeries {
                name: if study.settings.combos == 1 { "feasible".into() } else { format!("combination {k}: {}", study.combo_label(k)) },
                points: ev.iter().filter(|e| e.objective.is_some() && e.point.combo == k).map(|e| (x_of(e), e.told())).collect(),
                mark: Mark::Dots,
            })
            .collect();
        if top.is_finite() {
            s.push(StudySeries { name: "infeasible".into(), points: ev.iter().filter(|e| e.objective.is_none()).map(|e| (x_of(e), top)).collect(), mark: Mark::Crosses });
        }
        study_figure(&s, [&format!("{name}: objective over {field}"), field, "objective [J]"], &out.join("map")).map_err(anyhow::Error::msg)?;
    }
    let pts: Vec<(f64, f64)> = ev.iter().filter(feasible).filter_map(|e| Some((e.hand_error_rms_m? * 1e3, e.energy_j?))).collect();
    if !pts.is_empty() {
        let front = pareto_front(&pts);
        let s = [StudySeries { name: "feasible designs".into(), points: pts, mark: Mark::Dots }, StudySeries { name: "Pareto front".into(), points: front, mark: Mark::Line }];
        study_figure(&s, [&format!("{name}: energy against hand error"), "hand error RMS [mm]", "electric energy [J]"], &out.join("pareto")).map_err(anyhow::Error::msg)?;
    }
    Ok(())
}

/// The best design of every discrete combination (at the evaluations' tolerance): what the
/// study says for each choice, e.g. each load in the hand.
fn per_combination(study: &Study, state: &State, report: &mut String) -> Result<()> {
    let cols = study.columns();
    writeln!(report, "\n## Best design per combination (evaluations' tolerance)\n")?;
    writeln!(report, "| combination | {} | objective [J] | evaluations | infeasible |", cols.join(" | "))?;
    writeln!(report, "|---|{}---|---|---|", "---|".repeat(cols.len()))?;
    for k in 0..study.settings.combos {
        let of_k: Vec<&Evaluation> = state.evaluations.iter().filter(|e| e.point.combo == k).collect();
        let bad = of_k.iter().filter(|e| e.objective.is_none()).count();
        let best = of_k.iter().filter(|e| e.objective.is_some()).min_by(|a, b| a.told().total_cmp(&b.told()).then(a.index.cmp(&b.index)));
        let (cells, j) = match best {
            Some(e) => (study.cells(&e.point), format!("{:.4}", e.told())),
            None => (vec!["-".to_string(); cols.len()], "none feasible".to_string()),
        };
        writeln!(report, "| {k}: {} | {} | {j} | {} | {bad} |", study.combo_label(k), cells.join(" | "), of_k.len())?;
    }
    Ok(())
}
