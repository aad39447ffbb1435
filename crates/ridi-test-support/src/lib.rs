//! Helpers shared by the integration tests (and benchmarks) of the ridi-rs crates; a
//! dev-dependency only (and xtask's, for the fuzz seeds), never published.
//!
//! **Key design decision: this crate depends on no crate it helps to test.** Cargo builds a
//! dev-dependency's own dependencies as ordinary ones, so a support crate that depended on,
//! say, `ridi-data` would give `ridi-data`'s tests a second copy of `ridi-data` whose
//! `Sequence` is another type than the one under test. Hence it depends on `ridi-frames` (the
//! bottom layer, below every crate that uses it; `ridi-frames`' own tests do not use it) and
//! on no other workspace crate, and its helpers take and return plain types: paths, strings,
//! bytes, `f32`/`f64` slices, `ridi-frames` vectors. Fixtures built from a crate's own types stay
//! in that crate's `tests/common` (`ridi-data`'s `Sequence` fixtures, `ridi-correct`'s synthetic
//! walks).
//!
//! What is here:
//! - **The error rule.** [`assert_names_file`]: an error about an input names the file, and
//!   the line and field where there is one (`path:line: field `name`: what is wrong`);
//!   [`assert_err`] for the words a message must contain.
//! - **Data beside the code.** [`workspace_root`], [`sample_dataset`] (`datasets/sample`),
//!   [`shared_dataset`] (the third-party data in `../shared`, for the `#[ignore]`d checks).
//! - **Files and text.** [`write_files`], [`file_names`], [`edit_file`], and cell edits of
//!   delimited text ([`edit_cells`], [`edit_rows`], [`with_cell`]); [`stderr`] of a run binary.
//! - **Deterministic data.** [`SplitMix64`], and from it [`regression_data`] and [`blob_data`]
//!   for the SVM tests.
//! - **MAT files.** [`MatWriter`] writes Level 5 MAT files of [`MatArray`]s (plain or
//!   compressed, either byte order) and their elements, [`qtm_take`] the QTM export of the
//!   Tyrex ground truth: the fixtures of `ridi-data`'s MAT and Tyrex tests and the seeds of
//!   `cargo xtask fuzz`.
//! - **The synthetic Tyrex run.** [`TYREX_OMEGA`], [`TYREX_TIME_DIFF`], [`yaw`],
//!   [`tyrex_phone_rows`] and [`tyrex_mocap`]: the motion both of them write into runs.
//! - **Naive references.** [`naive_smooth`] (scipy's `gaussian_filter1d` by explicit padding)
//!   and [`naive_features`] (feature windows frame by frame): slow, written for clarity, the
//!   oracles of `ridi-features`' tests and the baseline of its benchmark.
//!
//! Items live in private modules and are re-exported here, as in the library crates.

mod errors;
mod files;
mod mat;
mod naive;
mod paths;
mod synthetic;
mod text;
mod tyrex;

pub use errors::{Blame, assert_err, assert_names_file};
pub use files::{edit_file, file_names, stderr, write_files};
#[cfg(unix)]
pub use files::{is_fifo, make_fifo};
pub use mat::{MatArray, MatWriter, qtm_take};
pub use naive::{naive_features, naive_kernel, naive_mirror, naive_smooth};
pub use paths::{sample_dataset, shared_dataset, workspace_root};
pub use synthetic::{SplitMix64, blob_data, regression_data, straight_between_points};
pub use text::{edit_cells, edit_rows, with_cell};
pub use tyrex::{TYREX_OMEGA, TYREX_TIME_DIFF, tyrex_mocap, tyrex_phone_rows, yaw};
