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
  analyze metrics out/two-elbow.mcap        one run's numbers, no comparison
  analyze report out/ -o out/report         the comparison as a document, with the figures
  analyze summary 'results/*.mcap' --sort E_j  hundreds of runs as one table
  analyze export out/ -o tables/            every topic as Parquet, for Python
  analyze diff old/ new/                    what moved between two versions";

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

const FIGURES_EXAMPLES: &str = "\
Examples:
  analyze figures out/                      the paper's Fig. 1-25 and more -> out/figures/
  analyze figures out/ -o paper-figures     then open paper-figures/index.html (or index.md)
  analyze figures out/paper-no-elbow.mcap out/paper-two-elbow.mcap -o two-runs";

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
    /// Per-run metrics only (no baseline, no findings), every number of each run; for many runs
    /// as one filterable table use `summary`.
    #[command(after_help = METRICS_EXAMPLES)]
    Metrics(MetricsArgs),
    /// One table of many runs (hundreds of recordings, read in parallel): one row per
    /// recording with its hand error, energy totals, per-link E_j and W_j, peak current, contact
    /// forces, energy residual and chosen scene parameters; filter, sort and pick columns
    /// (polars). Merges the shards of a sweep.
    #[command(after_help = SUMMARY_EXAMPLES)]
    Summary(SummaryArgs),
    /// Every topic of recordings as tables for Python and spreadsheets: one Parquet or CSV file
    /// per topic (time column `t` in s, one column per field, arrays expanded per joint or
    /// contact name) and metadata.json, in OUT/<recording name>/.
    #[command(after_help = EXPORT_EXAMPLES)]
    Export(ExportArgs),
    /// Compare two recordings or exported tables run by run (matched by run name): hand error,
    /// E and W totals, per-link W_j and E_j, currents, contact forces, energy residual, with
    /// absolute and relative differences. Exit status 0: nothing moved beyond the tolerances;
    /// 1: something moved (or is missing on one side); 2: bad input. `--format json`
    /// and `csv` list every quantity (one row each).
    #[command(after_help = "Examples:
  analyze diff old/run.mcap new/run.mcap          one run against itself, or another version
  analyze diff old-table.json out/                a table exported by `analyze metrics -f json`
  analyze diff a.mcap b.mcap --rtol 1e-6 --all    looser, and list every quantity
  analyze diff a.csv b.csv --format json")]
    Diff(DiffArgs),
    /// The comparison report as one Markdown document: what stands out, the tables (hand
    /// error, energy totals and per link with ratios to the baseline, contacts), the energy
    /// audit (electric energy in; kinetic, potential, magnetic stored; R, D and D_m losses;
    /// residual; the integrals rechecked from the samples) and the figures.
    #[command(after_help = "Examples:
  analyze report out/                           -> out/report/report.md and out/report/figures/
  analyze report out/ --baseline one-elbow -o review
  analyze report a.mcap b.mcap --no-figures -o r")]
    Report(ReportArgs),
    /// The paper's figures (hand paths Fig. 1-3, total and per-link work and electric energy
    /// Fig. 4-25) and more (currents, voltages, elbow normal forces, hand error), every run in
    /// each, as SVG and PNG, with index.md and index.html listing them in order.
    #[command(after_help = FIGURES_EXAMPLES)]
    Figures(FiguresArgs),
}

#[derive(Debug, Args)]
pub struct ReportArgs {
    /// Recordings (.mcap), or directories: every *.mcap directly in them, sorted by name.
    #[arg(required = true, value_name = "FILES_OR_DIRS")]
    pub inputs: Vec<PathBuf>,
    /// The baseline run, by run name, file path or file stem [default: the first run without
    /// contacts, else the first run].
    #[arg(long, value_name = "RUN")]
    pub baseline: Option<String>,
    /// Directory for report.md and its figures/ (created if needed).
    #[arg(long, short = 'o', value_name = "DIR", default_value = "out/report")]
    pub output: PathBuf,
    /// Leave out the figures (faster; the report then has tables only).
    #[arg(long)]
    pub no_figures: bool,
    /// The energy integrals are rechecked from the samples over the whole run and from this
    /// time on, s (after the start-up transient, which is faster than the output step).
    #[arg(long, value_name = "SECONDS", default_value_t = 0.05)]
    pub check_from: f64,
}

#[derive(Debug, Args)]
pub struct FiguresArgs {
    /// Recordings (.mcap), or directories: every *.mcap directly in them, sorted by name.
    #[arg(required = true, value_name = "FILES_OR_DIRS")]
    pub inputs: Vec<PathBuf>,
    /// Directory to write the figures and index pages to (created if needed).
    #[arg(long, short = 'o', value_name = "DIR", default_value = "out/figures")]
    pub output: PathBuf,
}

#[derive(Debug, Args)]
pub struct DiffArgs {
    /// A: a recording (.mcap), a directory of recordings, or a table exported by
    /// `analyze metrics|compare --format json|csv`.
    #[arg(value_name = "A")]
    pub a: PathBuf,
    /// B: the same kinds of input as A.
    #[arg(value_name = "B")]
    pub b: PathBuf,
    /// Relative tolerance: a quantity moved when |B - A| > atol + rtol * max(|A|, |B|).
    #[arg(long, value_name = "RTOL", default_value = "1e-9")]
    pub rtol: f64,
    /// Absolute tolerance (in the quantity's SI unit).
    #[arg(long, value_name = "ATOL", default_value = "1e-12")]
    pub atol: f64,
    /// List every compared quantity in the table, not only those that moved.
    #[arg(long)]
    pub all: bool,
    #[command(flatten)]
    pub output: Output,
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

const SUMMARY_EXAMPLES: &str = "\
Examples:
  analyze summary results/                            every results/*.mcap
  analyze summary 'results/**/*.mcap' -j 8            a quoted glob, 8 reader threads
  analyze summary results/ --param controller.kp --param controller.kd --sort E_j
  analyze summary results/ --filter 'z_rms_m<0.02' --filter run=two-elbow --sort E_j --desc
  analyze summary results/ --columns file,run,E_j,z_rms_m --limit 10
  analyze summary results/ --format csv -o runs.csv   every column (per link too)

Columns (SI units, suffix = unit): file scene run status contacts n_contacts integrator t_end_s
samples hand_rms_m hand_max_m z_rms_m z_max_m E_j W_j peak_current_a peak_current_joint
min_normal_force_n pull_time_s residual_rel error bytes, E.<joint>_j and W.<joint>_j per link,
p.<path> per --param. The text table shows a readable subset unless --columns is given.";

const EXPORT_EXAMPLES: &str = "\
Examples:
  analyze export out/paper-two-elbow.mcap -o tables/       -> tables/paper-two-elbow/*.parquet
  analyze export out/ --format csv -o tables/              every recording, CSV
  analyze export run.mcap --topics /motors,/energy -o t/   only these topics

In Python: pandas.read_parquet('tables/paper-two-elbow/motors.parquet')";

#[derive(Debug, Args)]
pub struct SummaryArgs {
    /// Recordings (.mcap), directories (every *.mcap directly in them) or glob patterns
    /// (quote them: 'results/**/*.mcap'); sorted by path, duplicates removed.
    #[arg(required = true, value_name = "FILES_DIRS_OR_GLOBS")]
    pub inputs: Vec<String>,
    /// Add the scene parameter at this dot path of the scene JSON stored in each recording as
    /// a column `p.<PATH>` (e.g. controller.kp, motors.0.R); repeatable.
    #[arg(long = "param", value_name = "PATH")]
    pub params: Vec<String>,
    /// Keep rows where COLUMN OP VALUE holds, OP one of = != < <= > >= (numbers compare as
    /// numbers); repeatable, all must hold. E.g. 'z_rms_m<0.02', run=two-elbow.
    #[arg(long = "filter", value_name = "COND", value_parser = parse_filter)]
    pub filters: Vec<analyze::filter::Filter>,
    /// Sort by these columns (comma-separated), ascending unless --desc [default: by file].
    #[arg(long, value_name = "COLUMNS", value_delimiter = ',')]
    pub sort: Vec<String>,
    /// Sort descending.
    #[arg(long)]
    pub desc: bool,
    /// Show only these columns, in this order (comma-separated) [default: all for json and
    /// csv; a readable subset for the table].
    #[arg(long, value_name = "COLUMNS", value_delimiter = ',')]
    pub columns: Vec<String>,
    /// Show at most N rows (after filtering and sorting).
    #[arg(long, value_name = "N")]
    pub limit: Option<usize>,
    /// Reader threads [default: one per core].
    #[arg(long, short = 'j', value_name = "N", default_value_t = 0)]
    pub jobs: usize,
    /// Leave out recordings that cannot be read (each is named on stderr) instead of stopping
    /// at the first; the exit status is still 1 if any was left out.
    #[arg(long)]
    pub skip_bad: bool,
    #[command(flatten)]
    pub output: Output,
}

fn parse_filter(s: &str) -> Result<analyze::filter::Filter, String> {
    s.parse()
}

/// Table file format of `analyze export`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ExportFormat {
    Parquet,
    Csv,
}

#[derive(Debug, Args)]
pub struct ExportArgs {
    /// Recordings (.mcap), or directories: every *.mcap directly in them, sorted by name.
    #[arg(required = true, value_name = "FILES_OR_DIRS")]
    pub inputs: Vec<PathBuf>,
    /// Output directory; each recording goes to OUT/<its file stem>/.
    #[arg(long, short = 'o', value_name = "OUT", default_value = "out/tables")]
    pub output: PathBuf,
    /// File format of the tables.
    #[arg(long, short = 'f', value_name = "FORMAT", default_value = "parquet")]
    pub format: ExportFormat,
    /// Only these topics (comma-separated, e.g. /motors,/energy) [default: every decoded topic].
    #[arg(long, value_name = "TOPICS", value_delimiter = ',')]
    pub topics: Vec<String>,
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
        assert!(matches!(parse(&["summary", "dir/"]).unwrap().command, Command::Summary(_)));
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
    fn figures_takes_inputs_and_an_output_directory() {
        let Command::Figures(a) = parse(&["figures", "out/", "b.mcap", "-o", "figs"])
            .unwrap()
            .command
        else {
            panic!()
        };
        assert_eq!(a.inputs, [PathBuf::from("out/"), PathBuf::from("b.mcap")]);
        assert_eq!(a.output, PathBuf::from("figs"));
        let Command::Figures(a) = parse(&["figures", "out"]).unwrap().command else {
            panic!()
        };
        assert_eq!(a.output, PathBuf::from("out/figures"));
        assert_eq!(
            parse(&["figures"]).unwrap_err().kind(),
            ErrorKind::MissingRequiredArgument
        );
    }

    #[test]
    fn diff_takes_two_inputs_and_tolerances() {
        let Command::Diff(a) = parse(&["diff", "a.mcap", "t.json"]).unwrap().command else {
            panic!()
        };
        assert_eq!(
            (a.a, a.b),
            (PathBuf::from("a.mcap"), PathBuf::from("t.json"))
        );
        assert_eq!(
            (a.rtol, a.atol, a.all, a.output.format),
            (1e-9, 1e-12, false, Format::Table)
        );
        let cli = parse(&[
            "diff", "a", "b", "--rtol", "0.02", "--atol", "1e-6", "--all", "-f", "json",
        ]);
        let Command::Diff(a) = cli.unwrap().command else {
            panic!()
        };
        assert_eq!(
            (a.rtol, a.atol, a.all, a.output.format),
            (0.02, 1e-6, true, Format::Json)
        );
        let kind = |args: &[&str]| parse(args).unwrap_err().kind();
        assert_eq!(kind(&["diff", "a"]), ErrorKind::MissingRequiredArgument);
        assert_eq!(kind(&["diff", "a", "b", "--rtol", "x"]), ErrorKind::ValueValidation);
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
