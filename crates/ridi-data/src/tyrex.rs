//! Reader for the Tyrex smartphone attitude benchmark (Inria Tyrex, "On Attitude Estimation
//! with Smartphones", PerCom 2017): Android (Nexus 5) and iOS (iPhone 4S) IMU recordings with
//! Qualisys motion-capture ground truth.
//!
//! # Layouts
//! ```text
//! <root>/datasets/android/<Person>_<Phone>_<Dist>_<Motion>/
//!     accelerometer.txt          t ax ay az            m/s^2, with gravity
//!     gyroscope-calibrated.txt   t wx wy wz            rad/s
//!     rotation-vector.txt        t qx qy qz qw [acc]   Android TYPE_ROTATION_VECTOR, x,y,z,w!
//!     timeAlignment.txt          timeDiff              s
//!     record.properties          [Device] Model = ..., [Time] StartTime = ...
//! <root>/datasets/ios/<Person>_<Phone>_<Dist>_<Motion>/
//!     accelerometer.txt          t ax ay az            g, Core Motion's sign (-1 g up at rest)
//!     gyroscope.txt              t wx wy wz            rad/s
//!     attitude.txt               t qw qx qy qz         Core Motion attitude, w,x,y,z
//!     timeAlignment.txt          timeDiff              s
//!     description.txt            [Time] BootTime = s   the offset of the time column
//! <root>/datasets/qualisys/<same name>.mat   QTM "Level 5 MAT-file" export
//! ```
//! Text files are space-separated without a header; the first column is seconds.
//! [`layout_of`] tells the layouts apart by their own files (`rotation-vector.txt`,
//! `attitude.txt`, ...). `linear-acceleration.txt` (Android) is not read: it is sparse in some
//! runs, and the linear acceleration is rebuilt from the accelerometer and the orientation
//! instead. The Qualisys file is matched regardless of ASCII case when no file has the run's
//! exact name ([`mat_path`]: the source spells one run `Jakob_iPhone4S_NoDist_Backpocket` and its
//! file `..._BackPocket.mat`). The placement is the motion, matched the same way
//! ([`motion_of`]); the name stays the folder's.
//!
//! # Frames
//! The device frame is the Android sensor frame (x right, y to the top, z out of the screen;
//! the iPhone's is the same). Gravity is `gravity_in_device(orientation, g)` with `g` =
//! [`TyrexOptions::gravity`] ([`STANDARD_GRAVITY`] by default, the value Android's own gravity
//! sensor uses), and linear acceleration is accelerometer minus gravity. The device orientation:
//! - Android: the rotation vector ([`OrientationSource::RotationVector`]: magnetometer-based,
//!   world = east-north-up).
//! - iOS: the Core Motion attitude ([`OrientationSource::CoreMotionAttitude`]), turned as the
//!   authors' loader turns it (see below), so that its world is east-north-up too.
//!
//! The iOS files are brought into the Android conventions exactly as the authors' loader
//! (`src/Import/loadiOSDataset.m` of the source, whose helpers `dcm2quat`, `quatmultiply` and
//! `Constants` are in its `src/Utils/`) does:
//! - **Accelerometer** (lines 24-25): `acce = -9.80665 * [ax, ay, az]`. Core Motion reports
//!   acceleration in g with the opposite sign to Android's (`-1 g` along the upward axis at
//!   rest, where Android reads `+9.8 m/s^2`); `Constants.STANDARD_GRAVITY` is 9.80665.
//! - **Gyroscope** (lines 20, 42): taken as it is, rad/s.
//! - **Attitude** (lines 34-39): `q = h ⊗ [qw, qx, qy, qz]` with `h` the quarter turn `+90°`
//!   about z (`headingRotation` is the matrix of `+90°`, and the authors' `dcm2quat` returns the
//!   quaternion of the transpose of its argument, so `dcm2quat(headingRotation')` is `+90°`;
//!   `quatmultiply` is the Hamilton product). Core Motion's reference frame has x towards
//!   magnetic north and z up; the turn takes its north onto east-north-up's +y. The result is
//!   world-from-device like the rotation vector.
//! - **Time** (lines 47-48): every time column minus `BootTime` of `description.txt`'s `[Time]`
//!   section (`offsetTimeAllData(-bootTime)`), which puts it near 0 at the start, as the Android
//!   files' times are; `timeAlignment.txt`'s `timeDiff` applies to that clock, as for Android
//!   (the authors' `findTimeDiffBetweenQualisysAndSmartphone.m` loads it for the data as
//!   loaded). "Phone clock" in the warnings means this clock.
//!
//! Checked on the shared runs (`tests/tyrex_shared.rs`): the accelerometer averaged over a
//! second lies within 1-4 degrees (median) of the gravity the motion capture gives for the
//! hand-held runs of both phones (with the wrong sign it would be 180), and the iOS attitude's
//! heading, turned, is within a few degrees of the room's, as the rotation vector's is (without
//! the turn it would be 90 degrees off).
//!
//! Ground truth keeps the mocap room frame (z up, metres, origin and heading of the room): the
//! QTM struct's `RigidBodies.Positions` (1x3xN, mm) divided by 1000, and
//! `RigidBodies.Rotations` (1x9xN, a column-major 3x3 with `p_room = R p_phone`; the authors'
//! `loadQualisysDataset.m` line 27 takes `dcm2quat(reshape(R, 3, 3)')`, the same rotation). The
//! rigid body was defined to coincide with the device frame (of either phone), so `R` is the
//! world-from-device rotation directly. Frames where the mocap lost the body are `NaN` in the
//! file. A finite `R` must be a rotation matrix
//! ([`Rot::from_matrix`](ridi_frames::Rot::from_matrix): determinant positive, `|RᵀR − I|`
//! within 1e-3; the Tyrex exports are within 1e-7), otherwise reading fails naming the file, the
//! field and the frame.
//!
//! # Time
//! Mocap frame `i` (0-based, first exported frame) is at mocap time `i / FrameRate`
//! (`loadQualisysDataset.m` lines 17-18), and `phone_time + timeDiff = mocap_time` with
//! `timeDiff` from `timeAlignment.txt` (the authors' estimate; a residual lag of about 0.02 s
//! remains for the Android runs, see [`TyrexOptions::extra_time_diff_s`]). Output sequences are
//! on the phone clock, on a uniform timeline at [`TyrexOptions::rate_hz`] (200 Hz: the Nexus 5
//! logs at about 200 Hz, the iPhone 4S its accelerometer at 90 Hz and its gyroscope and attitude
//! at 107 Hz, interpolated linearly, the orientation by slerp) over the time covered by every
//! phone stream and the ground truth.
//!
//! # Device
//! Every sequence's [`Sequence::device`] is the phone: `Model` of `record.properties` (Android;
//! `Nexus 5` in every shared run) or of a `[Device]` section of `description.txt` (iOS; the
//! shared runs have none), else the phone part of the run's name ([`phone_of`]: `iPhone4S` is
//! `iPhone 4S`); its IMU rate is the slower of the accelerometer's and the gyroscope's own rates
//! (198.6 Hz on the Nexus 5, 90 Hz on the iPhone 4S).
//!
//! # Mocap faults
//! Two checks cut mocap frames out as losses before anything is interpolated: where the
//! mocap's up axis is further than [`TyrexOptions::max_mocap_tilt_deg`] from the phone
//! orientation's and the accelerometer sides with the phone (a mis-solved body), and where the
//! rotation the mocap shows over 0.1 s contradicts the one the gyro integrates
//! ([`TyrexOptions::max_mocap_gyro_rad`], [`mocap_gyro_conflicts`]: a body solved flipped, which
//! a tilt check cannot see when the flip is about the vertical, and which would turn the
//! velocity targets the wrong way). Each is reported in [`TyrexRead::warnings`] with its times.
//!
//! # Gaps
//! Mocap losses up to [`TyrexOptions::max_mocap_gap_s`] are interpolated across; a longer one,
//! or a gap in a phone stream longer than [`TyrexOptions::max_sensor_gap_s`], splits the
//! recording. Every part at least [`TyrexOptions::min_part_s`] long is returned, named after the
//! folder with `_part1`, `_part2`, ... when there are several; each split and each dropped part
//! is reported in [`TyrexRead::warnings`].
//!
//! # Warnings
//! Besides splits and dropped parts: a clipped accelerometer (the Nexus 5 clips at 2 g, 19.553
//! m/s^2, exactly, in its running runs; the iPhone 4S near 2 g at a limit that differs by axis
//! and direction and drifts, so there the readings within 3 % of an axis's largest one count, in
//! its running runs and two of Thibaud's pocket runs), orientation jumps against the gyro (see
//! [`Sequence::orientation_jumps`]), an unknown motion, an unusable `Model`, and, for iOS files
//! only, a last record without a line break, which is left out (one shared file,
//! `Thibaud_iPhone4S_NoDist_RunningHand/attitude.txt`, is cut off so).
//!
//! # Errors
//! Every error names the file, and the line and field when one is to blame. An Android phone
//! file whose last line has no line break after it was cut off while being written and is
//! refused (`timeAlignment.txt`, `record.properties` and `description.txt` are not: small
//! hand-written files, some shared runs lack the break). The accelerometer, gyroscope and
//! orientation files are checked against the [`Validation`] limits before resampling (the iOS
//! accelerometer after its conversion to m/s^2): their median time step (seconds: milliseconds
//! step by 5 s), and every accelerometer and gyroscope value against its physical bound (the
//! gyro's median magnitude too); the accelerometer's scale against gravity is checked on each
//! sequence and reported on `accelerometer.txt`. A quaternion whose norm is not 1 names its line
//! and `qw`; a missing or malformed `BootTime` names `description.txt` and `BootTime`; a folder
//! with files of both layouts, or two Qualisys files that differ only in case, is an error.
//!
//! # Example
//! ```no_run
//! use ridi_data::tyrex::{self, TyrexOptions};
//!
//! let root = std::path::Path::new("tyrex-attitude-smartphones");
//! let listed = tyrex::list_sequences(root)?;
//! if let Some(w) = listed.warning() {
//!     eprintln!("{w}");
//! }
//! for dir in &listed.runs {
//!     let read = tyrex::read(dir, &TyrexOptions::default())?;
//!     for w in &read.warnings {
//!         eprintln!("{}: {w}", dir.display());
//!     }
//!     for seq in &read.sequences {
//!         println!("{} {:?} {:.0} s", seq.name(), seq.placement(), seq.duration());
//!     }
//! }
//! # Ok::<(), ridi_data::DataError>(())
//! ```

use std::path::{Path, PathBuf};

use ridi_frames::nalgebra::Matrix3;
use ridi_frames::{DeviceVec, QuatError, STANDARD_GRAVITY, WorldFromDevice, WorldVec};

use crate::android;
use crate::error::{DataError, Location, Result, counted, shown, spans_text, times};
use crate::mat::{MatFile, MatValue, dims_text};
use crate::options::ReadOptions;
use crate::resample::{interpolate_rot, interpolate_vec3, intersect, intervals, uniform_timeline};
use crate::text::{self, Nan};
use crate::validation::orientation_jump_warning;
use crate::{
    Channel, DeviceInfo, GroundTruth, OrientationJump, OrientationSource, Sequence, SequenceError,
    SequenceParts, Validation, bridge_orientation_jumps, part_name,
};

mod ios;
mod mocap_gyro;

pub use mocap_gyro::{
    MAX_MOCAP_GYRO_RAD, MOCAP_CHECK_WINDOW_S, MOCAP_MERGE_S, MOCAP_PAD_S, mocap_gyro_conflicts,
};

/// Mocap frame rate assumed when a `.mat` has no `FrameRate` (the Tyrex captures are 60 Hz).
pub const DEFAULT_MOCAP_RATE_HZ: f64 = 60.0;

/// The motions (placements) of the benchmark, the last part of a sequence name.
pub const MOTIONS: [&str; 8] = [
    "Texting",
    "Swinging",
    "AR",
    "BackPocket",
    "FrontPocket",
    "Phoning",
    "RunningHand",
    "RunningPocket",
];

/// How Tyrex folders are turned into sequences.
#[derive(Debug, Clone, PartialEq)]
pub struct TyrexOptions {
    /// Rate of the output timeline, Hz.
    pub rate_hz: f64,
    /// Gravity magnitude used to build the gravity channel from the orientation, m/s^2.
    pub gravity: f64,
    /// Longest mocap loss interpolated across, seconds (from the last frame before the loss to
    /// the first after it); longer ones split the recording.
    pub max_mocap_gap_s: f64,
    /// Longest interval between two samples of a phone stream, seconds; longer ones split the
    /// recording.
    pub max_sensor_gap_s: f64,
    /// Parts shorter than this are dropped, seconds.
    pub min_part_s: f64,
    /// Whether to read the ground truth when the `.mat` file is there.
    pub ground_truth: bool,
    /// Added to `timeDiff`: a positive value moves the ground truth earlier on the phone clock.
    ///
    /// 0 by default (the authors' alignment as published). Matching the rotation vector's tilt to
    /// the mocap's over lags in 5 ms steps gives a best value of -0.020 s (median over the 24
    /// NoDist runs, all within -0.010..-0.030 s). The rotation vector is a filtered output, so
    /// part of that may be its own latency rather than a clock offset of the raw sensors.
    pub extra_time_diff_s: f64,
    /// Where the mocap's up axis (in the device frame) is further than this from the phone
    /// orientation's, degrees, for a second, the accelerometer decides which is wrong: mocap
    /// frames it discredits are treated as mocap losses, a phone orientation it discredits is
    /// a warning ([`MAX_MOCAP_TILT_DEG`]). Infinity trusts both.
    pub max_mocap_tilt_deg: f64,
    /// Where the rotation the mocap shows over [`MOCAP_CHECK_WINDOW_S`] differs from the one the
    /// gyro integrates by more than this, rad, the mocap flipped the rigid body: those stretches
    /// ([`mocap_gyro_conflicts`]) are treated as mocap losses. Infinity trusts the mocap.
    pub max_mocap_gyro_rad: f64,
    /// Bridge the OS orientation's jumps by the gyro, keeping the heading continuous across them
    /// ([`bridge_orientation_jumps`]). Off by default: on the disturbed Nexus 5 runs the jumps
    /// mostly correct a heading the magnetic field had bent, and bridging them raised RIDI's
    /// RTE 5 s by 0.18 m [0.01, 0.38] (`cargo xtask eval tyrex --step 40 --orientation
    /// recorded`, its table "Orientation jumps").
    pub bridge_orientation_jumps: bool,
    /// Limits every output sequence is checked against.
    pub validation: Validation,
}

impl Default for TyrexOptions {
    fn default() -> Self {
        Self {
            rate_hz: 200.0,
            gravity: STANDARD_GRAVITY,
            max_mocap_gap_s: 0.25,
            max_sensor_gap_s: 0.1,
            min_part_s: 10.0,
            ground_truth: true,
            extra_time_diff_s: 0.0,
            max_mocap_tilt_deg: MAX_MOCAP_TILT_DEG,
            max_mocap_gyro_rad: MAX_MOCAP_GYRO_RAD,
            bridge_orientation_jumps: false,
            validation: Validation::default(),
        }
    }
}

impl From<&ReadOptions> for TyrexOptions {
    /// The validation limits and timeline rate of the generic reader options, Tyrex defaults
    /// for the rest.
    fn from(o: &ReadOptions) -> Self {
        Self {
            rate_hz: o.rate_without_pose_hz,
            validation: o.validation.clone(),
            ..Self::default()
        }
    }
}

/// What [`read`] found in one folder.
#[derive(Debug, Clone, PartialEq)]
pub struct TyrexRead {
    /// The usable parts of the recording, in time order (one unless gaps split it).
    pub sequences: Vec<Sequence>,
    /// Splits, dropped parts and other things a user should know about.
    pub warnings: Vec<String>,
    /// `timeDiff` from `timeAlignment.txt`, seconds, when ground truth was read.
    pub time_diff_s: Option<f64>,
    /// The phone's model, as every sequence's [`Sequence::device`] names it: `Model` of
    /// `record.properties` (Android) or of `description.txt`'s `[Device]` section (iOS; the
    /// shared runs have none) when given, else the phone part of the run's name (`Nexus5` is
    /// `Nexus 5`, `iPhone4S` `iPhone 4S`, any other as it is written).
    pub device_model: Option<String>,
    /// The layout the run was read in.
    pub layout: Layout,
}

/// The two layouts of a Tyrex run folder: the Android recorder's and the iOS recorder's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Layout {
    /// `datasets/android/<run>/`: `accelerometer.txt` (m/s^2), `gyroscope-calibrated.txt`,
    /// `rotation-vector.txt`, `record.properties`.
    Android,
    /// `datasets/ios/<run>/`: `accelerometer.txt` (g, opposite sign), `gyroscope.txt`,
    /// `attitude.txt` (Core Motion), `description.txt` (`BootTime`).
    Ios,
}

impl std::fmt::Display for Layout {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Layout::Android => "Android",
            Layout::Ios => "iOS",
        })
    }
}

/// Files only the Android layout has.
const ANDROID_FILES: [&str; 3] = [
    "gyroscope-calibrated.txt",
    "rotation-vector.txt",
    "record.properties",
];

/// Which layout the run folder `dir` is in: iOS when it holds `attitude.txt` or
/// `description.txt`, Android when it holds any of `gyroscope-calibrated.txt`,
/// `rotation-vector.txt` and `record.properties`; a folder with neither (say only
/// `accelerometer.txt`) is iOS when it sits in an `ios` folder, Android otherwise, so that
/// reading it names the files of that layout it lacks.
///
/// # Errors
/// A folder with files of both layouts, naming one of each.
pub fn layout_of(dir: impl AsRef<Path>) -> Result<Layout> {
    let dir = dir.as_ref();
    let has = |f: &&&str| dir.join(f).exists();
    let android = ANDROID_FILES.iter().find(has);
    let ios = ios::OWN_FILES.iter().find(has);
    match (android, ios) {
        (Some(a), Some(i)) => Err(DataError::format(
            Location::file(dir),
            format!(
                "holds files of both Tyrex layouts: {a} (Android) and {i} (iOS); a run folder \
                 is one or the other"
            ),
        )),
        (Some(_), None) => Ok(Layout::Android),
        (None, Some(_)) => Ok(Layout::Ios),
        (None, None) => {
            let in_ios = dir
                .canonicalize()
                .ok()
                .and_then(|d| d.parent().and_then(|p| p.file_name()).map(|n| n == "ios"))
                .unwrap_or(false);
            Ok(if in_ios { Layout::Ios } else { Layout::Android })
        }
    }
}

/// One mocap frame where the body was tracked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MocapPose {
    /// Position in the room frame, metres.
    pub position: WorldVec,
    /// Room-from-device rotation.
    pub orientation: WorldFromDevice,
}

/// Ground truth at the mocap rate, as stored in the `.mat` (before any resampling).
#[derive(Debug, Clone, PartialEq)]
pub struct MocapTrack {
    /// Frame rate, Hz.
    pub rate_hz: f64,
    /// Name of the variable the track was read from (QTM names it after the take).
    pub variable: String,
    /// Mocap time of each frame, seconds: `index / rate_hz`.
    pub time: Vec<f64>,
    /// Pose per frame; `None` where the mocap lost the body.
    pub pose: Vec<Option<MocapPose>>,
}

impl MocapTrack {
    /// Number of frames with a pose.
    pub fn valid_count(&self) -> usize {
        self.pose.iter().filter(|p| p.is_some()).count()
    }
}

/// The motion (placement) of a sequence named `<Person>_<Phone>_<Dist>_<Motion>`, one of
/// [`MOTIONS`] (matched without regard to case, returned in canonical spelling).
pub fn motion_of(name: &str) -> Option<&'static str> {
    let last = name.rsplit('_').next()?;
    MOTIONS
        .iter()
        .find(|m| m.eq_ignore_ascii_case(last))
        .copied()
}

/// The run folders of a Tyrex root, as [`list_sequences`] finds them.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct TyrexRuns {
    /// Runs with a Qualisys file, sorted by path (the Android runs, then the iOS runs, each by
    /// name): the ones to convert, train and evaluate on.
    pub runs: Vec<PathBuf>,
    /// Runs without one (the source keeps an earlier take, `Jakob_Nexus5_Dist_Swinging_old`,
    /// without motion capture), sorted by path.
    pub without_mocap: Vec<PathBuf>,
}

impl TyrexRuns {
    /// One line naming the runs without motion capture and saying they were skipped; `None`
    /// when every run has it.
    pub fn warning(&self) -> Option<String> {
        (!self.without_mocap.is_empty()).then(|| {
            let names: Vec<String> = self.without_mocap.iter().map(shown).collect();
            format!(
                "{} without a Qualisys file in ../../qualisys/ skipped: {}",
                counted(names.len(), "run folder"),
                names.join(", ")
            )
        })
    }
}

/// The folders of run folders under a Tyrex root: `datasets/android/` and `datasets/ios/` (those
/// that exist), else `android/` and `ios/`, else `root` itself.
fn run_folders(root: &Path) -> Option<Vec<PathBuf>> {
    for base in [root.join("datasets"), root.to_path_buf()] {
        let found: Vec<PathBuf> = ["android", "ios"]
            .iter()
            .map(|l| base.join(l))
            .filter(|p| p.is_dir())
            .collect();
        if !found.is_empty() {
            return Some(found);
        }
    }
    root.is_dir().then(|| vec![root.to_path_buf()])
}

/// The run folders under a Tyrex root. `root` may be the dataset root (with
/// `datasets/android/` and `datasets/ios/`, side by side or one of them), its `datasets/` folder,
/// or an `android/` or `ios/` folder itself; a run folder is one that holds `accelerometer.txt`
/// (both layouts have it). Runs without a Qualisys file are listed apart
/// ([`TyrexRuns::without_mocap`]): a root is converted for its ground truth, and one such
/// folder must not fail it. Read one alone with [`read`] (without ground truth).
pub fn list_sequences(root: impl AsRef<Path>) -> Result<TyrexRuns> {
    let root = root.as_ref();
    let bases = run_folders(root).ok_or_else(|| {
        DataError::format(
            Location::file(root),
            format!(
                "not a Tyrex run or root ({}): {}",
                if root.exists() {
                    "not a folder"
                } else {
                    "no such file or folder"
                },
                crate::Format::Tyrex.layout()
            ),
        )
    })?;
    let mut out = TyrexRuns::default();
    for base in &bases {
        let entries = std::fs::read_dir(base).map_err(|e| DataError::io(base, e))?;
        for entry in entries {
            let path = entry.map_err(|e| DataError::io(base, e))?.path();
            if !path.join("accelerometer.txt").is_file() {
                continue;
            }
            // `exists`, not `is_file`: a Qualisys path that is no regular file (or two files whose
            // names differ only in case) is the reader's error to report, not a reason to skip
            // the run.
            if mat_candidates(&path).is_some_and(|m| !m.is_empty()) {
                out.runs.push(path);
            } else {
                out.without_mocap.push(path);
            }
        }
    }
    if out.runs.is_empty() && out.without_mocap.is_empty() {
        let names: Vec<String> = bases.iter().map(shown).collect();
        return Err(DataError::format(
            Location::file(&bases[0]),
            format!(
                "no Tyrex sequence folder (with accelerometer.txt) here or in datasets/android/ \
                 or datasets/ios/ (looked in {})",
                names.join(", ")
            ),
        ));
    }
    out.runs.sort();
    out.without_mocap.sort();
    Ok(out)
}

/// The Qualisys files of the run folder `dir` in `../../qualisys/`: `<name>.mat` when it exists,
/// else every file whose name is `<name>.mat` but for ASCII case (the source spells one run
/// `Jakob_iPhone4S_NoDist_Backpocket` and its file `Jakob_iPhone4S_NoDist_BackPocket.mat`).
/// `None` when `dir` has no name or parent folders to look in.
fn mat_candidates(dir: &Path) -> Option<Vec<PathBuf>> {
    let exact = exact_mat_path(dir)?;
    if exact.exists() {
        return Some(vec![exact]);
    }
    let want = exact.file_name()?.to_str()?.to_owned();
    let folder = exact.parent()?;
    let Ok(entries) = std::fs::read_dir(folder) else {
        return Some(Vec::new());
    };
    let mut found: Vec<PathBuf> = entries
        .filter_map(|e| e.ok())
        .filter(|e| {
            e.file_name()
                .to_str()
                .is_some_and(|n| n.eq_ignore_ascii_case(&want))
        })
        .map(|e| e.path())
        .collect();
    found.sort();
    Some(found)
}

/// `../../qualisys/<name>.mat` of the run folder `dir`, spelled as the folder is.
fn exact_mat_path(dir: &Path) -> Option<PathBuf> {
    let name = dir.file_name()?;
    let datasets = dir.parent()?.parent()?;
    let mut file = datasets.join("qualisys").join(name);
    file.as_mut_os_string().push(".mat");
    Some(file)
}

/// Where the ground truth of the sequence folder `dir` is: `../../qualisys/<name>.mat` beside
/// the `android/` or `ios/` folder, matched regardless of ASCII case when no file has the exact
/// name (one shared run is `..._Backpocket`, its file `..._BackPocket.mat`). When no file or
/// several match, the exact name (which does not exist).
pub fn mat_path(dir: &Path) -> Option<PathBuf> {
    match mat_candidates(dir)?.as_slice() {
        [one] => Some(one.clone()),
        _ => exact_mat_path(dir),
    }
}

/// The Qualisys file [`read`] takes for `dir`: `None` when there is none.
///
/// # Errors
/// Several files match but for case; or the one that matches is not a regular file (a folder, a
/// device).
fn ground_truth_file(dir: &Path) -> Result<Option<PathBuf>> {
    let found = mat_candidates(dir).unwrap_or_default();
    match found.as_slice() {
        [] => Ok(None),
        [one] if one.is_file() => Ok(Some(one.clone())),
        [one] => Err(DataError::format(
            Location::file(one),
            "the run's Qualisys file is not a regular file",
        )),
        [first, second, ..] => Err(DataError::format(
            Location::file(first),
            format!(
                "{} Qualisys files match the run `{}` but for case ({} and {}): keep one",
                found.len(),
                dir.file_name().unwrap_or_default().to_string_lossy(),
                shown(first),
                shown(second)
            ),
        )),
    }
}

/// Reads the ground truth of a QTM `.mat` export at the mocap rate.
///
/// The take is the top-level struct with a `RigidBodies` field (the one named after the file
/// if several: QTM names the variable after the take, which does not always match the file).
/// The first rigid body is used. A frame is valid when its position and rotation are finite;
/// a finite rotation that is not a proper rotation matrix (a reflection, or further than
/// [`Rot::ORTHONORMALITY_TOLERANCE`](ridi_frames::Rot::ORTHONORMALITY_TOLERANCE) from
/// orthonormal: the Tyrex exports are within 1e-7) is an error naming the file, the field
/// `<take>.RigidBodies.Rotations` and the frame (from 1). Valid rotations are taken as the
/// nearest rotation ([`Rot::from_matrix`](ridi_frames::Rot::from_matrix)).
pub fn read_ground_truth(path: impl AsRef<Path>) -> Result<MocapTrack> {
    let path = path.as_ref();
    let mat = MatFile::read(path)?;
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned());
    let has_bodies = |v: &MatValue| v.field("RigidBodies").is_some();
    let variable = mat
        .variables()
        .find(|(n, v)| Some(*n) == stem.as_deref() && has_bodies(v))
        .or_else(|| mat.variables().find(|(_, v)| has_bodies(v)))
        .map(|(n, _)| n.to_owned())
        .ok_or_else(|| {
            let names: Vec<&str> = mat.variables().map(|(n, _)| n).collect();
            DataError::format(
                Location::file(path).with_field("RigidBodies"),
                format!(
                    "no variable is a struct with a `RigidBodies` field (variables: {}): \
                     not a QTM export with rigid bodies",
                    names.join(", ")
                ),
            )
        })?;
    let field = |name: &str| format!("{variable}.{name}");
    let rate_hz = match mat.lookup(&field("FrameRate")) {
        None => DEFAULT_MOCAP_RATE_HZ,
        Some(v) => match v.scalar() {
            Some(r) if r.is_finite() && r > 0.0 => r,
            _ => {
                return Err(DataError::format(
                    Location::file(path).with_field(field("FrameRate")),
                    format!(
                        "expected one positive number, found a {} of size {}",
                        v.kind(),
                        dims_text(v.dims())
                    ),
                ));
            }
        },
    };
    let (pos, n) = body_channels(&mat, &field("RigidBodies.Positions"), 3)?;
    let (rot, n_rot) = body_channels(&mat, &field("RigidBodies.Rotations"), 9)?;
    if n != n_rot {
        return Err(DataError::format(
            Location::file(path).with_field(field("RigidBodies.Rotations")),
            format!("{n_rot} frames, but Positions has {n}"),
        ));
    }
    let mut pose = Vec::with_capacity(n);
    for i in 0..n {
        let p = pos(i);
        let r = rot(i);
        if !(p[..3].iter().all(|v| v.is_finite()) && r.iter().all(|v| v.is_finite())) {
            pose.push(None);
            continue;
        }
        let orientation =
            WorldFromDevice::from_matrix(&Matrix3::from_column_slice(&r)).map_err(|e| {
                DataError::format(
                    Location::file(path).with_field(field("RigidBodies.Rotations")),
                    // Frames are numbered from 1, as MATLAB and QTM do.
                    match e {
                        QuatError::NotRotation { .. } => format!("frame {} is {e}", i + 1),
                        _ => format!("frame {}: {e}", i + 1),
                    },
                )
            })?;
        pose.push(Some(MocapPose {
            position: WorldVec::new(p[0] / 1000.0, p[1] / 1000.0, p[2] / 1000.0),
            orientation,
        }));
    }
    Ok(MocapTrack {
        rate_hz,
        variable,
        time: (0..n).map(|i| i as f64 / rate_hz).collect(),
        pose,
    })
}

/// A per-body array `[bodies, k, frames]` (or `[k, frames]`): the first body's `k` values of a
/// frame (the first `k` of 9, the rest NaN), and the frame count.
#[allow(clippy::type_complexity)]
fn body_channels<'a>(
    mat: &'a MatFile,
    field: &str,
    k: usize,
) -> Result<(Box<dyn Fn(usize) -> [f64; 9] + 'a>, usize)> {
    let v = mat.require(field)?;
    let bad = |what: String| DataError::format(Location::file(mat.path()).with_field(field), what);
    let num = v
        .as_numeric()
        .ok_or_else(|| bad(format!("expected a numeric array, found a {}", v.kind())))?;
    let (bodies, frames) = match num.dims.as_slice() {
        [b, kk, n] if *kk == k && *b >= 1 => (*b, *n),
        [kk, n] if *kk == k => (1, *n),
        _ => {
            return Err(bad(format!(
                "size {}, expected bodies x {k} x frames",
                dims_text(&num.dims)
            )));
        }
    };
    if frames == 0 {
        return Err(bad("no frames".into()));
    }
    let data = &num.real;
    let get = move |i: usize| {
        let mut out = [f64::NAN; 9];
        for (c, o) in out.iter_mut().enumerate().take(k) {
            // Column-major [bodies, k, frames]: body 0, channel c, frame i.
            *o = data[bodies * (c + k * i)];
        }
        out
    };
    Ok((Box::new(get), frames))
}

/// The Tyrex files' names: `t` (seconds), `ax ay az`, `wx wy wz`; the channels built from the
/// orientation and the mocap by their sequence names (`gravity.x`).
struct TyrexFields;

impl text::Fields for TyrexFields {
    fn field(&self, channel: Channel, axis: Option<usize>) -> String {
        let axes = match channel {
            Channel::Time => return "t".to_owned(),
            Channel::Acce => ["ax", "ay", "az"],
            Channel::Gyro => ["wx", "wy", "wz"],
            _ => return text::sequence_field(channel, axis),
        };
        text::axis_field(axes, axis)
    }
    fn time_unit(&self) -> &str {
        "seconds"
    }
}

/// One phone stream: sample times (strictly increasing), values and their line numbers.
struct Stream<T> {
    path: PathBuf,
    time: Vec<f64>,
    values: Vec<T>,
    lines: Vec<usize>,
}

impl<T> Stream<T> {
    /// Checks the time step and, for `channel`, every value as the 3-vector `xyz` gives.
    fn check(
        &self,
        limits: &Validation,
        channel: Option<Channel>,
        xyz: impl Fn(&T) -> [f64; 3] + Clone,
    ) -> Result<()> {
        let values = self.values.iter().map(xyz);
        let (path, lines) = (&self.path, &self.lines);
        text::check_stream(
            limits,
            path,
            lines,
            &TyrexFields,
            &self.time,
            channel,
            values,
        )
    }
}

/// What [`read_stream`] does with a last record that has no line break after it (a file cut
/// off while being written, whose last value may be cut short yet still parse).
enum CutOff<'a> {
    /// Refuse the file, naming that line (the Android layout, as every other data reader).
    Refuse,
    /// Leave that record out, with a warning naming it (the iOS layout: one shared file,
    /// `Thibaud_iPhone4S_NoDist_RunningHand/attitude.txt`, is cut off so).
    Drop(&'a mut Vec<String>),
}

/// Reads a whitespace-separated table whose rows have one of the `widths` (time included),
/// converting each row with `row`.
fn read_stream<T>(
    path: &Path,
    names: &[&str],
    widths: &[usize],
    cut_off: CutOff<'_>,
    mut row: impl FnMut(&[f64], usize) -> Result<T>,
) -> Result<Stream<T>> {
    let bytes = text::read_file(path)?;
    let mut content = text::as_text(&bytes, path)?;
    if let CutOff::Drop(warnings) = cut_off
        && !text::ends_in_break(content)
        && let Some((line, last)) = text::lines(content).last()
    {
        // `last` is a slice of `content`: keep what comes before it.
        let at = last.as_ptr() as usize - content.as_ptr() as usize;
        content = &content[..at];
        warnings.push(format!(
            "{}:{line}: the file ends inside this record, without a line break (cut off while \
             being written): the record is left out",
            shown(path)
        ));
    }
    // About 45 bytes per row in these files: reserving avoids regrowing the vectors.
    let guess = content.len() / 40;
    let (mut time, mut values, mut lines) = (
        Vec::with_capacity(guess),
        Vec::with_capacity(guess),
        Vec::with_capacity(guess),
    );
    let mut cells = [0.0; 8];
    let max = widths.iter().copied().max().unwrap_or(0);
    for (line, l) in text::lines(content) {
        let mut n = 0;
        for cell in l.split_ascii_whitespace() {
            if n < max {
                let name = names.get(n).copied().unwrap_or("extra");
                cells[n] = text::number(cell, path, line, name, Nan::Reject)?;
            }
            n += 1;
        }
        if !widths.contains(&n) {
            let expected: Vec<String> = widths.iter().map(|w| w.to_string()).collect();
            return Err(DataError::format(
                Location::line(path, line),
                format!(
                    "{n} fields, expected {} ({})",
                    expected.join(" or "),
                    names.join(" ")
                ),
            ));
        }
        time.push(cells[0]);
        values.push(row(&cells[..n], line)?);
        lines.push(line);
    }
    if time.is_empty() {
        return Err(DataError::format(
            Location::file(path),
            "no samples: the file is empty",
        ));
    }
    text::check_line_break(content, lines.last().map(|&l| Location::line(path, l)), "")?;
    // Gaps are not errors here: they split the recording (see `intervals`).
    text::check_time(&time, &lines, path, names[0], f64::INFINITY)?;
    Ok(Stream {
        path: path.to_path_buf(),
        time,
        values,
        lines,
    })
}

fn read_vec_stream(path: &Path, names: &[&str]) -> Result<Stream<DeviceVec>> {
    read_stream(path, names, &[4], CutOff::Refuse, |c, _| {
        Ok(DeviceVec::new(c[1], c[2], c[3]))
    })
}

fn read_rotation_vector(path: &Path) -> Result<Stream<WorldFromDevice>> {
    let names = ["t", "qx", "qy", "qz", "qw", "heading_accuracy"];
    read_stream(path, &names, &[4, 5, 6], CutOff::Refuse, |c, line| {
        // Old Android versions give only x, y, z.
        android::rotation_vector([c[1], c[2], c[3]], c.get(4).copied()).map_err(|message| {
            DataError::format(Location::line(path, line).with_field("qw"), message)
        })
    })
}

fn read_time_diff(path: &Path) -> Result<f64> {
    let bytes = text::read_file(path)?;
    let content = text::as_text(&bytes, path)?;
    let mut cells = text::lines(content)
        .flat_map(|(line, l)| l.split_ascii_whitespace().map(move |c| (line, c)));
    let (line, cell) = cells.next().ok_or_else(|| {
        DataError::format(
            Location::file(path),
            "empty: expected one number, timeDiff in s",
        )
    })?;
    let value = text::number(cell, path, line, "timeDiff", Nan::Reject)?;
    if let Some((line, extra)) = cells.next() {
        return Err(DataError::format(
            Location::line(path, line),
            format!("unexpected `{}` after timeDiff", text::snippet(extra)),
        ));
    }
    Ok(value)
}

/// The value of `key` in the ini-style file `path` (`[Section]` lines, `key = value` lines):
/// the first in `section` (any section when `None`), with its line. `None` when the file is not
/// there (`record.properties` is optional) or has no such key. A small hand-written file: its
/// last line needs no line break.
fn ini_value(path: &Path, section: Option<&str>, key: &str) -> Result<Option<(usize, String)>> {
    if !text::present(path) {
        return Ok(None);
    }
    let bytes = text::read_file(path)?;
    let content = text::as_text(&bytes, path)?;
    let mut current: Option<&str> = None;
    for (line, l) in text::lines(content) {
        let l = l.trim();
        if let Some(name) = l.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
            current = Some(name.trim());
            continue;
        }
        let Some((k, value)) = l.split_once('=') else {
            continue;
        };
        if k.trim() == key && (section.is_none() || current == section) {
            return Ok(Some((line, value.trim().to_owned())));
        }
    }
    Ok(None)
}

/// The phone of a run named `<Person>_<Phone>_<Dist>_<Motion>`, as a model name: the known
/// Tyrex phones spelled as their makers do (`Nexus5` is `Nexus 5`, `iPhone4S` `iPhone 4S`,
/// `iPhone5` `iPhone 5`), any other as it is written.
pub fn phone_of(name: &str) -> Option<String> {
    let mut parts = name.split('_');
    let phone = parts.nth(1)?;
    if parts.count() < 2 || phone.is_empty() {
        return None;
    }
    Some(
        match phone {
            "Nexus5" => "Nexus 5",
            "iPhone4S" => "iPhone 4S",
            "iPhone5" => "iPhone 5",
            other => other,
        }
        .to_owned(),
    )
}

/// The run's device: `Model` in `file` (`section` of it) when given and usable, else the phone
/// of the run's name, with the IMU rate of the accelerometer and gyroscope streams. An unusable
/// `Model` (see [`DeviceInfo::new`]) is a warning, not an error: the device is a label.
fn device_of(
    file: &Path,
    section: Option<&str>,
    name: &str,
    acce: &Stream<DeviceVec>,
    gyro: &Stream<DeviceVec>,
    warnings: &mut Vec<String>,
) -> Result<Option<DeviceInfo>> {
    let given = match ini_value(file, section, "Model")? {
        Some((line, model)) => match DeviceInfo::new(&model) {
            Ok(d) => Some(d),
            Err(e) => {
                warnings.push(format!(
                    "{}:{line}: field `Model`: {e}: the device is taken from the run's name",
                    shown(file)
                ));
                None
            }
        },
        None => None,
    };
    let device = given.or_else(|| DeviceInfo::new(&phone_of(name)?).ok());
    Ok(device.map(|d| crate::device::with_imu_rate(d, &acce.time, &gyro.time)))
}

/// A warning when many accelerometer readings sit exactly at the largest magnitude seen: the
/// sensor's range was exceeded (the Nexus 5 clips at 2 g, 19.55 m/s^2, in 12-28 % of the samples
/// of the running sequences), so the linear acceleration is wrong there.
fn clipping(acce: &Stream<DeviceVec>) -> Option<String> {
    let abs = |v: &DeviceVec| v.to_array().map(f64::abs);
    let peak = acce.values.iter().flat_map(abs).fold(0.0, f64::max);
    let clipped = acce
        .values
        .iter()
        .filter(|v| abs(v).iter().any(|&c| c >= peak - 1e-6))
        .count();
    let share = clipped as f64 / acce.values.len() as f64;
    // No phone accelerometer has a range below 2 g, and a phone at rest repeats its (noise-free
    // or quantized) reading near 1 g: only peaks well above 1 g can be a range limit.
    (share > 0.005 && peak > 1.5 * STANDARD_GRAVITY).then(|| {
        format!(
            "{}: {:.1} % of the samples are clipped at +-{peak:.3} m/s^2: the accelerometer range \
             was exceeded",
            shown(&acce.path),
            share * 100.0
        )
    })
}

/// `seq` with its orientation's `jumps` bridged by the gyro ([`bridge_orientation_jumps`]), and
/// gravity and linear acceleration derived from the bridged orientation.
fn bridged(
    seq: Sequence,
    jumps: &[OrientationJump],
    gravity: f64,
    limits: &Validation,
) -> std::result::Result<Sequence, SequenceError> {
    let mut p = seq.into_parts();
    p.orientation = bridge_orientation_jumps(&p.time, &p.gyro, &p.orientation, jumps);
    (p.gravity, p.linacce) = android::gravity_and_linacce(&p.orientation, &p.acce, gravity);
    Sequence::with_validation(p, limits)
}

/// Largest angle between the mocap's and the phone's up axis in the device frame at which the
/// two are taken to agree, degrees. Both come from orientations, not from the accelerometer, so
/// walking does not move them apart: clean runs agree within a few degrees (medians 1-3).
pub const MAX_MOCAP_TILT_DEG: f64 = 20.0;

/// Blocks judged as a whole, seconds: long enough for the mean accelerometer to point along
/// gravity, short enough to cut little around a fault.
const TILT_BLOCK_S: f64 = 1.0;

/// Largest angle between a block's mean accelerometer and the phone orientation's up axis at
/// which the accelerometer discredits the mocap, degrees: 1.5-2.5 where the mocap mis-solves,
/// 17-80 in running blocks where both the mocap and the attitude may be off.
const ACCE_SIDES_DEG: f64 = 10.0;

/// Which of the mocap and the phone's own orientation a block of disagreement discredits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum TiltVerdict {
    Agree,
    /// The accelerometer sides with the phone: the mocap mis-solved the rigid body.
    MocapWrong,
    /// The accelerometer sides with the mocap: the phone's orientation filter lost its tilt
    /// (Core Motion does while running with a clipped accelerometer).
    PhoneWrong,
}

/// Judges each mocap frame (`time` on the phone clock, orientations `mocap`) in blocks of
/// [`TILT_BLOCK_S`]: where the median angle between the mocap's and the phone orientation's up
/// axis exceeds `max_deg`, the block's mean accelerometer (nearly gravity over a second) decides
/// which of the two is wrong: the mocap only when the accelerometer is within
/// [`ACCE_SIDES_DEG`] of the phone, the phone whenever it is closer to the mocap. Frames outside `spans` (where every phone stream has data) are
/// not judged: they are cut later.
fn judge_tilt(
    time: &[f64],
    mocap: &[WorldFromDevice],
    phone: &Stream<WorldFromDevice>,
    acce: &Stream<DeviceVec>,
    spans: &[(f64, f64)],
    max_deg: f64,
) -> Vec<TiltVerdict> {
    let mut verdicts = vec![TiltVerdict::Agree; time.len()];
    if max_deg == f64::INFINITY {
        return verdicts;
    }
    let up = WorldVec::new(0.0, 0.0, 1.0);
    let angle = |a: DeviceVec, b: DeviceVec| {
        let cos = a.dot(b) / (a.norm() * b.norm());
        cos.clamp(-1.0, 1.0).acos().to_degrees()
    };
    for &(start, end) in spans {
        let first = time.partition_point(|&t| t < start);
        let last = time.partition_point(|&t| t <= end);
        let mut i = first;
        while i < last {
            let j = (time[i..last].partition_point(|&t| t < time[i] + TILT_BLOCK_S) + i).max(i + 1);
            let block = &time[i..j];
            let phone_at = interpolate_rot(&phone.time, &phone.values, block);
            let acce_at = interpolate_vec3(&acce.time, &acce.values, block);
            let (mut m_sum, mut p_sum, mut a_sum) =
                (DeviceVec::ZERO, DeviceVec::ZERO, DeviceVec::ZERO);
            let mut diffs = Vec::with_capacity(block.len());
            for ((m, p), a) in mocap[i..j].iter().zip(&phone_at).zip(&acce_at) {
                let (m_up, p_up) = (m.inverse() * up, p.inverse() * up);
                diffs.push(angle(m_up, p_up));
                m_sum += m_up;
                p_sum += p_up;
                a_sum += *a;
            }
            diffs.sort_unstable_by(f64::total_cmp);
            if diffs[diffs.len() / 2] > max_deg {
                let (to_phone, to_mocap) = (angle(a_sum, p_sum), angle(a_sum, m_sum));
                // The mocap is dropped only on clear evidence: a running phone's clipped
                // accelerometer can side with a wrong orientation by chance.
                let verdict = if to_phone < ACCE_SIDES_DEG && to_phone < to_mocap {
                    TiltVerdict::MocapWrong
                } else if to_mocap < to_phone {
                    TiltVerdict::PhoneWrong
                } else {
                    TiltVerdict::Agree
                };
                verdicts[i..j].fill(verdict);
            }
            i = j;
        }
    }
    verdicts
}

/// The stretches of frames judged `which`, `a-b s` (phone clock), the first few, and their
/// number of frames.
fn verdict_spans(time: &[f64], verdicts: &[TiltVerdict], which: TiltVerdict) -> (usize, String) {
    let mut spans: Vec<(f64, f64)> = Vec::new();
    let mut frames = 0;
    for (i, (&t, &v)) in time.iter().zip(verdicts).enumerate() {
        if v != which {
            continue;
        }
        frames += 1;
        match spans.last_mut() {
            Some(s) if i > 0 && verdicts[i - 1] == which => s.1 = t,
            _ => spans.push((t, t)),
        }
    }
    (frames, spans_text(&spans))
}

/// Mocap frames: times (phone clock), positions, orientations.
type Mocap = (Vec<f64>, Vec<WorldVec>, Vec<WorldFromDevice>);

/// `mocap` without the frames `lost` says are lost.
fn without_lost(mocap: Mocap, lost: impl Fn(usize) -> bool) -> Mocap {
    let (t, p, q) = mocap;
    let mut kept = (Vec::new(), Vec::new(), Vec::new());
    for i in (0..t.len()).filter(|&i| !lost(i)) {
        kept.0.push(t[i]);
        kept.1.push(p[i]);
        kept.2.push(q[i]);
    }
    kept
}

fn stream_intervals<T>(s: &Stream<T>, max_gap: f64, warnings: &mut Vec<String>) -> Vec<(f64, f64)> {
    intervals(&s.time, max_gap, |i| {
        warnings.push(format!(
            "{}:{}: gap of {:.3} s in the samples at {:.3} s (phone clock): recording split",
            shown(&s.path),
            s.lines[i],
            s.time[i] - s.time[i - 1],
            s.time[i - 1]
        ));
    })
}

/// The phone streams of a run, in the Android sensor conventions (device frame, m/s^2, rad/s,
/// world-from-device orientation), on the phone clock: what each layout's reader gives the
/// shared checks, gap handling, time alignment and resampling of [`read`].
struct PhoneStreams {
    acce: Stream<DeviceVec>,
    gyro: Stream<DeviceVec>,
    orientation: Stream<WorldFromDevice>,
    source: OrientationSource,
    device: Option<DeviceInfo>,
    /// The clipping warning of the layout's accelerometer, if any.
    clipping: Option<String>,
}

/// Reads the streams of an Android run folder.
fn read_android(dir: &Path, name: &str, warnings: &mut Vec<String>) -> Result<PhoneStreams> {
    let acce = read_vec_stream(&dir.join("accelerometer.txt"), &["t", "ax", "ay", "az"])?;
    let gyro = read_vec_stream(
        &dir.join("gyroscope-calibrated.txt"),
        &["t", "wx", "wy", "wz"],
    )?;
    let orientation = read_rotation_vector(&dir.join("rotation-vector.txt"))?;
    let device = device_of(
        &dir.join("record.properties"),
        None,
        name,
        &acce,
        &gyro,
        warnings,
    )?;
    Ok(PhoneStreams {
        clipping: clipping(&acce),
        acce,
        gyro,
        orientation,
        source: OrientationSource::RotationVector,
        device,
    })
}

/// Refuses options no reading can follow, by field: NaN compares false, so a NaN gap limit
/// would split nothing and a NaN tilt or gyro limit trust both, unsaid; phone streams are never
/// interpolated across an unbounded gap (that would invent them).
fn check_options(dir: &Path, o: &TyrexOptions) -> Result<()> {
    o.validation.check_output_rate(o.rate_hz, dir, "rate_hz")?;
    let finite_positive = |v: f64| v.is_finite() && v > 0.0;
    const POSITIVE: &str = "a finite number above 0";
    for (field, value, ok, rule) in [
        (
            "max_mocap_gap_s",
            o.max_mocap_gap_s,
            o.max_mocap_gap_s > 0.0,
            "above 0 (infinity interpolates across every loss)",
        ),
        (
            "max_sensor_gap_s",
            o.max_sensor_gap_s,
            finite_positive(o.max_sensor_gap_s),
            POSITIVE,
        ),
        ("gravity", o.gravity, finite_positive(o.gravity), POSITIVE),
        (
            "min_part_s",
            o.min_part_s,
            o.min_part_s.is_finite() && o.min_part_s >= 0.0,
            "a finite number of at least 0",
        ),
        (
            "max_mocap_tilt_deg",
            o.max_mocap_tilt_deg,
            o.max_mocap_tilt_deg > 0.0,
            "above 0 (infinity trusts both)",
        ),
        (
            "max_mocap_gyro_rad",
            o.max_mocap_gyro_rad,
            o.max_mocap_gyro_rad > 0.0,
            "above 0 (infinity trusts the mocap)",
        ),
        (
            "extra_time_diff_s",
            o.extra_time_diff_s,
            o.extra_time_diff_s.is_finite(),
            "a finite number",
        ),
    ] {
        if !ok {
            return Err(DataError::format(
                Location::file(dir).with_field(field),
                format!("{value}: expected {rule}"),
            ));
        }
    }
    Ok(())
}

/// Reads one run folder, `datasets/android/<name>/` or `datasets/ios/<name>/` (see
/// [`layout_of`]) and, when [`TyrexOptions::ground_truth`] is set and `datasets/qualisys/` holds
/// its `.mat` (see [`mat_path`]), its ground truth. See the module documentation for the
/// layouts, frames, time alignment and gap handling.
pub fn read(dir: impl AsRef<Path>, options: &TyrexOptions) -> Result<TyrexRead> {
    let dir = dir.as_ref();
    check_options(dir, options)?;
    // `.` or `..` have no file name of their own: take the folder's real name.
    let name = dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .or_else(|| {
            let real = dir.canonicalize().ok()?;
            Some(real.file_name()?.to_string_lossy().into_owned())
        })
        .unwrap_or_default();
    let mut warnings = Vec::new();
    let placement = motion_of(&name);
    if placement.is_none() {
        warnings.push(format!(
            "`{name}` does not end in a known motion ({}): no placement",
            MOTIONS.join(", ")
        ));
    }

    let layout = layout_of(dir)?;
    let PhoneStreams {
        acce,
        gyro,
        orientation: rv,
        source,
        device,
        clipping,
    } = match layout {
        Layout::Android => read_android(dir, &name, &mut warnings)?,
        Layout::Ios => ios::read(dir, &name, &mut warnings)?,
    };

    let limits = &options.validation;
    acce.check(limits, Some(Channel::Acce), |v| v.to_array())?;
    gyro.check(limits, Some(Channel::Gyro), |v| v.to_array())?;
    rv.check(limits, None, |_| [0.0; 3])?;
    warnings.extend(clipping);
    let gap = options.max_sensor_gap_s;
    let mut spans = stream_intervals(&acce, gap, &mut warnings);
    spans = intersect(&spans, &stream_intervals(&gyro, gap, &mut warnings));
    spans = intersect(&spans, &stream_intervals(&rv, gap, &mut warnings));

    let mat = if options.ground_truth {
        ground_truth_file(dir)?
    } else {
        None
    };
    let mut time_diff_s = None;
    // Valid mocap frames on the phone clock.
    let mut truth: Option<Mocap> = None;
    if let Some(mat) = &mat {
        let diff = read_time_diff(&dir.join("timeAlignment.txt"))? + options.extra_time_diff_s;
        time_diff_s = Some(diff);
        let track = read_ground_truth(mat)?;
        let (mut t, mut p, mut q) = (Vec::new(), Vec::new(), Vec::new());
        for (time, pose) in track.time.iter().zip(&track.pose) {
            if let Some(pose) = pose {
                t.push(time - diff);
                p.push(pose.position);
                q.push(pose.orientation);
            }
        }
        let verdicts = judge_tilt(&t, &q, &rv, &acce, &spans, options.max_mocap_tilt_deg);
        let (wrong, at) = verdict_spans(&t, &verdicts, TiltVerdict::PhoneWrong);
        if wrong > 0 {
            warnings.push(format!(
                "{}: the phone's orientation tilts more than {} degrees from the mocap's, and \
                 the accelerometer sides with the mocap, for {wrong} of {} mocap frames ({at}): \
                 gravity and linear acceleration derived from it are wrong there (tracking with \
                 the orientation estimated from gyro and accelerometer avoids them)",
                shown(&rv.path),
                options.max_mocap_tilt_deg,
                t.len()
            ));
        }
        let (dropped, at) = verdict_spans(&t, &verdicts, TiltVerdict::MocapWrong);
        if dropped > 0 {
            warnings.push(format!(
                "{}: {dropped} of {} mocap frames tilted more than {} degrees from the phone's \
                 orientation, the accelerometer siding with the phone ({at}): the mocap \
                 mis-solved the body there; treated as mocap losses",
                shown(mat),
                t.len(),
                options.max_mocap_tilt_deg,
            ));
            (t, p, q) = without_lost((t, p, q), |i| verdicts[i] == TiltVerdict::MocapWrong);
        }
        let conflicts = mocap_gyro_conflicts(
            &t,
            &q,
            &gyro.time,
            &gyro.values,
            options.max_mocap_gyro_rad,
            options.max_mocap_gap_s,
        );
        if !conflicts.is_empty() {
            let before = t.len();
            let inside = |x: f64| conflicts.iter().any(|&(a, b)| x >= a && x <= b);
            let lost: Vec<bool> = t.iter().map(|&x| inside(x)).collect();
            (t, p, q) = without_lost((t, p, q), |i| lost[i]);
            warnings.push(format!(
                "{}: the mocap's rotation contradicts the gyro's (by more than {} rad over \
                 {MOCAP_CHECK_WINDOW_S} s, or in its offset from the gyro's attitude) in {} \
                 ({}, phone clock, with {MOCAP_PAD_S} s margins): the rigid body was \
                 solved flipped there; {} of {before} mocap frames treated as mocap losses",
                shown(mat),
                options.max_mocap_gyro_rad,
                counted(conflicts.len(), "stretch"),
                spans_text(&conflicts),
                before - t.len(),
            ));
        }
        if t.is_empty() {
            return Err(DataError::format(
                Location::file(mat).with_field("RigidBodies.Positions"),
                "no mocap frame left: every frame is NaN, or was cut out by the checks the \
                 warnings name (a rigid body that does not coincide with the device frame, or \
                 a `timeAlignment.txt` off by a tenth of a second, fails them all)",
            ));
        }
        // One warning for all the losses: a running run loses the body dozens of times.
        let mut losses = Vec::new();
        let gt_spans = intervals(&t, options.max_mocap_gap_s, |i| {
            losses.push((t[i - 1], t[i]))
        });
        if !losses.is_empty() {
            let longest = losses.iter().map(|(a, b)| b - a).fold(0.0, f64::max);
            warnings.push(format!(
                "{}: mocap lost the body {} (up to {longest:.3} s; {}, phone clock): recording \
                 split there",
                shown(mat),
                times(losses.len()),
                spans_text(&losses),
            ));
        }
        spans = intersect(&spans, &gt_spans);
        truth = Some((t, p, q));
    }

    let (kept, short): (Vec<_>, Vec<_>) = spans
        .iter()
        .copied()
        .filter(|(start, end)| end > start)
        .partition(|(start, end)| end - start >= options.min_part_s);
    if !short.is_empty() {
        warnings.push(format!(
            "{}: {} shorter than {} s dropped ({:.3} s in all; {}, phone clock)",
            shown(dir),
            counted(short.len(), "part"),
            options.min_part_s,
            short.iter().map(|(a, b)| b - a).sum::<f64>(),
            spans_text(&short),
        ));
    }
    if kept.is_empty() {
        return Err(DataError::format(
            Location::file(dir),
            format!(
                "no stretch of at least {} s where every phone stream{} has data without long gaps",
                options.min_part_s,
                if truth.is_some() {
                    " and the ground truth"
                } else {
                    ""
                }
            ),
        ));
    }

    let mut sequences = Vec::with_capacity(kept.len());
    for (k, &(start, end)) in kept.iter().enumerate() {
        let time = uniform_timeline(start, end, options.rate_hz);
        let orientation = interpolate_rot(&rv.time, &rv.values, &time);
        let acce_i = interpolate_vec3(&acce.time, &acce.values, &time);
        let (gravity, linacce) =
            android::gravity_and_linacce(&orientation, &acce_i, options.gravity);
        let ground_truth = truth.as_ref().map(|(t, p, q)| GroundTruth {
            position: interpolate_vec3(t, p, &time),
            orientation: interpolate_rot(t, q, &time),
        });
        let parts = SequenceParts {
            name: part_name(&name, k, kept.len()),
            placement: placement.map(str::to_owned),
            gyro: interpolate_vec3(&gyro.time, &gyro.values, &time),
            acce: acce_i,
            linacce,
            gravity,
            magnet: None,
            orientation,
            orientation_source: Some(source),
            ground_truth,
            steps: None,
            device: device.clone(),
            time,
        };
        let seq = Sequence::with_validation(parts, limits).map_err(|e| {
            // The accelerometer's scale is the one check the streams could not make alone.
            let path = match e {
                SequenceError::AcceScale { .. } => &acce.path,
                SequenceError::GyroScale { .. }
                | SequenceError::GyroDirection { .. }
                | SequenceError::GyroAxis { .. } => &gyro.path,
                _ => dir,
            };
            text::sequence_error(path, None, &TyrexFields, e)
        })?;
        let jumps = seq.orientation_jumps();
        warnings.extend(orientation_jump_warning(&shown(&rv.path), &jumps).map(|w| {
            if options.bridge_orientation_jumps {
                format!("{w}; bridged by the gyro, the heading kept across them")
            } else {
                w
            }
        }));
        let seq = if options.bridge_orientation_jumps && !jumps.is_empty() {
            bridged(seq, &jumps, options.gravity, limits)
                .map_err(|e| text::sequence_error(&rv.path, None, &TyrexFields, e))?
        } else {
            seq
        };
        sequences.push(seq);
    }
    Ok(TyrexRead {
        sequences,
        warnings,
        time_diff_s,
        device_model: device.map(|d| d.model().to_owned()),
        layout,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two minutes of one-second judgements at 100 Hz: the phone flat, the accelerometer on
    /// gravity, the mocap and phone tilted by `mocap_tilt(t)` and `phone_tilt(t)` degrees about x.
    fn judge(
        mocap_tilt: impl Fn(f64) -> f64,
        phone_tilt: impl Fn(f64) -> f64,
        acce_tilt: impl Fn(f64) -> f64,
        spans: &[(f64, f64)],
        max_deg: f64,
    ) -> Vec<TiltVerdict> {
        let time: Vec<f64> = (0..12_000).map(|i| i as f64 / 100.0).collect();
        let x = ridi_frames::nalgebra::Vector3::x_axis();
        let rot = |deg: f64| WorldFromDevice::from_axis_angle(&x, deg.to_radians());
        fn stream<T>(time: &[f64], values: Vec<T>) -> Stream<T> {
            Stream {
                path: PathBuf::new(),
                time: time.to_vec(),
                values,
                lines: vec![0; time.len()],
            }
        }
        let phone = stream(&time, time.iter().map(|&t| rot(phone_tilt(t))).collect());
        let acce = stream(
            &time,
            time.iter()
                .map(|&t| rot(acce_tilt(t)).inverse() * WorldVec::new(0.0, 0.0, 9.8))
                .collect(),
        );
        let mocap: Vec<_> = time.iter().map(|&t| rot(mocap_tilt(t))).collect();
        judge_tilt(&time, &mocap, &phone, &acce, spans, max_deg)
    }

    #[test]
    fn tilt_disagreement_discredits_whichever_the_accelerometer_contradicts() {
        let whole = [(0.0, 120.0)];
        let fault = |t: f64| if (30.0..40.0).contains(&t) { 45.0 } else { 0.0 };
        let at = |v: &[TiltVerdict], t: f64| v[(t * 100.0) as usize];
        // The mocap tilts alone: it is wrong for those ten seconds, nowhere else.
        let v = judge(fault, |_| 0.0, |_| 0.0, &whole, MAX_MOCAP_TILT_DEG);
        assert_eq!(at(&v, 35.0), TiltVerdict::MocapWrong);
        assert_eq!(at(&v, 29.0), TiltVerdict::Agree);
        assert_eq!(at(&v, 41.0), TiltVerdict::Agree);
        let wrong = v.iter().filter(|&&x| x == TiltVerdict::MocapWrong).count();
        assert_eq!(wrong, 1000);
        // The phone's orientation tilts while the accelerometer follows the mocap.
        let v = judge(|_| 0.0, fault, |_| 0.0, &whole, MAX_MOCAP_TILT_DEG);
        assert_eq!(at(&v, 35.0), TiltVerdict::PhoneWrong);
        assert!(!v.contains(&TiltVerdict::MocapWrong));
        // Under the limit, and a single glitching frame, are agreement.
        let glitch = |t: f64| {
            if (50.0..50.01).contains(&t) {
                90.0
            } else {
                15.0
            }
        };
        let v = judge(glitch, |_| 0.0, |_| 0.0, &whole, MAX_MOCAP_TILT_DEG);
        assert!(v.iter().all(|&x| x == TiltVerdict::Agree));
        // Outside the spans nothing is judged (the phone streams have a gap there), and an
        // infinite limit judges nothing.
        let v = judge(
            fault,
            |_| 0.0,
            |_| 0.0,
            &[(0.0, 25.0), (45.0, 120.0)],
            MAX_MOCAP_TILT_DEG,
        );
        assert!(v.iter().all(|&x| x == TiltVerdict::Agree));
        let v = judge(fault, |_| 0.0, |_| 0.0, &whole, f64::INFINITY);
        assert!(v.iter().all(|&x| x == TiltVerdict::Agree));
    }

    #[test]
    fn verdict_spans_name_the_stretches() {
        use TiltVerdict::*;
        let time: Vec<f64> = (0..10).map(f64::from).collect();
        let v = [
            Agree, MocapWrong, MocapWrong, Agree, MocapWrong, Agree, Agree, Agree, Agree, Agree,
        ];
        assert_eq!(
            verdict_spans(&time, &v, MocapWrong),
            (3, "1.00-2.00 s, 4.00-4.00 s".to_string())
        );
        assert_eq!(verdict_spans(&time, &v, PhoneWrong), (0, String::new()));
    }

    #[test]
    fn motion_is_the_last_name_part() {
        assert_eq!(
            motion_of("Jakob_Nexus5_NoDist_RunningPocket"),
            Some("RunningPocket")
        );
        assert_eq!(motion_of("x_ar"), Some("AR"));
        assert_eq!(motion_of("Jakob_Nexus5_NoDist_Dancing"), None);
        assert_eq!(motion_of(""), None);
    }

    #[test]
    fn mat_path_is_beside_the_android_folder() {
        let p = mat_path(Path::new("/d/datasets/android/A_B_C_AR")).unwrap();
        assert_eq!(p, Path::new("/d/datasets/qualisys/A_B_C_AR.mat"));
    }
}
