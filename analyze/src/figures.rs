//! The paper's figures from recordings, as SVG and PNG, with an index page (`analyze figures`).
//!
//! [`load_run`] reads the series of one recording ([`RunSeries`]); [`write_figures`] draws,
//! for all runs together (one colour per run, the same in every figure):
//!
//! - Fig. 1-3 (`fig01_xy`, `fig02_xz`, `fig03_yz`): the hand path r(t) in the xy, xz and yz
//!   planes, every run over the target path r_d(t) (dashed), equal scales on both axes, a dot
//!   where each path starts (`/hand` `actual`, `desired`);
//! - Fig. 4, 5 (`fig04_work_total`, `fig05_electric_total`): W(t) = Σ_j ∫ τ_j q̇_j dt and
//!   E(t) = Σ_j ∫ i_j v_j dt (`/energy` totals), on a log axis when the runs differ by more
//!   than a decade (the paper's: 114 J with two elbows, 3195 J without);
//! - Fig. 6-25 (`fig06_work_link01` … `fig25_electric_link10`): W_j(t) (even numbers) and
//!   E_j(t) (odd numbers) of link j = 1 … n, as the paper numbers them (Fig. 6 + 2 (j - 1));
//! - and beyond the paper (`extra_*`): motor currents and voltages as small multiples (one
//!   panel per joint, every run in it), the table's normal force on each contact (one panel
//!   per contact, a zero line: f_n < 0, the table pulls), and the hand error |r - r_d|.
//!
//! Drawing conventions (one colour per run in every figure, one line width, dashes only for the
//! target, legend strips, robust and log axes, ticks): [`draw`] and [`scale`]; labels use real
//! sub- and superscripts ([`markup`]); the PNG is rendered from the SVG ([`render`]). A figure
//! whose data no recording has is still written, saying so. [`write_index`] writes `index.md`
//! and `index.html`, every figure in order with its caption.

use std::path::{Path, PathBuf};

use plotters::style::FontStyle;
use schemas::{topics, ConstraintState, EnergyState, HandState, MotorState, Recording, Vec3};

use crate::Error;

mod catalogue;
mod draw;
mod index;
pub mod markup;
mod render;
mod scale;
mod work_precision;

pub use index::write_index;
pub use work_precision::{work_precision, WorkPrecisionSeries};

/// DejaVu Sans (licence beside it in `analyze/assets`): every figure of the project uses it
/// (plotters measures text with it, resvg renders the PNG with it).
static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Registers DejaVu Sans as plotters' "sans-serif" (once), so PNGs look the same everywhere.
fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // an embedded, valid font: registration cannot fail at run time
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// Errors of [`write_figures`].
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FigureError {
    /// Creating the output directory or writing the index failed.
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// Writing the index failed (names the file and the OS reason, or another writer).
    #[error(transparent)]
    Write(Box<schemas::Error>),
    /// plotters could not draw or write a figure.
    #[error("drawing {0}")]
    Draw(String),
}

/// Sample times (s) and one column per array entry (joint or contact).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Series {
    pub t: Vec<f64>,
    pub cols: Vec<Vec<f64>>,
}

impl Series {
    pub fn is_empty(&self) -> bool {
        self.t.is_empty() || self.cols.is_empty()
    }

    /// Appends one row: a longer row than the ones before adds columns (NaN before it, not
    /// drawn); a shorter one leaves NaN in the columns it lacks.
    fn push(&mut self, t: f64, row: &[f64]) {
        let n = self.t.len();
        while self.cols.len() < row.len() {
            self.cols.push(vec![f64::NAN; n]);
        }
        for (j, col) in self.cols.iter_mut().enumerate() {
            col.push(row.get(j).copied().unwrap_or(f64::NAN));
        }
        self.t.push(t);
    }
}

/// What the figures show of one recording. A topic the recording does not have is empty.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunSeries {
    /// Metadata `run.run`, else the file stem.
    pub name: String,
    /// Metadata `run.contacts` (elbow names, in `/constraints` array order); may be empty.
    pub contacts: Vec<String>,
    /// Metadata `run.joint_names` (in the order of the per-joint arrays); may be empty.
    pub joints: Vec<String>,
    /// Hand position r, m: columns x, y, z.
    pub actual: Series,
    /// Target r_d, m: columns x, y, z.
    pub desired: Series,
    /// |r - r_d|, m.
    pub error_norm: Series,
    /// W_j(t), J, one column per link; and the total.
    pub work: Series,
    pub work_total: Series,
    /// E_j(t), J, one column per motor; and the total.
    pub electric: Series,
    pub electric_total: Series,
    /// Motor currents, A, and terminal voltages, V, one column per motor.
    pub current: Series,
    pub voltage: Series,
    /// Normal force on each elbow, N, one column per contact.
    pub normal_force: Series,
}

/// The series of one recording in memory; `fallback_name` names it if it has no `run` record.
/// (Files are read streamed by [`read_run`].)
pub fn load_run(rec: &Recording, fallback_name: &str) -> Result<RunSeries, Error> {
    let mut c = SeriesCollect::default();
    let topics: Vec<&str> = FIGURE_TOPICS.iter().filter(|t| rec.check_topic(t).is_ok()).copied().collect();
    rec.replay(&topics, &mut c)?;
    c.into_series(rec, fallback_name)
}

/// The topics the figures draw.
pub const FIGURE_TOPICS: [&str; 4] = [topics::HAND, topics::ENERGY, topics::MOTORS, topics::CONSTRAINTS];

/// [`RunSeries`] collected as a recording is streamed ([`schemas::Visitor`]): only the drawn
/// numbers are kept (about 50 per sample for the paper arm), not the decoded messages.
#[derive(Default)]
pub struct SeriesCollect(RunSeries);

impl SeriesCollect {
    /// The series, named by the `run` record of `rec` (or `stem` without one).
    pub fn into_series(self, rec: &Recording, stem: &str) -> Result<RunSeries, Error> {
        let run = rec.run_opt()?;
        Ok(RunSeries {
            name: run.as_ref().map_or_else(|| stem.to_string(), |r| r.run.clone()),
            contacts: run.as_ref().map(|r| r.contacts.clone()).unwrap_or_default(),
            joints: run.map(|r| r.joint_names).unwrap_or_default(),
            ..self.0
        })
    }
}

impl schemas::Visitor for SeriesCollect {
    fn message(&mut self, m: schemas::DecodedMessage<'_>) -> Result<(), schemas::Error> {
        let (t, s) = (m.t_s(), &mut self.0);
        let xyz = |v: &Vec3| [v.x, v.y, v.z];
        match m.topic {
            topics::HAND => {
                let h: HandState = m.decode(None)?;
                s.actual.push(t, &xyz(&h.actual));
                s.desired.push(t, &xyz(&h.desired));
                s.error_norm.push(t, &[h.error_norm]);
            }
            topics::ENERGY => {
                let e: EnergyState = m.decode(None)?;
                s.work.push(t, &e.link_work);
                s.work_total.push(t, &[e.link_work_total]);
                s.electric.push(t, &e.electric_energy);
                s.electric_total.push(t, &[e.electric_energy_total]);
            }
            topics::MOTORS => {
                let mo: MotorState = m.decode(None)?;
                s.current.push(t, &mo.current);
                s.voltage.push(t, &mo.voltage);
            }
            topics::CONSTRAINTS => {
                let c: ConstraintState = m.decode(None)?;
                s.normal_force.push(t, &c.normal_force);
            }
            _ => {}
        }
        Ok(())
    }
}

/// Reads a recording file, streamed, into its [`RunSeries`] (named by its file stem if it has
/// no run name): memory is the drawn series, not the recording.
pub fn read_run(path: &Path) -> Result<RunSeries, Error> {
    let mut c = SeriesCollect::default();
    let rec = schemas::stream_recording(path, Some(&FIGURE_TOPICS), &mut c)?;
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    c.into_series(&rec, &stem)
}

/// One written figure: `<stem>.svg` and `<stem>.png` in the output directory.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// The paper's figure number (1-25), `None` for the figures beyond the paper.
    pub number: Option<u32>,
    pub stem: String,
    /// "Fig. 4: All link work, W = Σ ∫ τ q̇ dt", as drawn over the figure, sub- and
    /// superscripts marked ([`markup`]: [`markup::plain`] drops the marks).
    pub caption: String,
    /// One or two sentences for the index page: what is drawn and how to read it.
    pub note: String,
}

/// Draws every figure of `runs` into `dir` (created if needed) and returns them in order.
pub fn write_figures(runs: &[RunSeries], dir: &Path) -> Result<Vec<Figure>, FigureError> {
    register_font();
    std::fs::create_dir_all(dir).map_err(|source| FigureError::Io {
        path: dir.into(),
        source,
    })?;
    let mut out = Vec::new();
    for (figure, plot) in catalogue::plots(runs) {
        draw::write(&plot, &dir.join(&figure.stem)).map_err(FigureError::Draw)?;
        out.push(figure);
    }
    Ok(out)
}

/// [`write_figures`] and [`write_index`] together: the paper's figures from one call.
pub fn write_all(
    runs: &[RunSeries],
    sources: &[PathBuf],
    dir: &Path,
) -> Result<Vec<Figure>, FigureError> {
    let figures = write_figures(runs, dir)?;
    write_index(&figures, runs, sources, dir)?;
    Ok(figures)
}
