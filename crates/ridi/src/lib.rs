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
//! The pipeline, every item at the crate root (its modules are private, so each item has one
//! path): [`read_any`] reads any supported layout, [`convert()`] writes the RIDI layout with
//! list files (all or nothing, through [`Staging`]), [`load_listed`] reads the sequences of
//! list files for training and evaluation with the labels they need, [`inspect()`] and
//! [`inspect_model`] summarize a recording or a model, [`oriented`] swaps in an orientation
//! estimated from gyro and accelerometer, [`train()`], [`track()`] and [`evaluate()`] are the
//! three stages, [`LiveTracker`] tracks a stream sample by sample, [`Demo`] is `ridi demo`
//! (train on a sample, evaluate on its held-out runs, write both). The one public module is
//! `plot` (feature `plot`, on by default): figures are an optional sub-API with its own
//! error type.
//!
//! # Design decisions
//!
//! - **The model decides what a sequence must look like.** A trained [`regress::Cascade`]
//!   carries its feature configuration (window, S definition, orientation recorded or
//!   estimated); training, tracking and evaluation all pass a sequence through [`oriented`]
//!   and derive the correction's S from the model ([`TrackOptions::correction_for`]), so a
//!   model cannot be applied to features it was not trained on.
//! - **Online and live tracking are one code path.** `ridi track --online` and [`track()`] with
//!   [`TrackOptions::online`] feed a recording through [`LiveTracker`] sample by sample, so the
//!   streaming poses a program gets are the ones the command line tests. A recording whose
//!   orientation was estimated before (`ridi track` estimates it once, for its plot) streams
//!   with that orientation; the estimator and heading correction of the stream give the same
//!   one bit for bit, which the tests hold.
//! - **Outputs are checked first and written all or nothing, here.** An output is refused
//!   before any work when it cannot be written or would replace an input
//!   ([`check_output_file`], [`check_output_folder`], [`check_not_input`]); a command's files
//!   replace the old ones together or not at all ([`TrackOutput`], [`EvalFolder`] through
//!   [`Staging`]); every file goes through [`data::write_atomically`], with one permission
//!   mode. This is library policy, so that the `ridi` command line holds only its arguments,
//!   progress and exit codes, and a program using the library writes as it does.
//! - **Plots are optional.** The `plot` feature (on by default) brings plotters and an embedded
//!   font; an embedded tracker leaves it out with `default-features = false`.
//! - **A model ships with the crate.** The `bundled-model` feature (on by default) embeds a
//!   compact model trained on every shared Tyrex run ([`bundled_model`]), which the command
//!   line uses when no model is given.
//!
//! # Example
//!
//! Train on one person of the bundled sample, track and evaluate another's run:
//!
//! ```
//! use ridi::data::{Listed, ReadOptions};
//! use ridi::regress::NoProgress;
//! use ridi::{EvalOptions, GridChoice, PlacementMap, TrackOptions, TrainOptions};
//!
//! let sample = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../datasets/sample");
//! let read = |list: &str| Listed::read(&[sample.join(list)], &ReadOptions::default());
//! let mut train = read("list_Guillaume.txt")?.into_sequences();
//! PlacementMap::tyrex4().apply(&mut train);
//! let mut opts = TrainOptions::default();
//! opts.cascade.regressors = GridChoice::None.regressors(); // fixed C and epsilon: fast
//! let model = ridi::train(&train, &opts, &mut NoProgress)?;
//!
//! let mut test = read("list_Jakob.txt")?.into_sequences();
//! PlacementMap::tyrex4().apply(&mut test);
//! let track = ridi::track(&test[0], &model, &TrackOptions::default())?;
//! assert_eq!(track.position.len(), test[0].len());
//!
//! let (report, _) = ridi::evaluate(&test[..2], &model, &EvalOptions::default())?;
//! println!("RIDI RTE 5 s: {:.2} m", report.summary["ridi"].rte_5s_m);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub use ridi_correct as correct;
pub use ridi_data as data;
pub use ridi_eval as eval;
pub use ridi_features as features;
pub use ridi_frames as frames;
pub use ridi_regress as regress;

mod baselines;
#[cfg(feature = "bundled-model")]
mod bundled;
mod compare;
mod convert;
mod demo;
mod error;
mod evaluate;
mod inspect;
mod lists;
mod live;
mod orientation;
mod output;
mod placement;
#[cfg(feature = "plot")]
pub mod plot;
mod source;
mod staging;
mod track;
mod track_options;
mod train;
mod workers;

pub use baselines::{Method, baseline_trajectory, device_heading};
#[cfg(feature = "bundled-model")]
pub use bundled::{BUNDLED_MODEL_SUMMARY, bundled_model, bundled_training_runs};
pub use compare::{ComparedFigure, Comparison, compare_reports};
pub use convert::{
    ConvertOptions, ConvertSummary, Converted, SPLIT_MIN_PART_S, WARNINGS_FILE, convert,
    read_split, resample_max_gap, split_limit,
};
pub use demo::Demo;
pub use error::{PipelineError, Result};
pub use evaluate::{
    EvalOptions, GroupSummary, Provenance, Report, SequenceResult, Traces, check_evaluable,
    evaluate, evaluate_cancellable, placement_warnings,
};
pub use inspect::{
    Inspection, ModelInspection, PlacementModel, RegressorSummary, SeriesStats, inspect,
    inspect_model, inspect_stream,
};
pub use lists::{Purpose, check_distinct_recordings, load_listed};
pub use live::{
    CascadeRegressor, LiveTracker, Recorded, STREAM_ACCE_G, STREAM_CHECK_SAMPLES,
    STREAM_GYRO_CHECK_S, STREAM_MIN_GYRO_AGREEMENT, SensorReading,
};
pub use orientation::{apply_orientation, oriented};
pub use output::{
    EvalFolder, EvalPlots, EvalWritten, OutputError, TrackOutput, check_not_input,
    check_output_file, check_output_folder, save_model,
};
pub use placement::PlacementMap;
pub use source::{Loaded, ReadFiles, read_any, read_to_track, source_format};
pub use staging::Staging;
pub use track::{
    StreamedTrack, TRACK_RATE_HZ, TRACK_RATE_TOLERANCE, Track, regress_sequence, track,
};
pub use track_options::TrackOptions;
pub use train::{
    GridChoice, MIN_VELOCITY_CHANGES_PER_S, TrainOptions, TrainingData, default_step,
    ground_truth_view, train, training_data, training_warnings, training_windows,
};

pub use workers::{MAX_JOBS, Workers, start_workers};

/// The README's Rust example, compiled by `cargo test --doc` so that it cannot drift from the API.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
struct ReadmeDoctests;

/// This crate's README's example, compiled the same way.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct CrateReadmeDoctests;
