//! The flags both tools share, with the same short and long names and the same meaning:
//!
//! | flag | meaning |
//! |---|---|
//! | `-f, --format table\|json\|csv` | how a command prints its table on standard output |
//! | `-o, --out DIR` | the directory a command writes its files into |
//! | `-j, --jobs N` | worker threads (default: one per core); results never depend on it |
//! | `-q, --quiet` | no progress bars or notes on standard error |
//! | `-v, --verbose` | more detail on standard error (repeat for more); `sim`'s comparison in full |
//!
//! Tables always go to standard output (redirect to save them); files always go into `-o DIR`.

use analyze::Format;
use clap::builder::{PossibleValuesParser, TypedValueParser};

/// `-q` / `-v`, accepted before or after the subcommand.
#[derive(Debug, Clone, Copy, Default, clap::Args)]
pub struct Verbosity {
    /// No progress bars or notes on standard error (errors are still printed).
    #[arg(short, long, global = true, conflicts_with = "verbose")]
    pub quiet: bool,
    /// More detail: on standard error each run's solver work and timing, each file read; on
    /// standard output `sim`'s comparison in full (every table and finding), not the brief one.
    #[arg(short, long, global = true, action = clap::ArgAction::Count)]
    pub verbose: u8,
}

/// `-f/--format`: how a table is printed.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct TableFormat {
    /// table: aligned text for people; json: every number, stable keys; csv: one row per run.
    #[arg(short = 'f', long = "format", value_name = "FORMAT", default_value_t = Format::default(),
          value_parser = PossibleValuesParser::new(Format::ALL.map(Format::as_str)).try_map(|s| s.parse::<Format>()))]
    pub format: Format,
}

/// `-j/--jobs`: worker threads.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct Jobs {
    /// Worker threads [default: one per core]; results do not depend on it.
    #[arg(short = 'j', long = "jobs", value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub jobs: Option<u16>,
}

impl Jobs {
    /// The number of threads to use for `work` items (at least 1, at most `work`).
    pub fn threads(&self, work: usize) -> usize {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        self.jobs.map_or(cores, usize::from).clamp(1, work.max(1))
    }
}

/// The version both tools print: the package version and the git commit of the build.
pub const VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), " (commit ", env!("ELBOW_GIT_COMMIT"), ")");
