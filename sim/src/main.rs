//! The `sim` binary: parse the command line, act, and map the outcome to an exit status
//! (0 success, 1 a run failed numerically, 2 bad input or I/O).

mod app;
mod cli;
mod sweep_cmd;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let cli = cli::Cli::parse();
    let result = match cli.command {
        Some(cli::Command::Check { scene }) => app::check(scene.as_deref()).map(|_| ExitCode::SUCCESS),
        Some(cli::Command::Replay(args)) => app::replay(&args).map(|_| ExitCode::SUCCESS),
        Some(cli::Command::Sweep(args)) => sweep_cmd::run(&args),
        Some(cli::Command::Precision(args)) => app::precision(&args).map(|_| ExitCode::SUCCESS),
        Some(cli::Command::ExportScene { dir }) => app::export_scene(&dir).map(|_| ExitCode::SUCCESS),
        Some(cli::Command::Run(args)) => run(&args),
        None => run(&cli.run),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("sim: error: {e:#}");
            ExitCode::from(2)
        }
    }
}

fn run(args: &cli::RunArgs) -> anyhow::Result<ExitCode> {
    let outcome = app::run(args)?;
    if !outcome.written.is_empty() {
        app::print_comparison(&outcome.written, args.format, args.baseline.as_deref())?;
    }
    for f in &outcome.failures {
        eprintln!("sim: error: {f}");
    }
    Ok(if outcome.failures.is_empty() { ExitCode::SUCCESS } else { ExitCode::from(app::EXIT_RUN_FAILED) })
}
