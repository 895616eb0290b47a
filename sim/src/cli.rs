//! Command-line interface of `sim` (clap derive). Parsing only; `main.rs` acts on it.

use std::path::PathBuf;

use clap::{Parser, Subcommand, ValueEnum};

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// Aligned columns for people.
    Table,
    /// JSON for machines.
    Json,
    /// CSV, one row per run.
    Csv,
}

#[derive(Debug, Parser)]
#[command(
    name = "sim",
    version,
    about = "Simulate motor-driven arms that rest their elbows on a table; record every run to MCAP",
    long_about = "Simulate motor-driven arms that rest their elbows on a table; record every run to MCAP.\n\n\
        With no arguments, runs the built-in paper scene (three elbow configurations, 5 s each), writes \
        out/paper-<run>.mcap and prints a table comparing the configurations.",
    after_help = "Examples:\n  sim                               run the paper's three configurations into out/\n  \
        sim --run two-elbow -o /tmp/r      one configuration, elsewhere\n  \
        sim my_scene.json --format json    another scene, machine-readable table\n  \
        sim export-scene scenes/           write the built-in scene and URDF to edit\n  \
        sim check my_scene.json            validate a scene without running it",
    args_conflicts_with_subcommands = true
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    #[command(flatten)]
    pub run: RunArgs,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a scene (the default command).
    Run(RunArgs),
    /// Validate a scene file and print what it describes, without running it.
    Check {
        /// Scene JSON file (default: the built-in paper scene).
        scene: Option<PathBuf>,
    },
    /// Speed against error: every method over a ladder of tolerances or steps, and each model
    /// reduction, against a tight reference run; writes a table and a work–precision plot.
    Precision(PrecisionArgs),
    /// Re-run an experiment from a recording alone (its embedded scene, URDF and settings);
    /// the new recording is byte-identical to the original when the version is the same.
    Replay(ReplayArgs),
    /// Run a grid of scene variations in parallel (optionally one shard of it, for job arrays).
    Sweep(crate::sweep_cmd::SweepArgs),
    /// Write the built-in paper scene (paper.json) and its URDF into a directory, to edit.
    ExportScene {
        /// Directory to write into (created if missing).
        dir: PathBuf,
    },
}

#[derive(Debug, Clone, clap::Args)]
pub struct ReplayArgs {
    /// A recording written by `sim`.
    pub recording: PathBuf,
    /// Directory for the new recording (same file name as the original).
    #[arg(short, long, default_value = "out/replay")]
    pub out: PathBuf,
    /// No progress output.
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Debug, Clone, clap::Args)]
pub struct PrecisionArgs {
    /// Scene JSON file (default: the built-in paper scene).
    pub scene: Option<PathBuf>,
    /// The run of the scene to measure (default: its first run).
    #[arg(long = "run", value_name = "NAME")]
    pub run: Option<String>,
    /// Simulated time of every run, s (default: the scene's duration).
    #[arg(long)]
    pub duration: Option<f64>,
    /// Directory for precision.csv, precision.json, work-precision.svg and .png.
    #[arg(short, long, default_value = "out/precision")]
    pub out: PathBuf,
    /// Timed repetitions of each run; the best is kept.
    #[arg(long, default_value_t = 3)]
    pub repeats: usize,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Debug, Clone, clap::Args)]
pub struct RunArgs {
    /// Scene JSON file (default: the built-in paper scene).
    pub scene: Option<PathBuf>,
    /// Directory for the recordings, named <scene>-<run>.mcap.
    #[arg(short, long, default_value = "out")]
    pub out: PathBuf,
    /// Run only these runs of the scene (repeatable; default: all).
    #[arg(long = "run", value_name = "NAME")]
    pub runs: Vec<String>,
    /// Runs in parallel (default: the number of cores). Results do not depend on it.
    #[arg(short, long)]
    pub jobs: Option<usize>,
    /// How to print the comparison table.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    pub format: Format,
    /// Baseline run for the ratios in the table (default: a run without contacts).
    #[arg(long)]
    pub baseline: Option<String>,
    /// No progress bars.
    #[arg(short, long)]
    pub quiet: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_arguments_runs_the_paper_scene() {
        let cli = Cli::try_parse_from(["sim"]).unwrap();
        assert!(cli.command.is_none());
        assert!(cli.run.scene.is_none());
        assert_eq!(cli.run.out, PathBuf::from("out"));
        assert_eq!(cli.run.format, Format::Table);
    }

    #[test]
    fn run_options_parse() {
        let cli = Cli::try_parse_from(["sim", "s.json", "--run", "a", "--run", "b", "-o", "/tmp/x", "--format", "csv", "-j", "1"])
            .unwrap();
        assert_eq!(cli.run.scene, Some(PathBuf::from("s.json")));
        assert_eq!(cli.run.runs, ["a", "b"]);
        assert_eq!(cli.run.format, Format::Csv);
        assert_eq!(cli.run.jobs, Some(1));
        assert!(matches!(Cli::try_parse_from(["sim", "check", "s.json"]).unwrap().command, Some(Command::Check { .. })));
        assert!(Cli::try_parse_from(["sim", "--format", "xml"]).is_err());
    }
}
