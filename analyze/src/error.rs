//! The one error type of the library.
//!
//! Every variant about a recording names the file (`file`: the path, or the label the
//! recording was read with) and what is missing or wrong in it, so `analyze` and `sim` can print
//! it as is. Reading errors come from [`schemas::Error`], which names the file, topic and field.

/// Errors from computing, comparing or rendering run metrics.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The recording could not be read, or a topic / field it needs is absent or not numeric
    /// (boxed: the reader's errors carry the file, topic and field, and would make every
    /// `Result` of this crate large).
    #[error(transparent)]
    Read(Box<schemas::Error>),

    /// A metadata record or key the metrics need is absent.
    #[error("{file}: metadata record {record:?} has no key {key:?}")]
    MissingMetadata {
        file: String,
        record: String,
        key: String,
    },

    /// A metadata value does not parse (e.g. `run.contacts` is not a JSON array of strings).
    #[error("{file}: metadata {record}.{key} = {value:?}: {detail}")]
    BadMetadata {
        file: String,
        record: String,
        key: String,
        value: String,
        detail: String,
    },

    /// A contact event that names no contact of the run, or an unknown kind.
    #[error("{file}: /contact_events message {index} at t = {t_s} s: {field} = {value:?}: {detail}")]
    BadEvent {
        file: String,
        index: usize,
        t_s: f64,
        field: &'static str,
        value: String,
        detail: String,
    },

    /// A topic the metrics need has no messages.
    #[error("{file}: topic {topic} has no messages")]
    NoSamples { file: String, topic: String },

    /// An array field has the wrong number of entries for the joints / contacts in the metadata.
    #[error(
        "{file}: topic {topic}, field {field}, message #{index} (t = {t_s} s): \
         {found} entries, expected {expected} (one per {per})"
    )]
    WrongLength {
        file: String,
        topic: String,
        field: String,
        index: usize,
        t_s: f64,
        found: usize,
        expected: usize,
        per: &'static str,
    },

    /// A recorded value the metrics use is NaN or infinite: every peak and sum would be
    /// meaningless, so nothing is computed.
    #[error("{file}: topic {topic}, field {field}, message #{index} (t = {t_s} s): {value} is not a finite number")]
    NonFinite {
        file: String,
        topic: String,
        field: String,
        value: f64,
        index: usize,
        t_s: f64,
    },

    /// A sample is not on the output grid its `run` record states (time scaled, shifted, a gap).
    #[error(
        "{file}: topic {topic}, message #{index}: t = {t_s} s, but the run's output grid \
         ({rate_hz} Hz) puts sample #{index} at {expected_s} s (time scaled, shifted, or samples missing)"
    )]
    OffGrid {
        file: String,
        topic: String,
        index: usize,
        t_s: f64,
        expected_s: f64,
        rate_hz: f64,
    },

    /// A run recorded as complete stops before its duration.
    #[error(
        "{file}: topic {topic}: the run is recorded as complete, but its {samples} samples end at \
         t = {t_end_s} s, before the duration {duration_s} s"
    )]
    ShortRun {
        file: String,
        topic: String,
        samples: usize,
        t_end_s: f64,
        duration_s: f64,
    },

    /// What was recovered from a damaged recording is not enough for the metrics.
    #[error("{report}; what it holds cannot be analysed: {source}")]
    Damaged {
        report: Box<schemas::RecoverReport>,
        #[source]
        source: Box<Error>,
    },

    /// [`crate::Comparison::new`] was given no runs.
    #[error("no runs to compare")]
    NoRuns,

    /// The requested baseline is not the name (or file) of any run.
    #[error("baseline {name:?} is not one of the runs {available:?}")]
    UnknownBaseline {
        name: String,
        available: Vec<String>,
    },

    /// `compare --rank-by`: no compared run has the ranked quantity.
    #[error("--rank-by {by}: nothing to rank: {why}")]
    NothingToRank { by: &'static str, why: String },

    /// The requested baseline failed before its first sample: it has no numbers to divide by.
    #[error("baseline {name:?} ({file}) has no numbers to compare with: {why}; choose another run with --baseline")]
    UnmeasuredBaseline { name: String, file: String, why: String },

    /// Reading or writing a file (export, report) failed.
    #[error("{file}: {op} failed: {source}")]
    Io {
        file: String,
        op: &'static str,
        #[source]
        source: std::io::Error,
    },

    /// Building, querying or writing a table (polars) failed.
    #[error("{file}: {detail}")]
    Table { file: String, detail: String },

    /// The summary's query or table failed (an unknown column, a value that is not a number).
    #[error("summary: {0}")]
    Summary(String),

    /// Tables (`analyze summary`, `analyze export`) need polars: a build with the feature
    /// `tables`.
    #[error("tables need polars: this build has no feature `tables`; build with `cargo build --release --features tables` (or `cargo install --path . --features tables`)")]
    TablesUnavailable,

    /// A recording cannot be drawn (`analyze view`): what is missing or inconsistent in it.
    #[error("{file}: {detail}")]
    View { file: String, detail: String },

    /// `analyze view` needs the feature `rerun` (arrow's IPC writer).
    #[error("`analyze view` needs the feature `rerun`: build with `cargo build --release --features rerun` (or `cargo install --path . --features rerun`)")]
    ViewUnavailable,

    /// Serializing to JSON failed.
    #[error("writing JSON: {0}")]
    Json(#[from] serde_json::Error),
}

impl From<schemas::Error> for Error {
    fn from(e: schemas::Error) -> Self {
        Error::Read(Box::new(e))
    }
}
