//! `analyze`: per-run metrics of recordings and the comparison of runs (the paper's tables).
//!
//! - [`metrics`]: one recording -> [`RunMetrics`] (hand error, W_j and E_j, peak currents,
//!   contact forces, energy audit), read only through the generic reader of `schemas`.
//! - [`compare`]: several [`RunMetrics`] -> [`Comparison`] against a baseline run, with
//!   findings stated as sentences (SCENE.md "The paper's conclusions").
//! - [`render`]: a [`Comparison`] or a list of [`RunMetrics`] as an aligned text table, JSON
//!   or CSV ([`Format`]).
//! - `figures` (feature `figures`, on by default): the paper's Fig. 1-25 and more as SVG and PNG
//!   with an index page, drawn with plotters (`analyze figures`).
//! - `view` (feature `rerun`, off by default): recordings as Rerun `.rrd` files with a
//!   blueprint (`analyze view`).
//!
//! Typical use (what `sim` does after its runs):
//! ```no_run
//! # fn main() -> Result<(), analyze::Error> {
//! let paths = ["out/no-elbow.mcap", "out/two-elbow.mcap"];
//! let runs = paths
//!     .iter()
//!     .map(|p| analyze::read_run_metrics(std::path::Path::new(p)))
//!     .collect::<Result<Vec<_>, _>>()?;
//! let cmp = analyze::Comparison::new(&runs, None)?;
//! print!("{}", analyze::render_comparison(&cmp, analyze::Format::Table)?);
//! # Ok(())
//! # }
//! ```
//!
//! Units are SI; JSON keys carry them as suffixes (`_m`, `_s`, `_j`, `_a`, `_n`).
//! The library depends only on `schemas`, `serde`, `serde_json` and `thiserror` (and `plotters`
//! with the feature `figures`).

pub mod compare;
pub mod diff;
pub mod export;
pub mod filter;
pub mod integrals;
pub mod report;
mod error;
#[cfg(feature = "figures")]
pub mod figures;
#[cfg(feature = "tables")]
pub mod frames;
pub mod summary;
pub mod metrics;
pub mod view;
pub mod render;

pub use compare::{Comparison, RankBy};
pub use diff::{read_input, render_diff, Diff, DiffError, Tolerance};
pub use error::Error;
pub use metrics::{
    read_run_metrics, read_run_metrics_recover, run_metrics, run_metrics_recovered,
    stream_run_metrics, ContactAuditMetrics, LimitsMetrics, Reductions, RunMetrics, Status,
};
pub use render::{render_comparison, render_comparison_brief, render_comparison_fitted, render_metrics, render_metrics_fitted, Format};
pub use schemas::RecoverReport;
