//! `sim precision`: speed against error of every integrator on one run of a scene
//! (`sim::precision` measures; this command prints, writes the tables and draws the diagram).

use std::fmt::Write as _;
use std::path::PathBuf;

use analyze::figures::{work_precision, WorkPrecisionSeries};
use analyze::Format;
use anyhow::{Context, Result};
use cli::{exit, print_out, TableFormat, Verbosity};
use sim::precision::Row;

/// Speed against error: every method over a ladder of tolerances or steps, and each model
/// reduction, against a tight reference run; writes a table and a work–precision diagram.
#[derive(Debug, Clone, clap::Args)]
#[command(after_help = "\
Output: DIR/precision.csv, precision.json and the diagram work-precision.svg/.png (max hand
error against wall time, log-log); on stdout the table (-f json|csv: every row) and the cheapest
setting per method within --accuracy (default 1e-6 m) and the recommended setting. A run that
finished but left the physics (hand error above the arm's reach, energy error above the electric
energy, NaN) has the status \"diverged\".

Examples:
  sim precision                                   the paper's two-elbow run, 5 s
  sim precision --duration 1 --repeats 1          quicker
  sim precision sim/scenes/hard/mechanical.json --run free -o out/precision-mechanical")]
pub struct PrecisionArgs {
    /// Scene JSON file, or the name of a built-in scene (`sim list`) [default: the built-in paper
    /// scene].
    #[arg(value_name = "SCENE")]
    pub scene: Option<PathBuf>,
    /// The run of the scene to measure [default: its first run].
    #[arg(long = "run", value_name = "NAME")]
    pub run: Option<String>,
    /// Simulated time of every run, s [default: the scene's].
    #[arg(long, value_name = "SECONDS", value_parser = crate::run::positive_seconds)]
    pub duration: Option<f64>,
    /// Directory for precision.csv, precision.json, work-precision.svg and .png.
    #[arg(short = 'o', long = "out", value_name = "DIR", default_value = "out/precision")]
    pub out: PathBuf,
    /// Timed repetitions of each run; the best is kept.
    #[arg(long, value_name = "N", default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..))]
    pub repeats: u32,
    /// A requested max hand error, m: print the recommended setting (the cheapest measured
    /// method and tolerance within it, by wall time and by right-hand sides) and the cheapest
    /// run per method within it.
    #[arg(long, value_name = "METRES", default_value_t = 1e-6, value_parser = positive_metres)]
    pub accuracy: f64,
    #[command(flatten)]
    pub format: TableFormat,
}

/// A positive, finite length in metres.
fn positive_metres(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x > 0.0 && x.is_finite() => Ok(x),
        _ => Err(format!("{s:?} is not a positive number of metres")),
    }
}

pub fn run(a: &PrecisionArgs, v: Verbosity) -> Result<u8> {
    let scene = crate::load_scene(a.scene.as_deref())?;
    let scene = match a.duration {
        Some(d) => scene.vary(|s| s.duration = d)?,
        None => scene,
    };
    let run = match &a.run {
        Some(n) => crate::run::select_runs(&scene, std::slice::from_ref(n))?.remove(0),
        None => scene.runs()[0].clone(),
    };
    cli::create_dir(&a.out)?;
    let ladder = sim::precision::default_ladder(&scene)?;
    let bar = cli::progress::count(ladder.len() + 1, "precision", "runs", v.quiet);
    let method = sim::precision::reference_method(&scene, &run);
    bar.set_message(format!("reference ({method})"));
    let reference = sim::precision::reference(&scene, &run)?;
    bar.inc(1);
    let mut rows = Vec::with_capacity(ladder.len());
    for variant in &ladder {
        bar.set_message(format!("{} {}", variant.series, variant.setting));
        rows.push(sim::precision::measure(variant, &run, &reference, a.repeats as usize));
        bar.inc(1);
    }
    bar.finish_and_clear();

    // files for machines, and the diagram
    cli::write_file(&a.out.join("precision.json"), serde_json::to_string_pretty(&rows)? + "\n")?;
    cli::write_file(&a.out.join("precision.csv"), csv(&rows)?)?;
    let mut series: Vec<WorkPrecisionSeries> = Vec::new();
    for r in rows.iter().filter(|r| r.status == "ok") {
        match series.iter_mut().find(|s| s.name == r.series) {
            Some(s) => s.points.push((r.wall_s, r.max_hand_error_m)),
            None => series.push(WorkPrecisionSeries { name: r.series.clone(), points: vec![(r.wall_s, r.max_hand_error_m)] }),
        }
    }
    let title = format!("{} / {}: {} s simulated", scene.spec().name, run.name, scene.duration());
    work_precision(&series, &title, "max hand error vs reference [m]", &a.out.join("work-precision")).map_err(anyhow::Error::msg)?;

    let text = match a.format.format {
        Format::Json => serde_json::to_string_pretty(&rows)? + "\n",
        Format::Csv => csv(&rows)?,
        Format::Table => table(&rows, &scene.spec().name, &run.name, method, scene.duration(), a.accuracy)?,
    };
    print_out(&text)?;
    if !v.quiet {
        eprintln!("wrote {0}/precision.csv, precision.json, work-precision.svg, work-precision.png", a.out.display());
    }
    Ok(exit::SUCCESS)
}

/// One row per measured setting.
fn csv(rows: &[Row]) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in rows {
        w.serialize(r).context("writing the precision table")?;
    }
    Ok(String::from_utf8(w.into_inner().context("writing the precision table")?)?)
}

fn table(rows: &[Row], scene: &str, run: &str, reference: &str, duration: f64, accuracy: f64) -> Result<String> {
    let mut o = String::new();
    writeln!(o, "Speed against error: scene `{scene}`, run `{run}`, {duration} s simulated; reference {}", reference.replace(',', ""))?;
    // scenes with contact events get the event-time error and the unmatched events
    let with_events = rows.iter().any(|r| r.max_event_time_error_s.is_some());
    let mut head = vec!["method", "setting", "wall [ms]", "RHS", "steps", "rejected", "hand [m]", "energy [J]", "drift [m]", "x real"];
    if with_events {
        head.extend(["event t [s]", "unmatched"]);
    }
    head.push("status");
    let cells: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let mut c = vec![r.series.clone(), r.setting.clone()];
            if r.status == "ok" || r.status.starts_with("diverged") {
                c.extend([
                    format!("{:.2}", r.wall_s * 1e3),
                    r.rhs_evals.to_string(),
                    r.steps.to_string(),
                    r.rejected.to_string(),
                    format!("{:.2e}", r.max_hand_error_m),
                    format!("{:.2e}", r.max_link_energy_error_j),
                    format!("{:.1e}", r.max_drift_m),
                    format!("{:.0}", r.speed_vs_real_time),
                ]);
                if with_events {
                    c.push(r.max_event_time_error_s.map_or(String::from("-"), |e| format!("{e:.1e}")));
                    c.push(r.unmatched_events.map_or(String::from("-"), |n| n.to_string()));
                }
                c.push(r.status.clone());
            } else {
                // a failed run: no numbers, the reason in the status column
                c.extend(std::iter::repeat_n(String::from("-"), head.len() - 3));
                c.push(r.status.clone());
            }
            c
        })
        .collect();
    let mut t = analyze::render::TextTable::new(&head);
    t.left = 2;
    t.rows = cells;
    o.push_str(&t.aligned());
    let best = sim::precision::cheapest_within(rows, accuracy);
    let baseline = best.iter().find(|r| r.series.starts_with("paper baseline")).map(|r| r.wall_s);
    writeln!(o, "\nCheapest run per method with max hand error <= {accuracy:.0e} m:")?;
    for r in &best {
        let ratio = baseline.map_or(String::from("-"), |b| format!("{:.1}x faster than the paper baseline", b / r.wall_s));
        writeln!(o, "  {:<42} {:<12} {:>9.2} ms  {:>6.0}x real time  {ratio}", r.series, r.setting, r.wall_s * 1e3, r.speed_vs_real_time)?;
    }
    match sim::precision::recommend(rows, accuracy) {
        Some(rec) => {
            let (w, n) = (rec.by_wall, rec.by_rhs);
            writeln!(o, "\nRecommended for max hand error <= {accuracy:.0e} m: {} {} ({:.2} ms, {} RHS, hand error {:.1e} m)", w.series, w.setting, w.wall_s * 1e3, w.rhs_evals, w.max_hand_error_m)?;
            if !std::ptr::eq(w, n) {
                writeln!(o, "Fewest right-hand sides within it: {} {} ({:.2} ms, {} RHS, hand error {:.1e} m)", n.series, n.setting, n.wall_s * 1e3, n.rhs_evals, n.max_hand_error_m)?;
            }
        }
        None => {
            let best = rows.iter().filter(|r| r.status == "ok").map(|r| r.max_hand_error_m).fold(f64::INFINITY, f64::min);
            writeln!(o, "\nNo measured setting reaches max hand error <= {accuracy:.0e} m (the smallest was {best:.1e} m).")?;
        }
    }
    Ok(o)
}
