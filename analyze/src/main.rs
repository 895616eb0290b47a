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
            eprintln!("analyze: error: {}", message(&err));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes, `: `-separated, leaving out a cause whose text is already in the
/// message (errors that print their source, e.g. `unreadable MCAP: {source}`, would repeat it).
fn message(err: &anyhow::Error) -> String {
    let mut msg = err.to_string();
    for cause in err.chain().skip(1) {
        let c = cause.to_string();
        if !msg.contains(&c) {
            msg.push_str(": ");
            msg.push_str(&c);
        }
    }
    msg
}
