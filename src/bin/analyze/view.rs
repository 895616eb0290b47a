//! `analyze view`: recordings as Rerun `.rrd` files with a blueprint (`analyze::view`, feature
//! `rerun`); without the feature, an error that says how to get it.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use cli::{exit, Verbosity};

/// Recordings as Rerun .rrd files that open on the experiment: the arm in 3D with the table,
/// the target path, the hand (actual and target) and the contact forces coloured by mode; motor
/// currents and voltages, contact forces and modes, energies per joint, the totals and the
/// balance residual as plots named by joint and contact; a `sim_time` duration timeline; a
/// blueprint that lays it out. Several recordings with -o: one file, side by side.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Output: <stem>.rrd beside each recording, or OUT.rrd with -o (every input in one file: one 3D
view per run, energies of all runs overlaid, one plot per run and signal). The application id
is the file stem (Rerun applies a blueprint per application id). Needs the feature `rerun`.

Examples:
  analyze view out/paper-two-elbow.mcap            -> out/paper-two-elbow.rrd
  analyze view out/paper-two-elbow.mcap --spawn    and open it in the Rerun viewer
  analyze view out/ -o out/paper.rrd               every out/*.mcap side by side in one file
  analyze view out/run.mcap --tab \"slip / stick\"   open on the slip / stick tab
  rerun out/paper-two-elbow.rrd                    open a converted file (Rerun 0.41)")]
pub struct ViewArgs {
    /// Recordings (.mcap), or directories: every *.mcap directly in them, sorted by name.
    #[arg(required = true, value_name = "FILES_OR_DIRS")]
    pub inputs: Vec<PathBuf>,
    /// Write every input into this one .rrd, side by side [default: <stem>.rrd beside each
    /// input].
    #[arg(short = 'o', long = "out", value_name = "OUT.rrd")]
    pub out: Option<PathBuf>,
    /// Open the result in the Rerun viewer (`rerun` must be on PATH).
    #[arg(long)]
    pub spawn: bool,
    /// The tab the viewer opens on, by its name ("slip / stick", "energy", ...) [default: the
    /// first, "arm"].
    #[arg(long, value_name = "NAME")]
    pub tab: Option<String>,
}

fn stem(p: &Path) -> String {
    p.file_stem().map_or_else(|| "recording".into(), |s| s.to_string_lossy().into_owned())
}

/// `analyze view`.
pub fn run(a: &ViewArgs, v: Verbosity) -> Result<u8> {
    let expanded = cli::inputs::expand_all(&a.inputs)?;
    expanded.warn_skipped();
    let paths = expanded.files.clone();
    // (output, its inputs)
    let jobs: Vec<(PathBuf, Vec<PathBuf>)> = match &a.out {
        Some(out) => {
            if out.extension().is_none_or(|e| e != "rrd") {
                bail!("-o {}: the output must be a .rrd file", out.display());
            }
            vec![(out.clone(), paths.clone())]
        }
        None => paths.iter().map(|p| (p.with_extension("rrd"), vec![p.clone()])).collect(),
    };
    if a.out.is_some() && paths.len() > 1 {
        let mut stems: Vec<String> = paths.iter().map(|p| stem(p)).collect();
        stems.sort();
        if let Some(w) = stems.windows(2).find(|w| w[0] == w[1]) {
            bail!("two inputs are named {:?}: in one .rrd each run needs its own name; rename one", w[0]);
        }
    }
    if a.spawn {
        which_rerun()?;
    }
    let (written, failed) = convert(&jobs, a.tab.as_deref(), v)?;
    if a.spawn {
        let status = std::process::Command::new("rerun").args(&written).status();
        match status {
            Ok(s) if s.success() => {}
            Ok(s) => bail!("the Rerun viewer exited with {s}"),
            Err(e) => bail!("starting the Rerun viewer (`rerun`): {e}"),
        }
    }
    Ok(if failed > 0 || !expanded.skipped.is_empty() { exit::FAILED } else { exit::SUCCESS })
}

/// `rerun` on PATH, or an error that says how to get it.
fn which_rerun() -> Result<()> {
    let found = std::env::var_os("PATH")
        .map(|p| std::env::split_paths(&p).any(|d| d.join("rerun").is_file()))
        .unwrap_or(false);
    if !found {
        bail!("--spawn: the Rerun viewer `rerun` is not on PATH; install it with `pip install rerun-sdk==0.41.0` (or open the .rrd later with `rerun FILE.rrd`)");
    }
    Ok(())
}

/// Converts each job (an output and its inputs); a job that fails is reported and the others go
/// on. The outputs written and the number of jobs that failed.
fn convert(jobs: &[(PathBuf, Vec<PathBuf>)], tab: Option<&str>, v: Verbosity) -> Result<(Vec<PathBuf>, usize)> {
    use anyhow::Context;
    let total: usize = jobs.iter().map(|(_, i)| i.len()).sum();
    let bar = cli::progress::count(total, "reading", "recordings", v.quiet || total < 2);
    let outs: Vec<PathBuf> = jobs.iter().map(|(out, _)| out.clone()).collect();
    let failed_runs = std::cell::Cell::new(0usize);
    let result = cli::inputs::each_file(&outs, |out| {
        let inputs = &jobs.iter().find(|(o, _)| o == out).expect("a job per output").1;
        let started = std::time::Instant::now();
        let names = inputs.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ");
        let converted = analyze::view::convert(inputs, out, tab, &|| bar.inc(1)).with_context(|| format!("converting {names}"))?;
        let size = converted.bytes;
        // the URDF geometry that could not be drawn as written: once per output, per link
        for note in &converted.notes {
            bar.suspend(|| eprintln!("analyze: note: {}: {note}", out.display()));
        }
        for (p, result) in &converted.results {
            if let Some(note) = cli::inputs::failed_run_note(p, result.as_ref()) {
                bar.suspend(|| eprintln!("analyze: {note} (drawn with what it recorded)"));
                failed_runs.set(failed_runs.get() + 1);
            }
        }
        if !v.quiet {
            let mcap: u64 = inputs.iter().filter_map(|p| std::fs::metadata(p).ok()).map(|m| m.len()).sum();
            bar.suspend(|| {
                let (meshes, vertices, _) = converted.meshes;
                let meshes = if meshes > 0 { format!(", {meshes} meshes of {vertices} vertices") } else { String::new() };
                eprintln!(
                    "analyze: {names} -> {} ({} run{}{meshes}, {:.2} MB from {:.2} MB of MCAP, {:.2} s)",
                    out.display(),
                    inputs.len(),
                    if inputs.len() == 1 { "" } else { "s" },
                    size as f64 / 1e6,
                    mcap as f64 / 1e6,
                    started.elapsed().as_secs_f64()
                )
            });
        }
        Ok(())
    });
    bar.finish_and_clear();
    let (written, failed) = result?;
    let failed = failed + failed_runs.get();
    Ok((written.into_iter().map(|(out, ())| out).collect(), failed))
}
