//! `cli`: the command-line voice shared by the two tools, `sim` and `analyze` (the binaries of
//! this package). Everything a user sees the same way in both lives here, once: the output
//! flags (`-f/--format`, `-o/--output`), the exit statuses, writing to stdout or a file, the
//! progress bars, the inputs (files, directories, globs) and the version string.
//!
//! The libraries (`sim`, `analyze`, `schemas`) know nothing of the command line; the binaries
//! compose them (README, "Layout").

pub mod args;
pub mod examples;
pub mod exit;
pub mod extras;
pub mod inputs;
pub mod output;
pub mod progress;

pub use args::{Jobs, TableFormat, Verbosity, VERSION};
pub use output::{create_dir, print_out, terminal_width, write_file, TEXT_WIDTH};
