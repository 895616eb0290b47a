//! Carries out the `analyze` subcommands: expand inputs, read metrics, compare, render, write.

use std::io::Write;
use std::path::{Path, PathBuf};

use analyze::{
    read_run_metrics, render_comparison, render_metrics, run_metrics_recovered, Comparison,
    RunMetrics,
};
use anyhow::{bail, Context, Result};

use crate::cli::{Cli, Command, Output};

mod report;
#[cfg(feature = "tables")]
mod tables;

#[cfg(not(feature = "tables"))]
mod tables {
    //! Without the feature `tables` (polars) the commands say how to get them.
    fn missing() -> anyhow::Result<()> {
        anyhow::bail!(
            "this analyze was built without the feature `tables` (polars); build it with \
             `cargo build --release -p analyze`"
        )
    }
    pub fn summary(_: &crate::cli::SummaryArgs) -> anyhow::Result<()> {
        missing()
    }
    pub fn export(_: &crate::cli::ExportArgs) -> anyhow::Result<()> {
        missing()
    }
}

/// Runs one command line.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Compare(a) => {
            let runs = load(&a.inputs, a.recover)?;
            let cmp = Comparison::new(&runs, a.baseline.as_deref())?;
            emit(&a.output, &render_comparison(&cmp, a.output.format)?)
        }
        Command::Metrics(a) => {
            let runs = load(&a.inputs, a.recover)?;
            emit(&a.output, &render_metrics(&runs, a.output.format)?)
        }
        Command::Summary(a) => tables::summary(&a),
        Command::Report(a) => report::report(&a),
        Command::Export(a) => tables::export(&a),
        Command::Figures(a) => figures(&a),
        // exit status: 0 nothing moved, 1 something moved, 2 bad input (not main's 1)
        Command::Diff(a) => match diff(&a) {
            Ok(false) => Ok(()),
            Ok(true) => std::process::exit(1),
            Err(err) => {
                eprintln!("analyze: error: {err:#}");
                std::process::exit(2)
            }
        },
    }
}

/// `analyze figures`: every figure of every input into `a.output`, then the index pages.
fn figures(a: &crate::cli::FiguresArgs) -> Result<()> {
    let paths = expand_inputs(&a.inputs)?;
    let runs = paths
        .iter()
        .map(|p| analyze::figures::read_run(p).with_context(|| format!("reading {}", p.display())))
        .collect::<Result<Vec<_>>>()?;
    let figures = analyze::figures::write_all(&runs, &paths, &a.output)?;
    eprintln!(
        "analyze: {} figures (SVG and PNG) of {} runs in {}; open {}",
        figures.len(),
        runs.len(),
        a.output.display(),
        a.output.join("index.html").display()
    );
    Ok(())
}

/// `analyze diff`: reads both inputs, compares, writes the report; `Ok(true)` when something
/// differs beyond the tolerances.
fn diff(a: &crate::cli::DiffArgs) -> Result<bool> {
    let (left, right) = (analyze::read_input(&a.a)?, analyze::read_input(&a.b)?);
    let tol = analyze::Tolerance {
        rtol: a.rtol,
        atol: a.atol,
    };
    let d = analyze::diff::diff(&left, &right, tol)?;
    emit(
        &a.output,
        &analyze::render_diff(&d, a.output.format, a.all)?,
    )?;
    Ok(d.differs())
}

/// Files as given; a directory stands for every `*.mcap` file directly in it, sorted by name.
pub fn expand_inputs(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for input in inputs {
        if !input.is_dir() {
            out.push(input.clone());
            continue;
        }
        let mut found = Vec::new();
        let entries =
            std::fs::read_dir(input).with_context(|| format!("listing {}", input.display()))?;
        for entry in entries {
            let path = entry
                .with_context(|| format!("listing {}", input.display()))?
                .path();
            let is_mcap = path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("mcap"));
            if is_mcap && path.is_file() {
                found.push(path);
            }
        }
        if found.is_empty() {
            bail!("{}: no *.mcap files in this directory", input.display());
        }
        found.sort();
        out.extend(found);
    }
    Ok(out)
}

/// Metrics of every input, in order; the first unreadable file stops with an error naming it.
/// With `recover`, damaged files give the metrics of their intact part and a warning on stderr.
fn load(inputs: &[PathBuf], recover: bool) -> Result<Vec<RunMetrics>> {
    expand_inputs(inputs)?
        .iter()
        .map(|p| {
            let context = || format!("analyzing {}", p.display());
            if !recover {
                return read_run_metrics(p).with_context(context);
            }
            let (rec, report) = schemas::read_recording_recover(p).with_context(context)?;
            if !report.complete {
                eprintln!("analyze: warning: {report}");
            }
            run_metrics_recovered(&rec, &report).with_context(|| {
                format!(
                    "analyzing {} (recovered {} messages from its first {} bytes)",
                    p.display(),
                    report.messages,
                    report.stopped_at
                )
            })
        })
        .collect()
}

/// Writes `text` to the output file, or to standard output.
fn emit(output: &Output, text: &str) -> Result<()> {
    match &output.output {
        Some(path) => write_file(path, text),
        None => {
            let mut out = std::io::stdout().lock();
            out.write_all(text.as_bytes())
                .and_then(|()| out.flush())
                .context("writing to standard output")
        }
    }
}

fn write_file(path: &Path, text: &str) -> Result<()> {
    std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::Synth;
    use clap::Parser;

    fn cli(args: &[&str]) -> Cli {
        Cli::try_parse_from(std::iter::once("analyze").chain(args.iter().copied())).unwrap()
    }

    #[test]
    fn directories_expand_to_their_mcap_files_sorted() {
        let dir = tempfile::tempdir().unwrap();
        for name in ["b.mcap", "a.mcap", "notes.txt", "c.MCAP"] {
            std::fs::write(dir.path().join(name), "").unwrap();
        }
        std::fs::create_dir(dir.path().join("sub.mcap")).unwrap();
        let got = expand_inputs(&[PathBuf::from("x.mcap"), dir.path().to_path_buf()]).unwrap();
        let names: Vec<String> = got
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["x.mcap", "a.mcap", "b.mcap", "c.MCAP"]);
        let empty = tempfile::tempdir().unwrap();
        let err = expand_inputs(&[empty.path().to_path_buf()])
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(&empty.path().display().to_string()) && err.contains("no *.mcap"),
            "{err}"
        );
    }

    /// compare over a directory writes JSON to -o; no-elbow (0 contacts) becomes the baseline;
    /// E totals are 2 (1+2+3) = 12 J and 2 * 12 = 24 J, so the ratio is 2 (to 1e-12).
    #[test]
    fn compare_writes_the_comparison_of_a_directory() {
        let dir = tempfile::tempdir().unwrap();
        let mut two = Synth::new("two-elbow", &["elbow4", "elbow7"], 3);
        two.energy = Box::new(|t| crate::testutil::linear_energy(t, 3, 1.0, 4.0));
        two.write(dir.path());
        Synth::new("no-elbow", &[], 3).write(dir.path());
        let out = dir.path().join("cmp.json");
        let d = dir.path().to_str().unwrap();
        run(cli(&[
            "compare",
            d,
            "--format",
            "json",
            "-o",
            out.to_str().unwrap(),
        ]))
        .unwrap();
        let cmp: Comparison =
            serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        assert_eq!(cmp.baseline, "no-elbow");
        let names: Vec<&str> = cmp.runs.iter().map(|r| r.metrics.run.as_str()).collect();
        assert_eq!(names, ["no-elbow", "two-elbow"]); // sorted by file name
        assert!((cmp.runs[1].to_baseline.electric_energy.unwrap() - 2.0).abs() < 1e-12);

        let csv = dir.path().join("m.csv");
        run(cli(&[
            "metrics",
            d,
            "-f",
            "csv",
            "-o",
            csv.to_str().unwrap(),
        ]))
        .unwrap();
        assert_eq!(std::fs::read_to_string(&csv).unwrap().lines().count(), 3);
    }

    #[test]
    fn a_bad_file_is_an_error_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        Synth::new("good", &[], 2).write(dir.path());
        let bad = dir.path().join("zz-bad.mcap");
        std::fs::write(&bad, "not a recording").unwrap();
        let err = run(cli(&["compare", dir.path().to_str().unwrap()])).unwrap_err();
        let msg = format!("{err:#}");
        assert!(
            msg.contains("zz-bad.mcap") && msg.contains("not an MCAP file"),
            "{msg}"
        );
        let err = run(cli(&[
            "compare",
            dir.path().join("good.mcap").to_str().unwrap(),
            "--baseline",
            "nope",
        ]));
        assert!(format!("{:#}", err.unwrap_err()).contains("nope"));
    }
}
