//! Exit statuses, the same in both tools.
//!
//! - [`SUCCESS`] (0): done, and nothing to report.
//! - [`FAILED`] (1): the work ran to its end but its result is a failure the caller must see: a
//!   run stopped numerically (its recording says when and why), `analyze diff` found
//!   differences, unreadable recordings were left out with `--skip-bad`.
//! - [`BAD_INPUT`] (2): bad input, nothing (more) done: the command line (clap's own status), a
//!   scene or URDF, an unreadable recording, an I/O error.

pub const SUCCESS: u8 = 0;
pub const FAILED: u8 = 1;
pub const BAD_INPUT: u8 = 2;
