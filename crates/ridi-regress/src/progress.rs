//! Progress reporting hooks for long trainings (the CLI draws progress bars from them).

/// What is being trained.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage<'a> {
    /// One-vs-one placement classifier; steps are class pairs.
    Classifier,
    /// Cross-validated grid search of one placement; steps are single SVR fits
    /// (grid points × folds × 2 channels).
    Grid {
        /// Placement name.
        placement: &'a str,
    },
    /// Final fit of the regressors of one placement (S-x, S-z, and the speed when the cascade
    /// has one); steps are channels.
    Regressors {
        /// Placement name.
        placement: &'a str,
    },
}

/// One progress update: `done` of `total` steps of `stage` are finished.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ProgressEvent<'a> {
    /// Current stage.
    pub stage: Stage<'a>,
    /// Finished steps.
    pub done: usize,
    /// Steps of this stage.
    pub total: usize,
}

/// Receives progress updates, possibly from worker threads (hence `Send`); returning `false`
/// cancels the training, which then fails with [`crate::RegressError::Cancelled`].
pub trait Progress: Send {
    /// Called at the start of each stage (`done == 0`) and after each step.
    fn report(&mut self, event: &ProgressEvent<'_>) -> bool;
}

impl<F: FnMut(&ProgressEvent<'_>) -> bool + Send> Progress for F {
    fn report(&mut self, event: &ProgressEvent<'_>) -> bool {
        self(event)
    }
}

/// Ignores all updates.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn report(&mut self, _event: &ProgressEvent<'_>) -> bool {
        true
    }
}
