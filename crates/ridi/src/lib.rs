//! RIDI in Rust: the layers of ridi-rs re-exported, and the end-to-end pipeline.
//!
//! Each stage is its own crate and can be used alone; this crate ties them together:
//!
//! | module | crate | what |
//! | --- | --- | --- |
//! | [`frames`] | `ridi-frames` | frames W, I, S; typed vectors and rotations; gravity alignment |
//! | [`data`] | `ridi-data` | the `Sequence` model, dataset readers and writers |
//! | [`features`] | `ridi-features` | smoothing, feature windows, velocity targets |
//! | [`regress`] | `ridi-regress` | placement SVM and velocity SVRs |
//! | [`correct`] | `ridi-correct` | bias correction, integration, streaming tracker |
//! | [`eval`] | `ridi-eval` | alignment, MPE/ATE/RTE, reports |
//!
//! Pipeline modules: [`source`] reads any supported layout, [`convert`] writes the RIDI
//! layout with list files (all or nothing, through [`staging`]), [`lists`] reads list files
//! for training and evaluation with the labels they need, [`inspect`] summarizes a recording or a model,
//! [`orientation`] swaps in an orientation estimated from gyro and accelerometer, [`live`]
//! tracks a stream sample by sample.

pub use ridi_correct as correct;
pub use ridi_data as data;
pub use ridi_eval as eval;
pub use ridi_features as features;
pub use ridi_frames as frames;
pub use ridi_regress as regress;

pub mod baselines;
pub mod convert;
mod error;
pub mod evaluate;
pub mod inspect;
pub mod lists;
pub mod live;
pub mod orientation;
pub mod placement;
pub mod plot;
pub mod source;
pub mod staging;
pub mod track;
pub mod train;

pub use baselines::Method;
pub use error::{PipelineError, Result};
pub use evaluate::{EvalOptions, Report, evaluate};
pub use lists::{Purpose, load_lists};
pub use live::{LiveSample, LiveTracker, Recorded};
pub use orientation::{Orientation, apply_orientation, oriented};
pub use placement::PlacementMap;
pub use source::{Loaded, read_any};
pub use track::{Track, TrackOptions, track};
pub use train::{GridChoice, TrainOptions, train};

/// The README's Rust example, compiled by `cargo test --doc` so that it cannot drift from the API.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
struct ReadmeDoctests;
