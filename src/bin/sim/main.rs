//! The `sim` binary: parse the command line, run the command, map the outcome to an exit
//! status (`cli::exit`: 0 done, 1 a run failed numerically — its recording says when and why —,
//! 2 bad input: command line, scene, URDF, I/O). One file per command; the shared flags are
//! `cli::args`.

mod check;
mod export_scene;
mod precision;
mod replay;
mod run;
mod sweep;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{CommandFactory, Parser, Subcommand};
use cli::exit;
use cli::extras::{CompletionsArgs, ManArgs};
use cli::Verbosity;

const EXAMPLES: &str = "\
Examples:
  sim                                   the paper's three runs -> out/, then the comparison table
  sim --run two-elbow -o /tmp/r         one run of the built-in scene, elsewhere
  sim run my_scene.json -f json         another scene, the table as JSON
  sim check my_scene.json               validate a scene and describe it, without running it
  sim export-scene -o scenes/           the built-in scene and URDF, to edit
  sim replay out/paper-two-elbow.mcap   re-run a recording from its own metadata
  sim sweep sim/scenes/sweeps/paper-gains.json -j 2
  sim precision --duration 1            speed against error of every integrator";

/// Simulate motor-driven arms that rest their elbows on a table; record every run to MCAP.
///
/// With no command, runs the built-in paper scene (three elbow configurations, 5 s each), writes
/// out/paper-<run>.mcap and prints a table comparing the configurations (as `sim run`).
#[derive(Debug, Parser)]
#[command(name = "sim", version = cli::VERSION, after_help = EXAMPLES, args_conflicts_with_subcommands = true, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Scene JSON file [default: the built-in paper scene].
    #[arg(long, value_name = "FILE")]
    scene: Option<PathBuf>,
    #[command(flatten)]
    run: run::RunArgs,
    #[command(flatten)]
    verbosity: Verbosity,
}

#[derive(Debug, Subcommand)]
enum Command {
    Run(run::RunCommand),
    Check(check::CheckArgs),
    Replay(replay::ReplayArgs),
    Sweep(sweep::SweepArgs),
    Precision(precision::PrecisionArgs),
    ExportScene(export_scene::ExportSceneArgs),
    /// Print the shell completion script (bash, zsh, fish, elvish, powershell).
    #[command(after_help = "Example:\n  sim completions bash > ~/.local/share/bash-completion/completions/sim")]
    Completions(CompletionsArgs),
    /// Write the man pages of `sim` and its commands into a directory.
    #[command(after_help = "Example:\n  sim man -o man/ && man man/sim-run.1")]
    Man(ManArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let v = cli.verbosity;
    let result = match cli.command {
        None => run::run(cli.scene.as_deref(), &cli.run, v),
        Some(Command::Run(a)) => run::run(a.scene.as_deref(), &a.run, v),
        Some(Command::Check(a)) => check::run(&a),
        Some(Command::Replay(a)) => replay::run(&a, v),
        Some(Command::Sweep(a)) => sweep::run(&a, v),
        Some(Command::Precision(a)) => precision::run(&a, v),
        Some(Command::ExportScene(a)) => export_scene::run(&a, v),
        Some(Command::Completions(a)) => cli::extras::completions(Cli::command(), a.shell).map(|()| exit::SUCCESS),
        Some(Command::Man(a)) => cli::extras::man_pages(Cli::command(), &a.out).map(|n| {
            if !v.quiet {
                eprintln!("sim: {n} man pages in {}", a.out.display());
            }
            exit::SUCCESS
        }),
    };
    match result {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            eprintln!("sim: error: {}", exit::message(&e));
            ExitCode::from(exit::BAD_INPUT)
        }
    }
}

/// The scene at `path`, or the built-in paper scene.
fn load_scene(path: Option<&std::path::Path>) -> anyhow::Result<sim::scene::Scene> {
    Ok(match path {
        Some(p) => sim::scene::Scene::load(p)?,
        None => sim::scene::Scene::paper()?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::error::ErrorKind;

    fn parse(args: &[&str]) -> Result<Cli, clap::Error> {
        Cli::try_parse_from(std::iter::once("sim").chain(args.iter().copied()))
    }

    /// clap's consistency check, and every example of every `--help` parses as written.
    #[test]
    fn the_command_line_and_its_examples_are_consistent() {
        cli::examples::check_command_line(Cli::command(), |args| Cli::try_parse_from(args).map(drop));
    }

    #[test]
    fn no_arguments_runs_the_paper_scene() {
        let cli = parse(&[]).unwrap();
        assert!(cli.command.is_none() && cli.scene.is_none());
        assert_eq!(cli.run.out, PathBuf::from("out"));
        assert_eq!(cli.run.format.format, analyze::Format::Table);
    }

    #[test]
    fn a_scene_is_given_by_a_flag_or_the_run_command() {
        let cli = parse(&["--scene", "s.json", "--run", "a", "--run", "b", "-o", "/tmp/x", "-f", "csv", "-j", "1"]).unwrap();
        assert_eq!(cli.scene, Some(PathBuf::from("s.json")));
        assert_eq!(cli.run.runs, ["a", "b"]);
        assert_eq!((cli.run.format.format, cli.run.jobs.jobs), (analyze::Format::Csv, Some(1)));
        let Some(Command::Run(r)) = parse(&["run", "s.json", "--duration", "0.5"]).unwrap().command else { panic!() };
        assert_eq!((r.scene, r.run.duration), (Some(PathBuf::from("s.json")), Some(0.5)));
    }

    #[test]
    fn subcommands_are_matched_strictly_with_suggestions() {
        let kind = |args: &[&str]| parse(args).unwrap_err().kind();
        assert_eq!(kind(&["chek", "s.json"]), ErrorKind::InvalidSubcommand);
        assert!(parse(&["chek"]).unwrap_err().to_string().contains("check"));
        assert_eq!(kind(&["s.json"]), ErrorKind::InvalidSubcommand);
        assert_eq!(kind(&["-f", "xml"]), ErrorKind::InvalidValue);
        assert_eq!(kind(&["--scene", "a.json", "check"]), ErrorKind::ArgumentConflict);
        assert_eq!(kind(&["run", "--duration", "0"]), ErrorKind::ValueValidation);
        assert_eq!(kind(&["run", "--duration=-1"]), ErrorKind::ValueValidation);
        assert!(matches!(parse(&["check", "s.json", "-f", "json"]).unwrap().command, Some(Command::Check(_))));
    }
}
