//! The `sim` binary: parse the command line, run the command, map the outcome to an exit
//! status (`cli::exit`: 0 done, 1 a run failed numerically — its recording says when and why —,
//! 2 bad input: command line, scene, URDF, I/O). One file per command; the shared flags are
//! `cli::args`.

mod check;
mod export_scene;
mod list;
mod live;
mod optimize;
mod optimize_seeds;
mod precision;
mod replay;
mod run;
mod schema;
mod sweep;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{CommandFactory, Parser, Subcommand};
use cli::exit;
use cli::extras::{CompletionsArgs, ManArgs};
use cli::Verbosity;

const EXAMPLES: &str = "\
Examples:
  sim                                   the paper's three runs and the same arm over a real table
                                        (paper-unilateral) -> out/, then one comparison table
  sim --run two-elbow -o /tmp/r         one run of the built-in scene, elsewhere
  sim run my_scene.json -f json         another scene, the table as JSON
  sim check my_scene.json               validate a scene and describe it, without running it
  sim list                              the built-in scenes: the paper and three real arms
  sim ur5e-like -o /tmp/ur              a built-in scene by name (as `sim run ur5e-like`)
  sim export-scene -o scenes/           the built-in scene and URDF, to edit
  sim schema -o scene.schema.json       the scene files' JSON Schema, for editors
  sim replay out/paper-two-elbow.mcap   re-run a recording from its own metadata
  sim sweep sim/scenes/sweeps/paper-gains.json -j 2
  sim optimize sim/scenes/studies/which-elbow.json -j 2
  sim precision --duration 1            speed against error of every integrator
  sim --live                            also stream each run to the Foxglove app, paced to real
                                        time (build with --features live): ws://localhost:8765";

/// Simulate motor-driven arms that rest their elbows on a table; record every run to MCAP.
///
/// With no command, runs the built-in paper scene (three elbow configurations, 5 s each, a table
/// that holds the elbows bilaterally, as the paper) and the same arm over a real table that only
/// pushes (`paper-unilateral`: the elbows rest unilaterally with friction, and the no-elbow arm
/// over a table under the whole arm), writes out/<scene>-<run>.mcap and prints the findings that
/// matter and one table comparing the six runs (`-v`: every table and finding). With a scene (`--scene`, `sim run SCENE`), runs that scene. With the
/// name of a built-in scene instead of a command (`sim list` shows them), runs that scene.
#[derive(Debug, Parser)]
#[command(name = "sim", version = cli::VERSION, after_help = EXAMPLES, args_conflicts_with_subcommands = true, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Scene JSON file, or the name of a built-in scene (`sim list`) [default: the built-in paper
    /// scene].
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
    Optimize(optimize::OptimizeArgs),
    Precision(precision::PrecisionArgs),
    ExportScene(export_scene::ExportSceneArgs),
    List(list::ListArgs),
    Schema(schema::SchemaArgs),
    /// Print the shell completion script (bash, zsh, fish, elvish, powershell).
    #[command(after_help = "Example:\n  sim completions bash > ~/.local/share/bash-completion/completions/sim")]
    Completions(CompletionsArgs),
    /// Write the man pages of `sim` and its commands into a directory.
    #[command(after_help = "Examples:\n  sim man -o man/ && man man/sim-run.1\n  sim man --markdown -o docs/src/reference/   the book's CLI reference, sim.md")]
    Man(ManArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse_from(builtin_as_run(std::env::args_os().collect()));
    let v = cli.verbosity;
    let result = match cli.command {
        None if cli.scene.is_none() => run::run_default(&cli.run, v),
        None => run::run(cli.scene.as_deref(), &cli.run, v),
        Some(Command::Run(a)) => run::run(a.scene.as_deref(), &a.run, v),
        Some(Command::Check(a)) => check::run(&a),
        Some(Command::Replay(a)) => replay::run(&a, v),
        Some(Command::Sweep(a)) => sweep::run(&a, v),
        Some(Command::Optimize(a)) => optimize::run(&a, v),
        Some(Command::Precision(a)) => precision::run(&a, v),
        Some(Command::ExportScene(a)) => export_scene::run(&a, v),
        Some(Command::List(a)) => list::run(&a),
        Some(Command::Schema(a)) => schema::run(&a, v),
        Some(Command::Completions(a)) => cli::extras::completions(Cli::command(), a.shell).map(|()| exit::SUCCESS),
        Some(Command::Man(a)) => cli::extras::man(Cli::command(), &a).map(|n| {
            if !v.quiet {
                eprintln!("sim: {n} {} in {}", if a.markdown { "Markdown page" } else { "man pages" }, a.out.display());
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

/// `sim NAME ARGS…` for a built-in scene NAME (`sim list`) is `sim run NAME ARGS…`: the
/// arguments with `run` inserted before the first one when it is a built-in scene's name and no
/// command's. Anything else is left to clap as it is (so an unknown command is still an error
/// with suggestions, and `sim` alone still runs the paper).
fn builtin_as_run(mut args: Vec<std::ffi::OsString>) -> Vec<std::ffi::OsString> {
    let first = args.get(1).and_then(|a| a.to_str()).map(str::to_string);
    if let Some(first) = first {
        let is_command = Cli::command().get_subcommands().any(|c| c.get_name() == first || c.get_all_aliases().any(|a| a == first));
        if !is_command && sim::scene::builtin::find(&first).is_some() {
            args.insert(1, "run".into());
        }
    }
    args
}

/// The scene at `path`; a `path` that is no file but a built-in scene's name (`sim list`) is
/// that scene; no `path` is the built-in paper scene.
fn load_scene(path: Option<&std::path::Path>) -> anyhow::Result<sim::scene::Scene> {
    Ok(match path {
        Some(p) => match p.to_str().and_then(sim::scene::builtin::find) {
            Some(b) if !p.exists() => b.load()?,
            _ => sim::scene::Scene::load(p)?,
        },
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
        cli::examples::check_command_line(Cli::command(), |args| Cli::try_parse_from(builtin_as_run(args.iter().map(Into::into).collect())).map(drop));
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
    fn a_builtin_scene_name_runs_that_scene() {
        let argv = |args: &[&str]| builtin_as_run(std::iter::once("sim").chain(args.iter().copied()).map(Into::into).collect());
        let Some(Command::Run(r)) = Cli::try_parse_from(argv(&["ur5e-like", "--run", "free", "-o", "/tmp/u"])).unwrap().command else { panic!() };
        assert_eq!((r.scene, r.run.runs, r.run.out), (Some(PathBuf::from("ur5e-like")), vec!["free".to_string()], PathBuf::from("/tmp/u")));
        // commands and files are left alone
        assert_eq!(argv(&["list"]), ["sim", "list"]);
        assert_eq!(argv(&["run", "paper"]), ["sim", "run", "paper"]);
        assert_eq!(argv(&[]), ["sim"]);
        assert!(matches!(parse(&["list", "-f", "csv"]).unwrap().command, Some(Command::List(_))));
    }

    #[test]
    fn schema_prints_the_scene_schema_by_default() {
        let Some(Command::Schema(a)) = parse(&["schema"]).unwrap().command else { panic!() };
        assert_eq!((a.kind, a.format, a.out), (schema::Kind::Scene, schema::SchemaFormat::Json, None));
        let Some(Command::Schema(a)) = parse(&["schema", "sweep", "-f", "markdown", "-o", "f.md"]).unwrap().command else { panic!() };
        assert_eq!((a.kind, a.format, a.out), (schema::Kind::Sweep, schema::SchemaFormat::Markdown, Some(PathBuf::from("f.md"))));
        assert_eq!(parse(&["schema", "scenes"]).unwrap_err().kind(), ErrorKind::InvalidValue);
        assert_eq!(parse(&["schema", "-f", "csv"]).unwrap_err().kind(), ErrorKind::InvalidValue);
    }

    #[test]
    fn subcommands_are_matched_strictly_with_suggestions() {
        let kind = |args: &[&str]| parse(args).unwrap_err().kind();
        assert_eq!(kind(&["chek", "s.json"]), ErrorKind::InvalidSubcommand);
        assert!(parse(&["chek"]).unwrap_err().to_string().contains("check"));
        assert_eq!(kind(&["s.json"]), ErrorKind::InvalidSubcommand);
        assert_eq!(kind(&["-f", "xml"]), ErrorKind::InvalidValue);
        assert_eq!(kind(&["--scene", "a.json", "check"]), ErrorKind::ArgumentConflict);
        assert_eq!(kind(&["ur5e-lik"]), ErrorKind::InvalidSubcommand);
        assert_eq!(kind(&["run", "--duration", "0"]), ErrorKind::ValueValidation);
        assert_eq!(kind(&["run", "--duration=-1"]), ErrorKind::ValueValidation);
        assert!(matches!(parse(&["check", "s.json", "-f", "json"]).unwrap().command, Some(Command::Check(_))));
    }
}
