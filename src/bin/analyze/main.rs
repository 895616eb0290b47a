//! The `analyze` binary: parse the command line, run the command, map the outcome to an exit
//! status (`cli::exit`: 0 done, 1 a result the caller must see — differences found, files left
//! out —, 2 bad input). One file per command; the shared flags are `cli::args`.

mod compare;
mod diff;
mod export;
mod figures;
mod layout;
mod load;
mod report;
mod summary;
mod view;

use std::process::ExitCode;

use clap::{CommandFactory, Parser, Subcommand};
use cli::exit;
use cli::extras::{CompletionsArgs, ManArgs};
use cli::Verbosity;

const EXAMPLES: &str = "\
Examples:
  analyze compare out/                      every out/*.mcap against the run without elbows
  analyze compare out/ --baseline one-elbow -f csv > table.csv
  analyze metrics out/paper-two-elbow.mcap  one run's numbers, no comparison
  analyze report out/ -o out/report         the comparison as a document, with the figures
  analyze summary 'out/*.mcap' --sort E_total_j   many runs as one table
  analyze export out/ -o out/tables         every topic as Parquet, for Python
  analyze view out/paper-two-elbow.mcap     as a Rerun .rrd with a blueprint (feature rerun)
  analyze layout out/ -o out                the Foxglove layout of the recordings
  analyze diff recordings/ out/             what moved between two versions";

/// Reads recordings of `sim` runs: hand error, link work W_j, motor electric energy E_j,
/// contact forces, the energy balance; compares runs, draws figures, exports tables.
#[derive(Debug, Parser)]
#[command(name = "analyze", version = cli::VERSION, after_help = EXAMPLES, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    #[command(flatten)]
    verbosity: Verbosity,
}

#[derive(Debug, Subcommand)]
enum Command {
    Compare(compare::CompareArgs),
    Metrics(compare::MetricsArgs),
    Summary(summary::SummaryArgs),
    Diff(diff::DiffArgs),
    Report(report::ReportArgs),
    Figures(figures::FiguresArgs),
    Export(export::ExportArgs),
    View(view::ViewArgs),
    Layout(layout::LayoutArgs),
    /// Print the shell completion script (bash, zsh, fish, elvish, powershell).
    #[command(after_help = "Example:\n  analyze completions bash > ~/.local/share/bash-completion/completions/analyze")]
    Completions(CompletionsArgs),
    /// Write the man pages of `analyze` and its commands into a directory.
    #[command(after_help = "Examples:\n  analyze man -o man/ && man man/analyze-compare.1\n  analyze man --markdown -o docs/src/reference/   the book's CLI reference, analyze.md")]
    Man(ManArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let v = cli.verbosity;
    let result = match cli.command {
        Command::Compare(a) => compare::compare(&a, v),
        Command::Metrics(a) => compare::metrics(&a, v),
        Command::Summary(a) => summary::run(&a, v),
        Command::Diff(a) => diff::run(&a),
        Command::Report(a) => report::run(&a, v),
        Command::Figures(a) => figures::run(&a, v),
        Command::Export(a) => export::run(&a, v),
        Command::View(a) => view::run(&a, v),
        Command::Layout(a) => layout::run(&a, v),
        Command::Completions(a) => cli::extras::completions(Cli::command(), a.shell).map(|()| exit::SUCCESS),
        Command::Man(a) => cli::extras::man(Cli::command(), &a).map(|n| {
            if !v.quiet {
                eprintln!("analyze: {n} {} in {}", if a.markdown { "Markdown page" } else { "man pages" }, a.out.display());
            }
            exit::SUCCESS
        }),
    };
    match result {
        Ok(code) => ExitCode::from(code),
        Err(err) => {
            eprintln!("analyze: error: {}", cli::exit::message(&err));
            ExitCode::from(exit::BAD_INPUT)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::error::ErrorKind;

    fn parse(args: &[&str]) -> Result<Cli, clap::Error> {
        Cli::try_parse_from(std::iter::once("analyze").chain(args.iter().copied()))
    }

    /// clap's consistency check, and every example of every `--help` parses as written.
    #[test]
    fn the_command_line_and_its_examples_are_consistent() {
        cli::examples::check_command_line(Cli::command(), |args| Cli::try_parse_from(args).map(drop));
    }

    #[test]
    fn shared_flags_parse_everywhere_and_bad_lines_are_rejected() {
        let cli = parse(&["compare", "out/", "x.mcap", "-f", "json", "--baseline", "one-elbow", "-q"]).unwrap();
        let Command::Compare(a) = cli.command else { panic!() };
        assert_eq!(a.inputs.len(), 2);
        assert_eq!(a.format.format, analyze::Format::Json);
        assert!(cli.verbosity.quiet);
        let cli = parse(&["-v", "summary", "dir/", "-j", "2", "--sort", "E_total_j,err_z_rms_m"]).unwrap();
        assert_eq!(cli.verbosity.verbose, 1);
        let Command::Summary(s) = cli.command else { panic!() };
        assert_eq!((s.jobs.jobs, s.sort.len()), (Some(2), 2));
        let kind = |args: &[&str]| parse(args).unwrap_err().kind();
        assert_eq!(kind(&["compare"]), ErrorKind::MissingRequiredArgument);
        assert_eq!(kind(&["compare", "out", "-f", "xml"]), ErrorKind::InvalidValue);
        assert_eq!(kind(&["comapre", "out"]), ErrorKind::InvalidSubcommand);
        assert_eq!(kind(&["summary", "d", "-j", "0"]), ErrorKind::ValueValidation);
        assert_eq!(kind(&["compare", "out", "-q", "-v"]), ErrorKind::ArgumentConflict);
        assert_eq!(kind(&[]), ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand);
    }

    #[test]
    fn a_misspelled_command_gets_a_suggestion() {
        let e = parse(&["comapre", "out"]).unwrap_err().to_string();
        assert!(e.contains("compare"), "{e}");
    }
}
