//! End to end, as a user runs it: the `sim` and `analyze` binaries of this package as processes
//! (exit statuses, messages, files written), and the pipeline sim → recording → analyze through
//! the libraries. One test binary (modules below), so the workspace links it once.

mod analyze_bad_recordings;
mod analyze_cli;
mod analyze_diff;
mod analyze_figures;
mod analyze_tables;
mod bounded_memory;
mod cli_voice;
mod contact_audit;
mod docs_book;
mod every_reader;
mod format_ownership;
mod foxglove_layout;
mod live;
mod pipeline;
mod recover_crash;
mod rerun_contact_shapes;
mod rerun_meshes;
mod rerun_view;
mod sampled_energy;
mod scene_schema;
mod sim_bad_input;
mod sim_list;
mod sim_optimize;
mod sim_output;
mod sim_sweep;
mod sim_table;
mod skip;
mod test_binaries;

/// Runs `analyze` with `args`.
fn run_analyze<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_analyze")).args(args).output().expect("analyze starts")
}

/// Runs `sim` with `args`.
fn run_sim<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_sim")).args(args).output().expect("sim starts")
}
