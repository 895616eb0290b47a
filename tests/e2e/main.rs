//! End to end, as a user runs it: the `sim` and `analyze` binaries of this package as processes
//! (exit statuses, messages, files written), and the pipeline sim → recording → analyze through
//! the libraries. One test binary (modules below), so the workspace links it once.

mod analyze_bad_recordings;
mod analyze_cli;
mod analyze_diff;
mod analyze_figures;
mod analyze_tables;
mod cli_voice;
mod format_ownership;
mod pipeline;
mod sampled_energy;
mod sim_bad_input;
mod sim_sweep;
