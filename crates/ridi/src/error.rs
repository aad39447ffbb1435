//! Errors of the pipeline: one enum over the layers' errors, plus what only the pipeline can
//! get wrong (a sequence without the labels a stage needs).

use std::path::PathBuf;

/// An error of the end-to-end pipeline.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// Reading or writing data.
    #[error(transparent)]
    Data(#[from] ridi_data::DataError),
    /// Features or targets.
    #[error("features: {0}")]
    Features(#[from] ridi_features::FeatureError),
    /// Training or prediction.
    #[error("regression: {0}")]
    Regress(#[from] ridi_regress::RegressError),
    /// Correction or integration.
    #[error("correction: {0}")]
    Correct(#[from] ridi_correct::CorrectError),
    /// Metrics.
    #[error("evaluation: {0}")]
    Eval(#[from] ridi_eval::EvalError),
    /// Orientation estimation.
    #[error("orientation: {0}")]
    Orientation(#[from] ridi_frames::EstimateError),
    /// The streaming tracker refused a sample or its configuration.
    #[error("tracking: {0}")]
    Track(#[from] ridi_correct::TrackError),
    /// A live stream's sample lacks what the model needs.
    #[error("live tracking: {0}")]
    Live(String),
    /// Drawing a plot.
    #[error("plot: {0}")]
    Plot(#[from] crate::plot::PlotError),
    /// A sequence lacks what a stage needs (ground truth, placement, enough frames).
    #[error("sequence `{sequence}`: {message}")]
    Sequence {
        /// Sequence name.
        sequence: String,
        /// What is missing.
        message: String,
    },
    /// A stage was given no sequence at all.
    #[error("no sequences to {0}")]
    NoSequences(&'static str),
    /// A file the pipeline writes or reads itself (models, reports, placement maps).
    #[error("{}: {message}", path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

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
