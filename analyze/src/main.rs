//! The `analyze` binary: parse the command line, run it, map the outcome to an exit code
//! (0 success, 1 error with its causes on stderr, 2 bad command line via clap).

mod cli;
mod commands;
#[cfg(test)]
#[path = "testutil.rs"]
mod testutil;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    match commands::run(cli::Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("analyze: error: {err:#}");
            ExitCode::FAILURE
        }
    }
}
