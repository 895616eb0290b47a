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
mod study;
mod work_precision;

pub use index::write_index;
pub use study::{pareto_front, study_figure, Mark, StudySeries};
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

/// Rows a [`Series`] keeps at most (16 384): a figure is at most a few thousand pixels wide, so
/// this is several rows per pixel column. A run of up to this many samples (the paper's 5 s at
/// 1 kHz: 5 001) is kept sample for sample; a longer one is decimated as it is read.
pub const MAX_ROWS: usize = 1 << 14;

/// Sample times (s) and one column per array entry (joint or contact).
///
/// Memory is bounded by [`MAX_ROWS`], not by the recording: past it the series is min-max
/// decimated as it is read, as plotting libraries do for long signals (M4 / min-max
/// decimation, Jugel et al., "M4: a visualization-oriented time series data aggregation",
/// VLDB 2014): consecutive samples are grouped into buckets of `stride` samples (a power of two,
/// doubled whenever the rows would pass [`MAX_ROWS`]), and each bucket keeps two rows, at its
/// first and last sample time, holding per column its smallest and largest value in the order
/// they occurred. Every peak and trough stays visible; a line moves by less than a bucket
/// (under one pixel column) in time. [`Series::finish`] adds the last, partial bucket.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Series {
    pub t: Vec<f64>,
    pub cols: Vec<Vec<f64>>,
    /// Samples per bucket: 1 while the series is kept sample for sample.
    stride: usize,
    /// The bucket being filled (decimated series only).
    pending: Option<Bucket>,
}

/// Samples of one bucket, reduced: times of its first and last sample and, per column, the
/// extremes with their sample index.
#[derive(Debug, Clone, PartialEq)]
struct Bucket {
    count: usize,
    t_first: f64,
    t_last: f64,
    /// Per column: `(min, index of min, max, index of max)`, NaN when every value was NaN.
    extremes: Vec<(f64, usize, f64, usize)>,
}

impl Bucket {
    fn new(t: f64) -> Self {
        Bucket { count: 0, t_first: t, t_last: t, extremes: Vec::new() }
    }

    fn add(&mut self, t: f64, row: impl Iterator<Item = f64>, width: usize) {
        while self.extremes.len() < width {
            self.extremes.push((f64::NAN, 0, f64::NAN, 0));
        }
        for (e, v) in self.extremes.iter_mut().zip(row.chain(std::iter::repeat(f64::NAN))) {
            if !v.is_nan() {
                if e.0.is_nan() || v < e.0 {
                    (e.0, e.1) = (v, self.count);
                }
                if e.2.is_nan() || v > e.2 {
                    (e.2, e.3) = (v, self.count);
                }
            }
        }
        self.t_last = t;
        self.count += 1;
    }

    /// The bucket's rows: `(t, values)`, one row for a single sample, else two.
    fn rows(&self) -> Vec<(f64, Vec<f64>)> {
        let first: Vec<f64> = self.extremes.iter().map(|e| if e.1 <= e.3 { e.0 } else { e.2 }).collect();
        if self.count == 1 {
            return vec![(self.t_first, first)];
        }
        let last: Vec<f64> = self.extremes.iter().map(|e| if e.1 <= e.3 { e.2 } else { e.0 }).collect();
        vec![(self.t_first, first), (self.t_last, last)]
    }
}

impl Series {
    pub fn is_empty(&self) -> bool {
        self.t.is_empty() || self.cols.is_empty()
    }

    /// Appends one row: a longer row than the ones before adds columns (NaN before it, not
    /// drawn); a shorter one leaves NaN in the columns it lacks. Past [`MAX_ROWS`] rows, the
    /// row goes into the current bucket (see [`Series`]).
    fn push(&mut self, t: f64, row: &[f64]) {
        let n = self.t.len();
        while self.cols.len() < row.len() {
            self.cols.push(vec![f64::NAN; n]);
        }
        if self.stride <= 1 {
            self.push_row(t, row.iter().copied());
            if self.t.len() >= MAX_ROWS {
                // every two rows are a bucket of two samples: merge pairs of them
                self.stride = 2;
                self.compact();
            }
            return;
        }
        let width = self.cols.len();
        let b = self.pending.get_or_insert_with(|| Bucket::new(t));
        b.add(t, row.iter().copied(), width);
        if b.count == self.stride {
            let b = self.pending.take().expect("a bucket");
            for (t, r) in b.rows() {
                self.push_row(t, r.into_iter());
            }
            if self.t.len() >= MAX_ROWS {
                self.compact();
            }
        }
    }

    fn push_row(&mut self, t: f64, row: impl Iterator<Item = f64>) {
        for (col, v) in self.cols.iter_mut().zip(row.chain(std::iter::repeat(f64::NAN))) {
            col.push(v);
        }
        self.t.push(t);
    }

    /// Merges each two consecutive buckets (four rows) into one (two rows: per column the
    /// extremes of the four in time order) and doubles the stride.
    fn compact(&mut self) {
        let rows = self.t.len() / 4 * 4;
        let width = self.cols.len();
        let mut t = Vec::with_capacity(MAX_ROWS);
        let mut cols: Vec<Vec<f64>> = (0..width).map(|_| Vec::with_capacity(MAX_ROWS)).collect();
        for start in (0..rows).step_by(4) {
            let mut b = Bucket::new(self.t[start]);
            for k in start..start + 4 {
                b.add(self.t[k], self.cols.iter().map(|c| c[k]), width);
            }
            for (tk, r) in b.rows() {
                t.push(tk);
                for (c, v) in cols.iter_mut().zip(r) {
                    c.push(v);
                }
            }
        }
        // rows that do not make a whole pair of buckets stay as they are
        for k in rows..self.t.len() {
            t.push(self.t[k]);
            for (c, src) in cols.iter_mut().zip(&self.cols) {
                c.push(src[k]);
            }
        }
        (self.t, self.cols) = (t, cols);
        self.stride *= 2;
    }

    /// Adds the partial bucket, if any (called once the series is read).
    pub fn finish(&mut self) {
        if let Some(b) = self.pending.take() {
            for (t, r) in b.rows() {
                self.push_row(t, r.into_iter());
            }
        }
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
    /// The run's status and reason (record `result`), when the recording has one: a failed
    /// run is drawn with what it recorded (nothing, when it failed at t = 0).
    pub result: Option<schemas::RunResult>,
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
    pub fn into_series(mut self, rec: &Recording, stem: &str) -> Result<RunSeries, Error> {
        let s = &mut self.0;
        for series in [
            &mut s.actual,
            &mut s.desired,
            &mut s.error_norm,
            &mut s.work,
            &mut s.work_total,
            &mut s.electric,
            &mut s.electric_total,
            &mut s.current,
            &mut s.voltage,
            &mut s.normal_force,
        ] {
            series.finish();
        }
        let run = rec.run_opt()?;
        let result = rec.result()?;
        Ok(RunSeries {
            result,
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A series of up to [`MAX_ROWS`] samples is kept sample for sample; a million samples are
    /// kept in at most [`MAX_ROWS`] rows, in time order from the first sample to the last, with
    /// the one spike and the one trough exactly, and every bucket's rows within the range of the
    /// samples it stands for (sin 2πt sampled at 1 kHz: the decimated line's extremes over a
    /// second are exactly those of the samples).
    #[test]
    fn long_series_are_min_max_decimated_keeping_peaks() {
        let f = |k: usize| match k {
            123_456 => -100.0,
            777_777 => 100.0,
            _ => (2.0 * std::f64::consts::PI * k as f64 * 1e-3).sin(),
        };
        let mut short = Series::default();
        for k in 0..MAX_ROWS - 1 {
            short.push(k as f64 * 1e-3, &[f(k), 2.0]);
        }
        short.finish();
        assert_eq!(short.t.len(), MAX_ROWS - 1);
        assert!(short.t.iter().enumerate().all(|(k, &t)| t == k as f64 * 1e-3 && short.cols[0][k] == f(k)));

        let n = 1_000_000;
        let mut s = Series::default();
        for k in 0..n {
            s.push(k as f64 * 1e-3, &[f(k), 2.0]);
        }
        s.finish();
        assert!(s.t.len() <= MAX_ROWS + 2 && s.t.len() > MAX_ROWS / 4, "{} rows", s.t.len());
        assert_eq!((s.t[0], *s.t.last().unwrap()), (0.0, (n - 1) as f64 * 1e-3));
        assert!(s.t.windows(2).all(|w| w[0] <= w[1]), "times out of order");
        let max = s.cols[0].iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let min = s.cols[0].iter().copied().fold(f64::INFINITY, f64::min);
        assert_eq!((min, max), (-100.0, 100.0));
        assert!(s.cols[1].iter().all(|&v| v == 2.0));
        // each whole second (away from the spikes): the decimated extremes are the samples'
        for sec in [1usize, 10, 500, 900] {
            let (lo, hi) = (sec as f64, sec as f64 + 1.0);
            let rows: Vec<f64> = (0..s.t.len()).filter(|&k| s.t[k] >= lo && s.t[k] < hi).map(|k| s.cols[0][k]).collect();
            let raw: Vec<f64> = (sec * 1000..(sec + 1) * 1000).map(f).collect();
            let ext = |v: &[f64]| (v.iter().copied().fold(f64::INFINITY, f64::min), v.iter().copied().fold(f64::NEG_INFINITY, f64::max));
            let (dmin, dmax) = ext(&rows);
            let (rmin, rmax) = ext(&raw);
            // the extremes sit mid-second (t = .25, .75), inside their buckets
            assert_eq!((dmin, dmax), (rmin, rmax), "second {sec}");
        }
    }
}
