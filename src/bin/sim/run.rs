//! `sim run` (and `sim` with no command): run the selected runs of a scene in parallel, each to
//! its recording, and print the comparison of the runs: by default the brief one (the headline
//! findings and one table, a row per run, fitted to the terminal and never wider than
//! [`cli::TEXT_WIDTH`] columns), with `-v` every table and finding, as `analyze compare` prints
//! them (fitted to the terminal when standard output is one); `-f json|csv` always complete.
//!
//! The comparison is made by the `analyze` library from what each run wrote, without reading
//! the files back: the writer feeds every record it writes to the reader's own record consumer
//! ([`schemas::Tap`]), which hands the metric topics to `analyze`'s running reductions
//! ([`analyze::metrics::Reductions`]) exactly as `analyze compare` on the files does (the same
//! decoders, checks and reductions; tests/e2e/sim_table.rs checks the two tables equal). The
//! `sim` library never depends on `analyze`; this binary composes the two.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use cli::{exit, print_out, Jobs, TableFormat, Verbosity};
use rayon::prelude::*;
use sim::run::{run_to_file_mirrored, Budget};

use crate::live::{self, LiveArgs};
use sim::scene::{Run, Scene};

/// The options of a run, with `sim` alone or `sim run`.
#[derive(Debug, Clone, clap::Args)]
pub struct RunArgs {
    /// Run only these runs of the scene (repeatable) [default: all].
    #[arg(long = "run", value_name = "NAME")]
    pub runs: Vec<String>,
    /// Directory for the recordings, named <scene>-<run>.mcap.
    #[arg(short = 'o', long = "out", value_name = "DIR", default_value = "out")]
    pub out: PathBuf,
    #[command(flatten)]
    pub jobs: Jobs,
    #[command(flatten)]
    pub format: TableFormat,
    /// Baseline run for the ratios in the table [default: a run without contacts].
    #[arg(long, value_name = "RUN")]
    pub baseline: Option<String>,
    /// Simulated time of every run, s [default: the scene's]. Changes the scene before it is
    /// validated, so the recording stores the scene that ran.
    #[arg(long, value_name = "SECONDS", value_parser = positive_seconds)]
    pub duration: Option<f64>,
    #[command(flatten)]
    pub wall_time: WallTime,
    #[command(flatten)]
    pub live: LiveArgs,
}

/// `--max-wall-time`: the wall-clock budget of each run (`sim run`, `sweep`, `replay`).
#[derive(Debug, Clone, Copy, Default, clap::Args)]
pub struct WallTime {
    /// Stop any run still going after this much wall-clock time, s [default: 600]: it fails
    /// (exit 1), and its recording says at which simulated time.
    #[arg(long = "max-wall-time", value_name = "SECONDS", value_parser = positive_seconds)]
    pub max_wall_time: Option<f64>,
}

impl WallTime {
    /// The budget of each run.
    pub fn budget(&self) -> Budget {
        match self.max_wall_time {
            Some(s) => Budget::wall_time(Duration::try_from_secs_f64(s).unwrap_or(Duration::MAX)),
            None => Budget::default(),
        }
    }
}

/// Run a scene (the default command): every run to <out>/<scene>-<run>.mcap, then the table.
#[derive(Debug, Clone, clap::Args)]
#[command(after_help = "\
Output: out/<scene>-<run>.mcap per run; on stdout the comparison of the runs: the findings that
matter, then one table (a row per run: electric energy E and E / E_base, hand error RMS and max,
what each contact did), at most 100 columns wide. -v: every table (hand error per axis, energy
totals, per-link energy, contacts, contact states, energy balance) and every finding, as
`analyze compare` prints them; in a terminal every table fits its width. -f json|csv: every
number, for machines. A progress bar per run on stderr.

Examples:
  sim run                                    the built-in paper scene (same as `sim`)
  sim run my_scene.json --max-wall-time 60   fail any run still going after a minute
  sim run sim/scenes/small/small.json -o /tmp/small
  sim run --run two-elbow --duration 1 -f csv
  sim run --run two-elbow --live --wait      stream it to Foxglove (feature live) once a viewer is
                                             connected to ws://localhost:8765
  sim run --live --pace fast --live-port 0   as fast as it computes, on any free port")]
pub struct RunCommand {
    /// Scene JSON file, or the name of a built-in scene (`sim list`) [default: the built-in paper
    /// scene].
    #[arg(value_name = "SCENE")]
    pub scene: Option<PathBuf>,
    #[command(flatten)]
    pub run: RunArgs,
}

/// A duration given on the command line: a positive number of seconds.
pub fn positive_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x > 0.0 && x.is_finite() => Ok(x),
        _ => Err(format!("{s:?} is not a positive number of seconds")),
    }
}

/// `sim [run]`.
pub fn run(scene: Option<&Path>, a: &RunArgs, v: Verbosity) -> Result<u8> {
    let scene = crate::load_scene(scene)?;
    let scene = match a.duration {
        Some(d) => scene.vary(|s| s.duration = d)?,
        None => scene,
    };
    let runs = select_runs(&scene, &a.runs)?;
    cli::create_dir(&a.out)?;
    let names = runs.iter().map(|r| r.name.clone()).collect();
    let live = live::Session::start(&a.live, &live::about(&[(&scene, names)], &a.out), v.quiet)?;
    warn_method_limits(&scene, &runs, v);
    let budget = a.live.budget(a.wall_time.budget(), scene.duration());
    let done = run_all_live(&scene, &runs, |run| a.out.join(format!("{}-{}.mcap", scene.spec().name, run.name)), &a.jobs, budget, v, live.as_ref());
    let layouts = write_layouts(&scene, &done, v);
    let failed = layouts.iter().any(Result::is_err);
    let code = finish(&done, a.format, a.baseline.as_deref(), v).map(|c| if failed { c.max(exit::BAD_INPUT) } else { c });
    report_layouts(&layouts, v);
    // messages the live view dropped (said on stderr) make the command's status 1
    let dropped = live.is_some_and(live::Session::close);
    code.map(|c| if dropped { c.max(exit::FAILED) } else { c })
}

/// `sim` with no scene: the paper's scene and the same arm over a real table
/// (`paper-unilateral`), one comparison table of all their runs. `--run NAME` picks runs from
/// either scene (their run names differ).
pub fn run_default(a: &RunArgs, v: Verbosity) -> Result<u8> {
    let mut scenes = Vec::new();
    for name in ["paper", "paper-unilateral"] {
        let b = sim::scene::builtin::find(name).with_context(|| format!("the built-in scene `{name}` is missing"))?;
        let scene = b.load()?;
        scenes.push(match a.duration {
            Some(d) => scene.vary(|s| s.duration = d)?,
            None => scene,
        });
    }
    let mut picked = Vec::new();
    for scene in &scenes {
        let names: Vec<String> = a.runs.iter().filter(|n| scene.run(n).is_some()).cloned().collect();
        if a.runs.is_empty() || !names.is_empty() {
            picked.push(select_runs(scene, &names)?);
        } else {
            picked.push(Vec::new());
        }
    }
    if let Some(n) = a.runs.iter().find(|n| scenes.iter().all(|s| s.run(n).is_none())) {
        let all: Vec<&str> = scenes.iter().flat_map(|s| s.runs().iter().map(|r| r.name.as_str())).collect();
        anyhow::bail!("no run `{n}` in the built-in scenes paper and paper-unilateral (runs: {})", all.join(", "));
    }
    cli::create_dir(&a.out)?;
    let about: Vec<_> = scenes.iter().zip(&picked).map(|(s, r)| (s, r.iter().map(|r| r.name.clone()).collect())).collect();
    let live = live::Session::start(&a.live, &live::about(&about, &a.out), v.quiet)?;
    let mut done = Vec::new();
    let mut layouts = Vec::new();
    for (scene, runs) in scenes.iter().zip(&picked).filter(|(_, r)| !r.is_empty()) {
        warn_method_limits(scene, runs, v);
        let budget = a.live.budget(a.wall_time.budget(), scene.duration());
        let scene_done = run_all_live(scene, runs, |run| a.out.join(format!("{}-{}.mcap", scene.spec().name, run.name)), &a.jobs, budget, v, live.as_ref());
        layouts.extend(write_layouts(scene, &scene_done, v));
        done.extend(scene_done);
    }
    let failed = layouts.iter().any(Result::is_err);
    let code = finish(&done, a.format, a.baseline.as_deref(), v).map(|c| if failed { c.max(exit::BAD_INPUT) } else { c });
    report_layouts(&layouts, v);
    let dropped = live.is_some_and(live::Session::close);
    code.map(|c| if dropped { c.max(exit::FAILED) } else { c })
}

/// Before the runs start: a run whose method cannot integrate its frictional rigid contacts
/// (`Integrator::frictional_limit`) says so on stderr, with the reason (issue 23 item 3).
fn warn_method_limits(scene: &Scene, runs: &[sim::scene::Run], v: Verbosity) {
    use sim::dynamics::contact::ContactModel;
    for run in runs {
        let friction = scene.run_contact_models(run).into_iter().filter_map(|c| match c.model {
            ContactModel::Unilateral { friction, .. } => Some(friction),
            _ => None,
        });
        if let (Some(why), false) = (scene.integrator().frictional_limit(friction), v.quiet) {
            eprintln!("sim: warning: run `{}`: {why}", run.name);
        }
    }
}

/// Write the Foxglove layout of each recording of `scene` beside it,
/// `<scene>-<run>.foxglove-layout.json` (`schemas::layout`): one per run, with only the series
/// that run records (its own contacts, not every contact of the scene: issue 27), so a user
/// imports the layout of the recording they open. Written atomically (`schemas::atomic`) after
/// the runs, and only for a run that wrote a recording (a run that wrote nothing leaves nothing
/// behind). Another `sim` writing the same layout at the same moment (the same run into one
/// directory) writes the same bytes: it is left to that one (`Ok(None)`). Any other failure is
/// the error's text (reported, exit status 2).
pub fn write_layouts(scene: &Scene, done: &[Done], v: Verbosity) -> Vec<Result<Option<PathBuf>, String>> {
    let input = sim::record::layout_input(scene);
    let mut out = Vec::new();
    for (d, recording) in done.iter().filter_map(|d| Some((d, d.path.as_ref()?))) {
        let stem = recording.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let mut one = input.clone();
        one.runs.retain(|r| format!("{}-{}", scene.spec().name, r.run) == stem);
        for r in one.runs.iter_mut().filter(|r| r.has_contact_topic) {
            r.has_contact_events = has_contact_events(d, recording);
        }
        out.push(write_layout(&one, &recording.with_file_name(schemas::layout::file_name(&stem)), v));
    }
    out
}

/// Whether the run `d` wrote a `/contact_events` message: from its metrics (a complete run),
/// else from the channels of its recording at `path` (read without decoding a message).
fn has_contact_events(d: &Done, path: &Path) -> bool {
    match &d.metrics {
        Some(Ok(m)) => m.contact_states.iter().any(|c| {
            let e = &c.events;
            e.lift_offs + e.touch_downs + e.impacts + e.rests + e.stick_to_slip + e.slip_to_stick > 0
        }),
        _ => schemas::read_recording_topics(path, Some(&[])).is_ok_and(|r| r.channel(schemas::topics::CONTACT_EVENTS).is_some()),
    }
}

/// Write the layout of `input` to `path` ([`write_layouts`]).
fn write_layout(input: &schemas::layout::LayoutInput, path: &Path, v: Verbosity) -> Result<Option<PathBuf>, String> {
    let layout = schemas::layout::foxglove(input);
    let text = serde_json::to_string_pretty(&layout).map_err(|e| format!("the Foxglove layout as JSON: {e}"))?;
    match schemas::atomic::write_file(path, text + "\n") {
        Ok(p) => Ok(Some(p)),
        Err(schemas::Error::Busy { .. }) => {
            if !v.quiet {
                eprintln!("note: another sim is writing {} (the same layout): left to it", path.display());
            }
            Ok(None)
        }
        Err(e) => Err(format!("cannot write the Foxglove layout {}: {e}", path.display())),
    }
}

/// Say where the layouts are, or why one is missing (after the runs' own lines; errors always).
fn report_layouts(layouts: &[Result<Option<PathBuf>, String>], v: Verbosity) {
    for l in layouts {
        match l {
            Ok(Some(p)) if !v.quiet => eprintln!("wrote {} (Foxglove: Layouts -> Import from file, then open a recording)", p.display()),
            Err(e) => eprintln!("sim: error: {e}"),
            _ => {}
        }
    }
}

/// The runs called `names` (all when empty), in that order.
pub fn select_runs(scene: &Scene, names: &[String]) -> Result<Vec<Run>> {
    if names.is_empty() {
        return Ok(scene.runs().to_vec());
    }
    names
        .iter()
        .map(|n| {
            scene.run(n).cloned().with_context(|| {
                let all: Vec<&str> = scene.runs().iter().map(|r| r.name.as_str()).collect();
                format!("no run `{n}` in scene `{}` (runs: {})", scene.spec().name, all.join(", "))
            })
        })
        .collect()
}

/// What became of one run.
pub struct Done {
    /// The recording, when it was written (complete, or failed numerically: it says why).
    pub path: Option<PathBuf>,
    /// The failure, if any.
    pub error: Option<String>,
    /// The failure is an I/O error (the recording could not be written), not a numerical one.
    pub io_error: bool,
    /// The metrics of a complete run, from what it wrote ([`MetricsTap`]).
    pub metrics: Option<Result<analyze::RunMetrics, analyze::Error>>,
}

/// `analyze`'s running reductions fed by the writer of a recording ([`schemas::Tap`]) with the
/// messages of the metric topics as it writes them: the metrics of a run without reading its
/// file back, by the code `analyze` runs on the file.
#[derive(Clone, Default)]
pub struct MetricsTap(Arc<Mutex<analyze::metrics::Reductions>>);

impl schemas::Visitor for MetricsTap {
    fn message(&mut self, m: schemas::DecodedMessage<'_>) -> Result<(), schemas::Error> {
        self.0.lock().unwrap_or_else(PoisonError::into_inner).message(m)
    }

    /// As `analyze` reads a file: the metric messages typed, by reference (no generic tree,
    /// no allocation per message).
    fn typed(&self) -> bool {
        true
    }

    fn by_ref(&self) -> bool {
        true
    }

    fn message_ref(&mut self, m: &schemas::DecodedMessage<'_>) -> Result<(), schemas::Error> {
        self.0.lock().unwrap_or_else(PoisonError::into_inner).message_ref(m)
    }

    fn metadata(&mut self, name: &str, entries: &std::collections::BTreeMap<String, String>) {
        self.0.lock().unwrap_or_else(PoisonError::into_inner).metadata(name, entries)
    }
}

impl MetricsTap {
    /// The tap for the recording at `path` (labelled as a reader labels it), and the handle
    /// that [`MetricsTap::metrics`] reads.
    pub fn new(path: &Path) -> (schemas::Tap, MetricsTap) {
        let acc = MetricsTap::default();
        let tap = schemas::Tap::new(path.display().to_string(), Some(&analyze::metrics::METRIC_TOPICS), Box::new(acc.clone()));
        (tap, acc)
    }

    /// The metrics, once the writer finished and gave back `tapped` (what
    /// [`analyze::metrics::stream_run_metrics`] computes from the file).
    #[allow(clippy::result_large_err)] // analyze::Error, as analyze::read_run_metrics returns it
    pub fn metrics(self, tapped: Option<schemas::Tapped>) -> Result<analyze::RunMetrics, analyze::Error> {
        let Some(tapped) = tapped else {
            return Err(schemas::Error::Stopped { file: "(no tap)".into() }.into());
        };
        drop(tapped.visitor); // the other handle of the reductions
        let acc = match Arc::try_unwrap(self.0) {
            Ok(m) => m.into_inner().unwrap_or_else(PoisonError::into_inner),
            Err(shared) => std::mem::take(&mut *shared.lock().unwrap_or_else(PoisonError::into_inner)),
        };
        let mut acc = acc;
        let rec = tapped.recording.map_err(|e| acc.take_error(e))?;
        acc.finish(&rec, None)
    }
}

/// Runs `runs` of `scene` on `jobs` threads, run `r` to `path(r)`, with a progress bar each.
pub fn run_all(scene: &Scene, runs: &[Run], path: impl Fn(&Run) -> PathBuf + Sync, jobs: &Jobs, budget: Budget, v: Verbosity) -> Vec<Done> {
    run_all_live(scene, runs, path, jobs, budget, v, None)
}

/// [`run_all`], and with a `live` session (`--live`) one run at a time, in order, each streamed
/// as it is written.
pub fn run_all_live(
    scene: &Scene,
    runs: &[Run],
    path: impl Fn(&Run) -> PathBuf + Sync,
    jobs: &Jobs,
    budget: Budget,
    v: Verbosity,
    live: Option<&live::Session>,
) -> Vec<Done> {
    let bars = cli::progress::RunBars::new(v.quiet);
    let bars: Vec<_> = runs.iter().map(|r| bars.add(&r.name, scene.duration())).collect();
    let threads = if live.is_some() { 1 } else { jobs.threads(runs.len()) };
    let started = Instant::now();
    let one = |(run, bar): (&Run, &indicatif::ProgressBar)| -> Done {
        let target = path(run);
        let t0 = Instant::now();
        let mut count = 0u32;
        let (tap, metrics) = MetricsTap::new(&target);
        let mirror = live.map(|l| {
            l.before_run(&format!("{}-{}", scene.spec().name, run.name));
            l.mirror()
        });
        let res = run_to_file_mirrored(scene, run, &target, budget, Some(tap), mirror, |t| {
            count += 1;
            if count.is_multiple_of(64) {
                cli::progress::set_time(bar, t);
            }
        });
        let wall = t0.elapsed().as_secs_f64();
        match res {
            Ok((r, tapped)) => {
                bar.finish_with_message(format!("{:.3} s", scene.duration()));
                if v.verbose > 0 {
                    let s = r.report.stats;
                    // (suspend the bars: `println` on a bar is dropped when stderr is no terminal)
                    bar.suspend(|| {
                        eprintln!(
                            "sim: {}: {} steps ({} rejected), {} right-hand sides, {:.2} s wall, {:.0}x real time",
                            run.name, s.steps, s.rejected, s.rhs_evals, wall, scene.duration() / wall.max(1e-9)
                        )
                    });
                }
                let metrics = metrics.metrics(tapped);
                // a run whose contacts broke their laws is not a result (exit 1), though it ran
                // to the end: its recording says where (record `contact_audit`)
                let error = match &metrics {
                    Ok(m) => m.contact_law_failure().map(|why| format!("run `{}`: the contact laws do not hold: {why}", run.name)),
                    Err(_) => None,
                };
                Done { path: Some(r.path), error, io_error: false, metrics: Some(metrics) }
            }
            Err(e) => {
                bar.abandon_with_message(format!("failed at {}", e.time().map_or("?".into(), |t| format!("{t:.3} s"))));
                // a numerical failure still leaves a recording that says when and why
                let written = e.time().is_some() && target.is_file();
                Done { path: written.then_some(target), error: Some(format!("run `{}`: {e}", run.name)), io_error: e.is_io(), metrics: None }
            }
        }
    };
    let work = || -> Vec<Done> {
        if live.is_some() {
            runs.iter().zip(&bars).map(&one).collect()
        } else {
            runs.par_iter().zip(&bars).map(&one).collect()
        }
    };
    let done = match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
        Ok(pool) => pool.install(work),
        Err(_) => work(),
    };
    if !v.quiet {
        for d in done.iter().filter(|d| d.error.is_none()) {
            if let Some(p) = &d.path {
                eprintln!("wrote {}", p.display());
            }
        }
        eprintln!("{} run(s) in {:.2} s wall time on {threads} thread(s)", runs.len(), started.elapsed().as_secs_f64());
    }
    done
}

/// Prints the comparison of the runs (brief, or with `-v` in full; a failed run with its
/// status and reason, a run without a recording named under the table) and the failures;
/// the exit status: 2 if a recording could not be written (an I/O error: its run's result is
/// lost), else 1 if a run failed numerically (its recording says when and why), else 0.
pub fn finish(done: &[Done], format: TableFormat, baseline: Option<&str>, v: Verbosity) -> Result<u8> {
    // every run with a recording is in the table, a failed one with its status and reason
    // (read back from its recording); a run without a recording is named under the table
    let recorded: Vec<&Done> = done.iter().filter(|d| d.path.is_some() && !d.io_error).collect();
    let unrecorded: Vec<&str> = done.iter().filter(|d| d.path.is_none() || d.io_error).filter_map(|d| d.error.as_deref()).collect();
    if !recorded.is_empty() {
        print_comparison(&recorded, format.format, baseline, v.verbose > 0, &unrecorded)?;
    }
    let failures: Vec<&str> = done.iter().filter_map(|d| d.error.as_deref()).collect();
    for f in &failures {
        eprintln!("sim: error: {f}");
    }
    Ok(if done.iter().any(|d| d.io_error) {
        exit::BAD_INPUT
    } else if failures.is_empty() {
        exit::SUCCESS
    } else {
        exit::FAILED
    })
}

/// Prints the comparison of the runs, from the metrics computed as they were written (a run
/// without them, which no caller makes, is read back): as text the brief one, or (`full`) every
/// section; JSON and CSV always whole.
fn print_comparison(done: &[&Done], format: analyze::Format, baseline: Option<&str>, full: bool, unrecorded: &[&str]) -> Result<()> {
    let metrics = done
        .iter()
        .filter_map(|d| d.path.as_deref().map(|p| (p, d.metrics.as_ref())))
        .map(|(p, m)| match m {
            Some(Ok(m)) => Ok(m.clone()),
            Some(Err(e)) => Err(anyhow::anyhow!("{e}")).with_context(|| format!("the metrics of {}", p.display())),
            None => analyze::read_run_metrics(p).with_context(|| format!("reading back {}", p.display())),
        })
        .collect::<Result<Vec<_>>>()?;
    let cmp = analyze::Comparison::new(&metrics, baseline)?;
    let width = cli::terminal_width();
    // the runs that left no recording: a line each under the table (JSON and CSV: on stderr
    // only, with the errors)
    let left_out = |width: usize| -> String {
        unrecorded.iter().map(|e| analyze::render::wrap(&format!("Not in the table (no recording): {e}"), width, "", "  ")).collect()
    };
    if format == analyze::Format::Table && !full {
        let width = width.map_or(cli::TEXT_WIDTH, |w| w.min(cli::TEXT_WIDTH));
        let more = analyze::render::wrap(BRIEF_MORE, width, "", "");
        return print_out(&(analyze::render_comparison_brief(&cmp, width) + &left_out(width) + "\n" + &more));
    }
    let mut text = analyze::render_comparison_fitted(&cmp, format, width)?;
    if format == analyze::Format::Table {
        text += &left_out(width.unwrap_or(cli::TEXT_WIDTH));
    }
    print_out(&text)
}

/// The last line of the brief comparison: where the rest is.
const BRIEF_MORE: &str = "-v: every table (hand error per axis, per link, per contact, energy balance) and every finding.";
