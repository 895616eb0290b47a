//! `analyze diff`: two versions' recordings or exported tables, run by run.

use std::path::PathBuf;

use anyhow::Result;
use cli::{exit, print_out, TableFormat};

/// Compare two recordings, directories of recordings or exported tables run by run (matched by
/// run name): hand error, E and W totals, per-link W_j and E_j, currents, contact forces,
/// energy residual, with absolute and relative differences. Exit status 0: nothing moved beyond
/// the tolerances; 1: something moved, is missing on one side, or is carried by one input only,
/// or a directory had `*.mcap` entries that are not files (named on stderr);
/// 2: bad input.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Output: the quantities that moved (--all: every one), with A, B, B - A and the relative
difference, and a last line \"N quantities moved beyond …\" or \"no differences beyond …\";
-f json and -f csv list every quantity, one row each.

Examples:
  analyze diff recordings/paper-archive-two-elbow.mcap out/paper-two-elbow.mcap
  analyze diff old-table.json out/          a table written by `analyze metrics -f json`
  analyze diff a.mcap b.mcap --rtol 1e-6 --all
  analyze diff a.csv b.csv -f json
  analyze diff old.csv new.json --common-only   only what both tables carry")]
pub struct DiffArgs {
    /// A: a recording (.mcap), a directory of recordings, or a table written by
    /// `analyze metrics|compare -f json|csv`.
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
    /// Judge only the quantities both inputs carry (e.g. a CSV table, which has no per-link
    /// peak currents, against a JSON one); by default a quantity one input's table does not
    /// carry is a difference.
    #[arg(long)]
    pub common_only: bool,
    #[command(flatten)]
    pub format: TableFormat,
}

pub fn run(a: &DiffArgs) -> Result<u8> {
    // a directory's `*.mcap` entries that are not files (dangling or looping links,
    // directories, FIFOs) are named, left out and make the exit status 1 (issue 29)
    let mut skipped = 0;
    for input in [&a.a, &a.b].into_iter().filter(|p| p.is_dir()) {
        let e = cli::inputs::expand_all(std::slice::from_ref(input))?;
        e.warn_skipped();
        skipped += e.skipped.len();
    }
    let (left, right) = (analyze::read_input(&a.a)?, analyze::read_input(&a.b)?);
    let tol = analyze::Tolerance { rtol: a.rtol, atol: a.atol };
    let d = analyze::diff::diff(&left, &right, tol)?.common_only(a.common_only);
    print_out(&analyze::render_diff(&d, a.format.format, a.all)?)?;
    Ok(if d.differs() || skipped > 0 { exit::FAILED } else { exit::SUCCESS })
}
