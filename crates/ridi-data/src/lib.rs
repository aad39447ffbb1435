//! IMU sequences and the dataset formats they come in.
//!
//! A [`Sequence`] is one recording on one timeline: device-frame gyro, accelerometer, linear
//! acceleration and gravity, the device orientation (world-from-device, see `ridi-frames`),
//! and optional ground truth and step counter. It is validated when built, so code that takes
//! a `Sequence` can rely on equal lengths, finite values, increasing time, values within physical
//! bounds, channels in plausible units and gravity along the orientation's up axis
//! ([`Validation`]). [`Sequence::with_estimated_orientation`] swaps in the gyro + accelerometer
//! estimate that models on the estimated orientation take.
//!
//! Readers and writers turn files into sequences and back; every error names the file, and
//! parse errors the line and field too. No reader panics on malformed input.
//!
//! # Formats
//!
//! | format | reader | writer |
//! | --- | --- | --- |
//! | RIDI processed `data.csv`: pandas index, then the 27 [`PROCESSED_COLUMNS`], time in ns | [`ridi_csv::read`] | [`write_ridi_csv`] |
//! | RIDI `data_plain.txt`: `N 27`, then N tab-separated rows | [`ridi_plain::read`] | [`write_ridi_plain`] |
//! | RIDI raw recorder folder (`gyro.txt`, `acce.txt`, ..., `pose.txt`) | [`ridi_raw::read`] | |
//! | Tyrex smartphone benchmark run folder (Android or iOS text files, Qualisys `.mat` ground truth) | [`tyrex::read`] | |
//! | Indoor Location Competition 2.0 path file (`unix_ms<TAB>TYPE_...` records, waypoints) | [`ilc::read`] | |
//! | RoNIN sequence folder (`data.hdf5`, `info.json`) | [`ronin::read`] | |
//! | dataset list file (`path,placement` per line) | [`ListEntry::read`], [`Listed`] | |
//!
//! Each format is a public module, the one kind of public module here: every format has its
//! own `read` (and most a `parse` of bytes), so the module is the name (`tyrex::read`,
//! `ronin::read`). Everything else is re-exported at the crate root from private modules.
//!
//! [`detect`] tells the format of a file or folder and [`read_sequence`] reads any of them
//! (a Tyrex run only when it is not split into parts; it drops the reader's warnings, which
//! [`tyrex::read`] and [`ilc::read`] return). [`ReadOptions`] holds the validation limits and the
//! raw synchronization settings.
//!
//! [`RowReader`] reads a RIDI `data.csv`, `data_plain.txt` or raw folder row by row, in memory
//! that does not grow with the recording, with the same rows, checks and errors as the
//! whole-file readers ([`Format::streams`] says which formats stream).
//!
//! Conventions at the file edges: time is nanoseconds in files and seconds (absolute, `f64`)
//! in a [`Sequence`]; quaternions are `w, x, y, z` in processed files and `x, y, z, w` in raw
//! files (Android, Tango). In the processed layout a missing magnetometer is written as zeros and
//! missing ground truth as `NaN` on every row, and both read back as absent. The device a
//! sequence was recorded with ([`DeviceInfo`]) has no column there: it goes to a sidecar beside
//! the data file ([`sidecar_path`]), optional on read.
//!
//! # Features
//!
//! - `internals` (off): the MAT-file and HDF5 readers, the list parser on bytes and the
//!   interpolation that the fuzz targets (`fuzz/`), this crate's tests and its benches use; not a supported
//!   API.
//!
//! # Example
//!
//! Write a tiny sequence in the RIDI processed layout and read it back:
//!
//! ```
//! use ridi_data::ridi_frames::{DeviceVec, WorldFromDevice};
//! use ridi_data::{read_sequence, write_ridi_csv, OrientationSource, ReadOptions, Sequence, SequenceParts};
//!
//! let n = 5;
//! let seq = Sequence::new(SequenceParts {
//!     name: "walk1".into(),
//!     time: (0..n).map(|i| (1_000_000_000 + 5_000_000 * i) as f64 / 1e9).collect(),
//!     gyro: vec![DeviceVec::new(0.01, -0.02, 0.03); n],
//!     // Lying flat: gravity along the device's z axis, the orientation's up.
//!     acce: vec![DeviceVec::new(0.1, 0.1, 10.0); n],
//!     linacce: vec![DeviceVec::new(0.1, 0.1, 0.2); n],
//!     gravity: vec![DeviceVec::new(0.0, 0.0, 9.8); n],
//!     orientation: vec![WorldFromDevice::identity(); n],
//!     orientation_source: Some(OrientationSource::GameRotationVector),
//!     ..Default::default()
//! })?;
//!
//! let dir = tempfile::tempdir().unwrap();
//! let folder = dir.path().join("walk1");
//! std::fs::create_dir_all(folder.join("processed")).unwrap();
//! write_ridi_csv(&seq, folder.join("processed/data.csv"))?;
//!
//! // The folder is detected as a RIDI capture and named after itself.
//! let back = read_sequence(&folder, &ReadOptions::default())?;
//! assert_eq!(back, seq);
//! assert!(back.ground_truth().is_none() && back.magnet().is_none());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod android;
mod detect;
mod device;
mod error;
mod file_id;
mod hdf5;
pub mod ilc;
#[cfg(feature = "internals")]
mod internals;
mod list;
mod mat;
mod options;
mod processed;
mod resample;
pub mod ridi_csv;
pub mod ridi_plain;
pub mod ridi_raw;
pub mod ronin;
mod sequence;
mod sequence_error;
mod sidecar;
mod stream;
mod temporaries;
mod text;
pub mod tyrex;
mod validation;
mod write;

pub use detect::{Format, detect, processed_file, read_sequence, source_files};
pub use device::{DeviceError, DeviceInfo};
pub use error::{DataError, Location, Result, counted, first_few, one_line, shown, spans_text};
pub use file_id::FileId;
#[cfg(feature = "internals")]
#[doc(hidden)]
pub use internals::{
    CellArray, CharArray, Hdf5Array, Hdf5File, MAX_DEPTH, MatClass, MatFile, MatValue, Numeric,
    StructArray, interpolate_vec3, parse_list,
};
pub use list::{ListEntry, Listed, unlistable_name};
pub use options::ReadOptions;
pub use processed::PROCESSED_COLUMNS;
pub use ridi_frames;
pub use sequence::{
    Channel, GroundTruth, OrientationSource, RESAMPLE_RATE_RANGE_HZ, Sequence, SequenceParts,
    SplitParts, heading_reference, part_name,
};
pub use sequence_error::{SequenceError, short};
pub use sidecar::{SIDECAR_SUFFIX, sidecar_path};
pub use stream::{MedianTest, Row, RowReader, median_interval};
pub use temporaries::{
    STAGING_LOCK, STAGING_PREFIX, StaleTemporary, TEMPORARY_FILE_PREFIX, TemporariesHold,
    Temporary, hold_temporaries, register_created_folder, register_temporary,
    remove_temporaries_for_exit, remove_temporary, stale_temporaries, temporary_prefix,
};
pub use text::read_text;
pub use validation::{
    GYRO_AXIS_MIN_SHARE, GYRO_AXIS_MIN_STEPS, GYRO_SCALE_MIN_RATE, GyroFit, LINACCE_SCALE_MIN_RMS,
    LINACCE_STILL_MAX_RMS, MAX_JUMP_SHARE, MIN_GYRO_AGREEMENT, MIN_GYRO_AXIS_SCALE,
    ORIENTATION_JUMP_RATE, ORIENTATION_STILL_GYRO_RATE, OrientationJump, Validation,
    bridge_orientation_jumps, orientation_jumps, up_angle_deg,
};
pub use write::{
    PendingFile, Precision, RoundTrip, output_target, write_atomically, write_pending,
    write_ridi_csv, write_ridi_csv_with, write_ridi_plain,
};

/// The README's example, compiled by `cargo test --doc` so that it cannot drift from the API.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
