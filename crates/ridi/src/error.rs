//! Errors of the pipeline: one enum over the layers' errors, plus what only the pipeline can
//! get wrong (a sequence without the labels a stage needs).

use std::path::PathBuf;

/// An error of the end-to-end pipeline.
///
/// Non-exhaustive: features add variants (`Plot` with the `plot` feature).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PipelineError {
    /// Reading or writing data.
    #[error(transparent)]
    Data(#[from] ridi_data::DataError),
    // The layers' errors below print their cause after a prefix and do not also chain it as
    // `source()`: an error prints its cause or chains it, never both (a reporter walking the
    // chain would print it twice).
    /// Features or targets.
    #[error("features: {0}")]
    Features(ridi_features::FeatureError),
    /// Training or prediction.
    #[error("regression: {0}")]
    Regress(ridi_regress::RegressError),
    /// Correction or integration.
    #[error("correction: {0}")]
    Correct(ridi_correct::CorrectError),
    /// Metrics.
    #[error("evaluation: {0}")]
    Eval(ridi_eval::EvalError),
    /// Orientation estimation.
    #[error("orientation: {0}")]
    Orientation(ridi_frames::EstimateError),
    /// The streaming tracker refused a sample or its configuration.
    #[error("tracking: {0}")]
    Track(ridi_correct::TrackError),
    /// A live stream's sample lacks what the model needs.
    #[error("live tracking: {0}")]
    Live(String),
    /// Drawing a plot.
    #[cfg(feature = "plot")]
    #[error("plot: {0}")]
    Plot(crate::plot::PlotError),
    /// A sequence lacks what a stage needs (ground truth, placement, enough frames).
    #[error(
        "sequence `{}`: {}",
        ridi_data::shown(sequence),
        ridi_data::shown(message)
    )]
    Sequence {
        /// Sequence name.
        sequence: String,
        /// What is missing.
        message: String,
    },
    /// The worker threads a run asked for could not be started ([`crate::start_workers`]).
    #[error(
        "cannot start {threads} worker thread{}{}: {reason}",
        if *threads == 1 { "" } else { "s" },
        variable.as_ref().map_or(String::new(), |v| format!(" ({v})"))
    )]
    Workers {
        /// How many were asked for.
        threads: usize,
        /// The variable that asked, as `NAME=value` (none for a count the caller gave).
        variable: Option<String>,
        /// The system's answer, or rayon's (a pool already running).
        reason: String,
    },
    /// A stage was given no sequence at all.
    #[error("no sequences to {0}")]
    NoSequences(&'static str),
    /// The caller cancelled an evaluation (its flag was set, [`crate::evaluate_cancellable`]);
    /// a training cancelled by its progress callback is
    /// `Regress(ridi_regress::RegressError::Cancelled)`.
    #[error("{0} cancelled")]
    Cancelled(&'static str),
    /// An output that cannot be written, or would replace an input ([`crate::OutputError`]).
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
    /// An error about one sequence of a list file, at the list file and line
    /// ([`PipelineError::locate_in`]); it chains the error itself.
    #[error("{at}")]
    Listed {
        /// The list file and line of the sequence.
        at: ridi_data::Location,
        /// The error about the sequence.
        #[source]
        source: Box<PipelineError>,
    },
    /// A file the pipeline writes or reads itself (models, reports, placement maps).
    #[error("{}: {message}", ridi_data::shown(path))]
    File {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

/// `From` for the variants that print their cause (see above).
macro_rules! printed_cause {
    ($($variant:ident($error:ty)),* $(,)?) => {$(
        impl From<$error> for PipelineError {
            fn from(e: $error) -> Self {
                PipelineError::$variant(e)
            }
        }
    )*};
}

printed_cause!(
    Features(ridi_features::FeatureError),
    Regress(ridi_regress::RegressError),
    Correct(ridi_correct::CorrectError),
    Eval(ridi_eval::EvalError),
    Orientation(ridi_frames::EstimateError),
    Track(ridi_correct::TrackError),
);

#[cfg(feature = "plot")]
printed_cause!(Plot(crate::plot::PlotError));

impl PipelineError {
    pub(crate) fn sequence(name: &str, message: impl Into<String>) -> Self {
        PipelineError::Sequence {
            sequence: name.to_string(),
            message: message.into(),
        }
    }
}

/// Result of the pipeline.
pub type Result<T, E = PipelineError> = std::result::Result<T, E>;
