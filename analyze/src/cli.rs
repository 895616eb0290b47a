//! The command line of the `analyze` binary (clap derive); `commands.rs` carries it out.

use std::path::PathBuf;

use analyze::Format;
use clap::builder::{PossibleValuesParser, TypedValueParser};
use clap::{Args, Parser, Subcommand};

const EXAMPLES: &str = "\
Examples:
  analyze compare out/                      every out/*.mcap against the run without elbows
  analyze compare out/ --baseline one-elbow --format csv -o table.csv
  analyze compare a.mcap b.mcap --format json
  analyze metrics out/two-elbow.mcap        one run's numbers, no comparison";

const COMPARE_EXAMPLES: &str = "\
Examples:
  analyze compare out/
  analyze compare out/no-elbow.mcap out/one-elbow.mcap out/two-elbow.mcap
  analyze compare out/ --baseline two-elbow --format json -o comparison.json
  analyze compare out/ --format csv > runs.csv";

const METRICS_EXAMPLES: &str = "\
Examples:
  analyze metrics out/two-elbow.mcap
  analyze metrics out/ --format json
  analyze metrics --recover out/.paper-two-elbow.mcap.partial   what a killed run left";

/// Reads recordings of `sim` runs and reports hand error, link work W_j, motor electric
/// energy E_j, contact forces and the energy balance, and compares runs.
#[derive(Debug, Parser)]
#[command(name = "analyze", version, after_help = EXAMPLES)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Compare runs against a baseline: hand error, E and W totals and their ratios, per-link
    /// W_j and E_j, contact forces, energy balance, and findings in plain sentences.
    #[command(after_help = COMPARE_EXAMPLES)]
    Compare(CompareArgs),
    /// Per-run metrics only (no baseline, no findings): one row per recording, so it also merges
    /// the shards of a sweep (`analyze summary results/`).
    #[command(after_help = METRICS_EXAMPLES, visible_alias = "summary")]
    Metrics(MetricsArgs),
}

#[derive(Debug, Args)]
pub struct CompareArgs {
    /// Recordings (.mcap), or directories: every *.mcap directly in them, sorted by name.
    #[arg(required = true, value_name = "FILES_OR_DIRS")]
    pub inputs: Vec<PathBuf>,
    /// The baseline run, by run name, file path or file stem [default: the first run without
    /// contacts, else the first run].
    #[arg(long, value_name = "RUN")]
    pub baseline: Option<String>,
    /// Read what is intact of damaged (e.g. truncated) recordings; see `metrics --help`.
    #[arg(long)]
    pub recover: bool,
    #[command(flatten)]
    pub output: Output,
}

#[derive(Debug, Args)]
pub struct MetricsArgs {
    /// Recordings (.mcap), or directories: every *.mcap directly in them, sorted by name.
    #[arg(required = true, value_name = "FILES_OR_DIRS")]
    pub inputs: Vec<PathBuf>,
    /// Read what is intact of damaged (e.g. truncated) recordings: the messages of every
    /// complete chunk and the metadata before the damage. A warning on stderr names each
    /// damaged file, the byte offset where reading stopped and what was recovered; a run cut
    /// short before its result is reported as status `incomplete`.
    #[arg(long)]
    pub recover: bool,
    #[command(flatten)]
    pub output: Output,
}

#[derive(Debug, Args)]
pub struct Output {
    /// table: aligned text for people; json: every number, stable keys; csv: one row per run.
    #[arg(long, short = 'f', value_name = "FORMAT", default_value_t = Format::default(),
          value_parser = PossibleValuesParser::new(Format::ALL.map(Format::as_str))
              .try_map(|s| s.parse::<Format>()))]
    pub format: Format,
    /// Write to FILE instead of standard output.
    #[arg(long, short = 'o', value_name = "FILE")]
    pub output: Option<PathBuf>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::error::ErrorKind;

    fn parse(args: &[&str]) -> Result<Cli, clap::Error> {
        Cli::try_parse_from(std::iter::once("analyze").chain(args.iter().copied()))
    }

    #[test]
    fn compare_takes_inputs_format_baseline_and_output() {
        let cli = parse(&[
            "compare",
            "out/",
            "x.mcap",
            "--format",
            "json",
            "--baseline",
            "one-elbow",
            "-o",
            "c.json",
        ])
        .unwrap();
        let Command::Compare(a) = cli.command else {
            panic!("{cli:?}")
        };
        assert_eq!(a.inputs, [PathBuf::from("out/"), PathBuf::from("x.mcap")]);
        assert_eq!(a.baseline.as_deref(), Some("one-elbow"));
        assert_eq!(
            (a.output.format, a.output.output),
            (Format::Json, Some(PathBuf::from("c.json")))
        );
    }

    #[test]
    fn defaults_are_table_to_stdout_and_automatic_baseline() {
        let Command::Compare(a) = parse(&["compare", "out"]).unwrap().command else {
            panic!()
        };
        assert_eq!(
            (a.output.format, a.output.output, a.baseline),
            (Format::Table, None, None)
        );
        assert!(matches!(parse(&["summary", "dir/"]).unwrap().command, Command::Metrics(_)));
        let Command::Metrics(m) = parse(&["metrics", "a.mcap", "-f", "csv"]).unwrap().command
        else {
            panic!()
        };
        assert_eq!((m.inputs.len(), m.output.format), (1, Format::Csv));
    }

    #[test]
    fn bad_command_lines_are_rejected() {
        let kind = |args: &[&str]| parse(args).unwrap_err().kind();
        assert_eq!(kind(&["compare"]), ErrorKind::MissingRequiredArgument);
        assert_eq!(kind(&["metrics"]), ErrorKind::MissingRequiredArgument);
        assert_eq!(
            kind(&["compare", "out", "--format", "xml"]),
            ErrorKind::InvalidValue
        );
        assert_eq!(
            kind(&["compare", "out", "--baseline"]),
            ErrorKind::InvalidValue
        );
        assert_eq!(kind(&["plot", "out"]), ErrorKind::InvalidSubcommand);
        assert_eq!(
            kind(&[]),
            ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
        );
    }

    #[test]
    fn help_lists_formats_and_examples() {
        let help = parse(&["compare", "--help"]).unwrap_err().to_string();
        for want in [
            "[possible values: table, json, csv]",
            "[default: table]",
            "--baseline <RUN>",
            "Examples:",
        ] {
            assert!(help.contains(want), "{want:?} not in\n{help}");
        }
        <Cli as clap::CommandFactory>::command().debug_assert();
    }
}
