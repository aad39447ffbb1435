//! Reader for the RoNIN dataset (Herath, Yan, Furukawa, "RoNIN: Robust Neural Inertial
//! Navigation in the Wild", ICRA 2020; <https://github.com/Sachini/ronin>): Android phones
//! carried naturally (in the hand, a pocket, a bag) by 100 people, with the pose of a second,
//! body-mounted Tango phone as ground truth.
//!
//! # Layout
//! One folder per sequence (`a000_1`, ...), as RoNIN's `compile_dataset_h5.py` writes it:
//! ```text
//! a000_1/
//!   info.json    calibration, orientation errors, start frame, device
//!   data.hdf5    synced/{time, gyro_uncalib, acce, game_rv, grav, linacce, magnet, ...}
//!                pose/{tango_pos, tango_ori, ekf_ori}
//!                raw/{imu, tango}/...   (unsynchronized streams, not read)
//! ```
//! Every `synced` and `pose` dataset has one row per frame of `synced/time` (seconds, 200 Hz).
//! The HDF5 files are read by ridi-data's own reader of the subset h5py writes by default
//! (contiguous, unfiltered `float64` datasets), with no system library.
//!
//! # What is read, as RoNIN's own loader reads it
//! `GlobSpeedSequence.load` (`source/data_glob_speed.py`) and `select_orientation_source`
//! (`source/data_utils.py`), with their defaults `grv_only = False`, `max_ori_error = 20`:
//!
//! | sequence | from |
//! | --- | --- |
//! | time, s | `synced/time` |
//! | gyro, rad/s | `synced/gyro_uncalib − imu_init_gyro_bias` |
//! | accelerometer, m/s² | `imu_acce_scale ⊙ (synced/acce − imu_acce_bias)` |
//! | orientation (world = Tango's) | `tango_ori[0] ⊗ start_calibration ⊗ src[0]⁻¹ ⊗ src` |
//! | ground-truth position, m | `pose/tango_pos` |
//! | gravity, linear acceleration | `synced/grav` and `synced/linacce` (Android's sensors) |
//! | magnetometer, µT | `synced/magnet`, when present |
//!
//! `src`, the orientation source, is chosen from `info.json`'s end-alignment errors
//! (degrees): the game rotation vector (`synced/game_rv`, `w, x, y, z`) when `grv_only` or
//! `grv_ori_error < max_ori_error`, else the source with the smallest of
//! `gyro_integration_error`, `grv_ori_error`, `ekf_ori_error` (numpy's `argmin`: the first
//! smallest, the first NaN if any is NaN): the gyro integrated from `game_rv[0]` (RoNIN's
//! `gyro_integration`, first-order, renormalized each step), the game rotation vector or
//! RoNIN's EKF estimate (`pose/ekf_ori`). The rotation `tango_ori[0] ⊗ start_calibration ⊗
//! src[0]⁻¹` turns the source's world into the Tango's at the first frame (`start_calibration`
//! is the IMU phone's rotation into the Tango phone at the start, when both were held
//! together). Frames before `info.json`'s `start_frame` (that calibration) are dropped
//! after the alignment, as RoNIN drops them. Quaternions are normalized (RoNIN's are not; the
//! difference is their deviation from unit norm).
//!
//! Gravity and linear acceleration are Android's own sensors from `synced/grav` (or
//! `synced/gravity`) and `synced/linacce`, what RoNIN's RIDI baseline reads; a file without
//! them gets gravity from the orientation ([`RoninOptions::gravity`] long) and linear
//! acceleration = accelerometer − gravity.
//!
//! # The ground truth is another phone's
//! `pose/tango_pos` is the position of the Tango phone strapped to the walker's body, not of
//! the phone whose IMU is read: a hand-held phone's swing or a pocket's leg motion is not in
//! it. The sequence's ground-truth orientation is the IMU phone's chosen source aligned to the
//! Tango world (not `pose/tango_ori`, the Tango phone's own attitude). Velocity targets computed
//! from it (`ridi_features::compute_targets`) are then the body's velocity expressed in the IMU
//! phone's stabilized frame, exactly the targets of RoNIN's RIDI baseline
//! (`source/baselines/data_stabilized_local_speed.py`). Orientation errors against this ground
//! truth mean nothing (it is the device orientation itself).
//!
//! # Errors
//! Every error names the file: `data.hdf5` and the dataset (a missing dataset, a wrong shape or
//! type, a row count that differs from `synced/time`'s, a truncated or corrupt file, a
//! quaternion far from unit norm), or `info.json` and the field (missing, not a number, the
//! wrong count of numbers, a `start_frame` beyond the data); then the sequence's validation
//! ([`Validation`]), naming the dataset.
//!
//! # Example
//! ```no_run
//! use ridi_data::ronin::{self, RoninOptions};
//!
//! let seq = ronin::read("ronin/train_dataset_1/a000_1", &RoninOptions::default())?;
//! println!("{}: {} frames, orientation from {} ({:.1} deg end error)",
//!          seq.sequence.name(), seq.sequence.len(), seq.orientation, seq.orientation_error);
//! # Ok::<(), ridi_data::DataError>(())
//! ```

use std::fmt;
use std::path::{Path, PathBuf};

use ridi_frames::{DeviceVec, QuatError, STANDARD_GRAVITY, WorldFromDevice, WorldVec};
use serde_json::Value;

use crate::error::{DataError, Location, Result, counted};
use crate::hdf5::Hdf5File;
use crate::options::ReadOptions;
use crate::text;
use crate::{
    Channel, DeviceInfo, GroundTruth, OrientationSource, Sequence, SequenceParts, Validation,
};

/// The HDF5 file of a sequence folder.
pub const DATA_FILE: &str = "data.hdf5";
/// The metadata of a sequence folder.
pub const INFO_FILE: &str = "info.json";

/// Largest `info.json` read, bytes (RoNIN's are under 2 KiB).
const MAX_INFO_BYTES: u64 = 1 << 20;

/// How RoNIN sequences are read; the defaults are RoNIN's.
#[derive(Debug, Clone, PartialEq)]
pub struct RoninOptions {
    /// Always use the game rotation vector (RoNIN's `grv_only`, `False` by default; its test
    /// scripts of the RIDI baseline set it).
    pub grv_only: bool,
    /// Largest `grv_ori_error` (degrees) at which the game rotation vector is used without
    /// looking at the other sources (RoNIN's `max_ori_error`, 20).
    pub max_ori_error: f64,
    /// Gravity magnitude for a file without `synced/grav`, m/s².
    pub gravity: f64,
    /// Placement label of the sequences (none by default: RoNIN does not label them; a list
    /// file's placement overrides it).
    pub placement: Option<String>,
    /// Limits the sequence is checked against.
    pub validation: Validation,
}

impl Default for RoninOptions {
    fn default() -> Self {
        Self {
            grv_only: false,
            max_ori_error: 20.0,
            gravity: STANDARD_GRAVITY,
            placement: None,
            validation: Validation::default(),
        }
    }
}

impl From<&ReadOptions> for RoninOptions {
    /// The validation limits of the generic reader options, RoNIN's defaults for the rest.
    fn from(o: &ReadOptions) -> Self {
        Self {
            validation: o.validation.clone(),
            ..Self::default()
        }
    }
}

/// The orientation sources RoNIN chooses from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RoninOrientation {
    /// The gyro integrated from the first game rotation vector.
    GyroIntegration,
    /// Android's game rotation vector, `synced/game_rv`.
    GameRotationVector,
    /// RoNIN's EKF estimate, `pose/ekf_ori`.
    Ekf,
}

impl RoninOrientation {
    /// RoNIN's name (`gyro_integration`, `game_rv`, `ekf`).
    pub fn name(self) -> &'static str {
        match self {
            RoninOrientation::GyroIntegration => "gyro_integration",
            RoninOrientation::GameRotationVector => "game_rv",
            RoninOrientation::Ekf => "ekf",
        }
    }

    /// The sequence's [`OrientationSource`].
    pub fn source(self) -> OrientationSource {
        match self {
            RoninOrientation::GyroIntegration => OrientationSource::GyroIntegration,
            RoninOrientation::GameRotationVector => OrientationSource::GameRotationVector,
            RoninOrientation::Ekf => OrientationSource::Ekf,
        }
    }

    /// The dataset the source comes from, for errors.
    fn dataset(self) -> &'static str {
        match self {
            RoninOrientation::GyroIntegration => "synced/gyro_uncalib",
            RoninOrientation::GameRotationVector => "synced/game_rv",
            RoninOrientation::Ekf => "pose/ekf_ori",
        }
    }
}

impl fmt::Display for RoninOrientation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What [`read`] found in one sequence folder.
#[derive(Debug, Clone, PartialEq)]
pub struct RoninSequence {
    /// The recording from `start_frame` on (see the module documentation).
    pub sequence: Sequence,
    /// The orientation source chosen.
    pub orientation: RoninOrientation,
    /// Its end-alignment error from `info.json`, degrees.
    pub orientation_error: f64,
    /// `info.json`'s `start_frame` (0 when absent): the frames dropped at the start.
    pub start_frame: usize,
}

/// Whether `folder` looks like a RoNIN sequence folder: it holds a `data.hdf5`.
pub fn looks_like(folder: &Path) -> bool {
    crate::text::present(&folder.join(DATA_FILE))
}

/// The files a read of `folder` takes.
pub fn files(folder: &Path) -> [PathBuf; 2] {
    [folder.join(DATA_FILE), folder.join(INFO_FILE)]
}

/// Reads the sequence folder `folder` (holding `data.hdf5` and `info.json`). See the module
/// documentation.
pub fn read(folder: impl AsRef<Path>, options: &RoninOptions) -> Result<RoninSequence> {
    let folder = folder.as_ref();
    let [data, info] = files(folder);
    let info_bytes = text::read_file_bounded(&info, MAX_INFO_BYTES)?;
    let data_bytes = text::read_file(&data)?;
    parse(data_bytes, &info_bytes, folder, options)
}

/// Parses a sequence from the contents of its `data.hdf5` and `info.json`; `folder` names the
/// files in errors and gives the sequence its name.
pub fn parse(
    data: Vec<u8>,
    info: &[u8],
    folder: &Path,
    options: &RoninOptions,
) -> Result<RoninSequence> {
    let [data_path, info_path] = files(folder);
    let info = Info::parse(info, &info_path)?;
    let file = Hdf5File::from_bytes(data, &data_path)?;
    let h5 = Datasets {
        file: &file,
        path: &data_path,
    };

    let time = h5.required("synced/time", 0, None)?;
    let n = time.len();
    let rows = Some(n);
    let gyro_uncalib = h5.required("synced/gyro_uncalib", 3, rows)?;
    let acce_raw = h5.required("synced/acce", 3, rows)?;
    let game_rv = h5.required("synced/game_rv", 4, rows)?;
    let tango_pos = h5.required("pose/tango_pos", 3, rows)?;
    let tango_ori = h5.required("pose/tango_ori", 4, rows)?;
    if n < 2 {
        return Err(h5.error(
            "synced/time",
            format!("{}: a sequence needs at least 2", counted(n, "frame")),
        ));
    }
    let start = info.start_frame;
    if start >= n - 1 {
        return Err(DataError::format(
            Location::file(&info_path).with_field("start_frame"),
            format!("start_frame {start} leaves fewer than 2 of the {n} frames of synced/time"),
        ));
    }

    // select_orientation_source.
    let errors = info.ori_errors;
    let pick = if options.grv_only || errors[1] < options.max_ori_error {
        1
    } else {
        argmin(&errors)
    };
    let source = [
        RoninOrientation::GyroIntegration,
        RoninOrientation::GameRotationVector,
        RoninOrientation::Ekf,
    ][pick];
    let gyro: Vec<[f64; 3]> = rows3(&gyro_uncalib)
        .map(|g| std::array::from_fn(|k| g[k] - info.gyro_bias[k]))
        .collect();
    let ori: Vec<[f64; 4]> = match source {
        RoninOrientation::GameRotationVector => rows4(&game_rv).collect(),
        RoninOrientation::Ekf => rows4(&h5.required("pose/ekf_ori", 4, rows)?).collect(),
        RoninOrientation::GyroIntegration => {
            gyro_integration(&time, &gyro, rows4(&game_rv).next().unwrap_or_default())
        }
    };

    // GlobSpeedSequence.load: the source in the Tango world.
    let tango0 = rows4(&tango_ori).next().unwrap_or_default();
    if let Err(e) = WorldFromDevice::from_wxyz(tango0) {
        return Err(h5.error("pose/tango_ori", format!("row 0: {}", quat_message(e))));
    }
    let rotor = qmul(qmul(tango0, info.start_calibration), qconj(ori[0]));
    let mut orientation = Vec::with_capacity(n - start);
    for (i, &q) in ori.iter().enumerate().skip(start) {
        let q = WorldFromDevice::from_wxyz(qmul(rotor, q)).map_err(|e| {
            h5.error(
                source.dataset(),
                format!(
                    "row {i}: {} (orientation source {source}, aligned to the Tango world)",
                    quat_message(e)
                ),
            )
        })?;
        orientation.push(q);
    }

    let vecs = |rows: Vec<[f64; 3]>| -> Vec<DeviceVec> {
        rows.into_iter()
            .skip(start)
            .map(DeviceVec::from_array)
            .collect()
    };
    let acce: Vec<DeviceVec> = vecs(
        rows3(&acce_raw)
            .map(|a| std::array::from_fn(|k| info.acce_scale[k] * (a[k] - info.acce_bias[k])))
            .collect(),
    );
    let gyro = vecs(gyro);
    let grav_name = ["synced/grav", "synced/gravity"]
        .into_iter()
        .find(|name| file.contains(name).unwrap_or(false));
    let (gravity, linacce, fields) = match grav_name {
        Some(name) => {
            let gravity = vecs(rows3(&h5.required(name, 3, rows)?).collect());
            let (linacce, linacce_name) = match h5.optional("synced/linacce", 3, rows)? {
                Some(l) => (vecs(rows3(&l).collect()), "synced/linacce"),
                None => (
                    acce.iter().zip(&gravity).map(|(&a, &g)| a - g).collect(),
                    "linacce",
                ),
            };
            (
                gravity,
                linacce,
                RoninFields {
                    gravity: name,
                    linacce: linacce_name,
                },
            )
        }
        None => {
            let (g, l) = crate::android::gravity_and_linacce(&orientation, &acce, options.gravity);
            (
                g,
                l,
                RoninFields {
                    gravity: "gravity",
                    linacce: "linacce",
                },
            )
        }
    };
    let magnet = h5
        .optional("synced/magnet", 3, rows)?
        .map(|m| vecs(rows3(&m).collect()));
    let position: Vec<WorldVec> = rows3(&tango_pos)
        .skip(start)
        .map(WorldVec::from_array)
        .collect();

    let parts = SequenceParts {
        name: folder
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
        placement: options.placement.clone(),
        time: time[start..].to_vec(),
        gyro,
        acce,
        linacce,
        gravity,
        magnet,
        ground_truth: Some(GroundTruth {
            position,
            orientation: orientation.clone(),
        }),
        orientation,
        orientation_source: Some(source.source()),
        steps: None,
        device: info.device.as_deref().and_then(|d| DeviceInfo::new(d).ok()),
    };
    let sequence = Sequence::with_validation(parts, &options.validation)
        .map_err(|e| text::sequence_error(&data_path, None, &fields, e))?;
    Ok(RoninSequence {
        sequence,
        orientation: source,
        orientation_error: errors[pick],
        start_frame: start,
    })
}

/// numpy's `argmin`: the first NaN if any, else the first smallest.
fn argmin(v: &[f64; 3]) -> usize {
    if let Some(i) = v.iter().position(|x| x.is_nan()) {
        return i;
    }
    let mut best = 0;
    for (i, &x) in v.iter().enumerate() {
        if x < v[best] {
            best = i;
        }
    }
    best
}

fn quat_message(e: QuatError) -> String {
    match e {
        QuatError::NotUnit { norm } => format!("quaternion w,x,y,z has norm {norm:.4}, not 1"),
        other => other.to_string(),
    }
}

/// Hamilton product of `w, x, y, z` quaternions.
fn qmul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    let [aw, ax, ay, az] = a;
    let [bw, bx, by, bz] = b;
    [
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    ]
}

fn qconj(q: [f64; 4]) -> [f64; 4] {
    [q[0], -q[1], -q[2], -q[3]]
}

/// RoNIN's `gyro_integration` (`source/math_util.py`): from `init`, each step
/// `q += ½ Ω(ω) q Δt` with the previous frame's rate (the body-frame rate, `q ⊗ (0, ω)`),
/// then renormalized.
fn gyro_integration(time: &[f64], gyro: &[[f64; 3]], init: [f64; 4]) -> Vec<[f64; 4]> {
    let mut out = Vec::with_capacity(gyro.len());
    let mut q = init;
    out.push(q);
    for i in 1..gyro.len().min(time.len()) {
        let dt = time[i] - time[i - 1];
        let d = qmul(q, [0.0, gyro[i - 1][0], gyro[i - 1][1], gyro[i - 1][2]]);
        let mut next: [f64; 4] = std::array::from_fn(|k| q[k] + 0.5 * d[k] * dt);
        let norm = next.iter().map(|c| c * c).sum::<f64>().sqrt();
        next.iter_mut().for_each(|c| *c /= norm);
        q = next;
        out.push(q);
    }
    out
}

fn rows3(data: &[f64]) -> impl Iterator<Item = [f64; 3]> + '_ {
    data.chunks_exact(3).map(|c| [c[0], c[1], c[2]])
}

fn rows4(data: &[f64]) -> impl Iterator<Item = [f64; 4]> + '_ {
    data.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]])
}

/// The datasets of one `data.hdf5`, read with their shapes checked.
struct Datasets<'a> {
    file: &'a Hdf5File,
    path: &'a Path,
}

impl Datasets<'_> {
    fn error(&self, dataset: &str, message: impl Into<String>) -> DataError {
        DataError::format(
            Location::file(self.path).with_field(dataset),
            message.into(),
        )
    }

    /// The dataset `name`, `(rows, width)` (`width` 0: one-dimensional), `rows` of them when
    /// given; `None` when there is no such dataset.
    fn optional(&self, name: &str, width: usize, rows: Option<usize>) -> Result<Option<Vec<f64>>> {
        let Some(array) = self.file.read_f64(name)? else {
            return Ok(None);
        };
        let shape = &array.shape;
        let want = if width == 0 {
            "(N,)".to_owned()
        } else {
            format!("(N, {width})")
        };
        let ok = match (shape.as_slice(), width) {
            ([_], 0) => true,
            ([_, w], _) => *w == width && width > 0,
            _ => false,
        };
        if !ok {
            return Err(self.error(
                name,
                format!("shape {}, expected {want}", shape_text(shape)),
            ));
        }
        if let Some(n) = rows
            && shape[0] != n
        {
            return Err(self.error(
                name,
                format!(
                    "{} rows, but synced/time has {n}: every synced and pose dataset has one \
                     row per frame",
                    shape[0]
                ),
            ));
        }
        Ok(Some(array.data))
    }

    fn required(&self, name: &str, width: usize, rows: Option<usize>) -> Result<Vec<f64>> {
        self.optional(name, width, rows)?.ok_or_else(|| {
            self.error(
                name,
                format!(
                    "no dataset {name}: a RoNIN data.hdf5 has synced/time, synced/gyro_uncalib, \
                     synced/acce, synced/game_rv, pose/tango_pos and pose/tango_ori (a sequence \
                     without ground truth cannot be read)"
                ),
            )
        })
    }
}

fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// The dataset names of the sequence's channels, for validation errors.
struct RoninFields {
    gravity: &'static str,
    linacce: &'static str,
}

impl text::Fields for RoninFields {
    fn field(&self, channel: Channel, axis: Option<usize>) -> String {
        let name = match channel {
            Channel::Time => return "synced/time".to_owned(),
            Channel::Gyro => "synced/gyro_uncalib",
            Channel::Acce => "synced/acce",
            Channel::Linacce => self.linacce,
            Channel::Gravity => self.gravity,
            Channel::Magnet => "synced/magnet",
            Channel::Position => "pose/tango_pos",
        };
        match axis {
            Some(a) => format!("{name}[:, {a}]"),
            None => name.to_owned(),
        }
    }

    fn time_unit(&self) -> &str {
        "seconds"
    }
}

/// What is read from `info.json`.
struct Info {
    gyro_bias: [f64; 3],
    acce_bias: [f64; 3],
    acce_scale: [f64; 3],
    start_calibration: [f64; 4],
    /// `gyro_integration_error`, `grv_ori_error`, `ekf_ori_error` (NaN allowed).
    ori_errors: [f64; 3],
    start_frame: usize,
    device: Option<String>,
}

/// Largest |component| of `imu_init_gyro_bias` accepted, rad/s.
const MAX_GYRO_BIAS: f64 = 1.0;
/// Largest |component| of `imu_acce_bias` accepted, m/s^2.
const MAX_ACCE_BIAS: f64 = 5.0;
/// Accepted range of each component of `imu_acce_scale`.
const ACCE_SCALE_RANGE: (f64, f64) = (0.5, 2.0);

impl Info {
    fn parse(bytes: &[u8], path: &Path) -> Result<Info> {
        let text = text::as_text(bytes, path)?;
        let value: Value = serde_json::from_str(&python_json(text)).map_err(|e| {
            let at = match e.line() {
                0 => Location::file(path),
                line => Location::line(path, line),
            };
            DataError::format(at, format!("not valid JSON: {e}"))
        })?;
        let Some(object) = value.as_object() else {
            return Err(DataError::format(
                Location::file(path),
                "expected a JSON object of RoNIN's sequence metadata",
            ));
        };
        let err = |field: &str, message: String| {
            DataError::format(Location::file(path).with_field(field), message)
        };
        let get = |field: &str| {
            object.get(field).ok_or_else(|| {
                err(
                    field,
                    format!("missing: RoNIN's loader needs `{field}` (an annotated sequence's info.json has it)"),
                )
            })
        };
        let number = |field: &str, v: &Value, nan: bool| -> Result<f64> {
            match v {
                Value::Null if nan => Ok(f64::NAN),
                Value::Number(x) => x
                    .as_f64()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| err(field, format!("{x} is not a finite number"))),
                other => Err(err(field, format!("expected a number, found `{other}`"))),
            }
        };
        fn array<const K: usize>(
            field: &str,
            v: &Value,
            number: &dyn Fn(&str, &Value, bool) -> Result<f64>,
            err: &dyn Fn(&str, String) -> DataError,
        ) -> Result<[f64; K]> {
            let items = v.as_array().filter(|a| a.len() == K).ok_or_else(|| {
                err(
                    field,
                    format!("expected a list of {K} numbers, found `{v}`"),
                )
            })?;
            let mut out = [0.0; K];
            for (o, item) in out.iter_mut().zip(items) {
                *o = number(field, item, false)?;
            }
            Ok(out)
        }
        let vec3 = |field: &str| array::<3>(field, get(field)?, &number, &err);
        let start_calibration = array::<4>(
            "start_calibration",
            get("start_calibration")?,
            &number,
            &err,
        )?;
        let ori_errors = ["gyro_integration_error", "grv_ori_error", "ekf_ori_error"]
            .map(|f| get(f).and_then(|v| number(f, v, true)));
        let [e0, e1, e2] = ori_errors;
        let start_frame = match object.get("start_frame") {
            None => 0,
            Some(v) => v
                .as_u64()
                .and_then(|s| usize::try_from(s).ok())
                .ok_or_else(|| {
                    err(
                        "start_frame",
                        format!("expected a frame index (a whole number from 0), found `{v}`"),
                    )
                })?,
        };
        // A calibration far from any phone's would be blamed on the data it is applied to.
        let calibration = |field: &str, (min, max): (f64, f64), what: &str| -> Result<[f64; 3]> {
            let v = vec3(field)?;
            match v.iter().find(|x| !(min..=max).contains(*x)) {
                Some(x) => Err(err(
                    field,
                    format!(
                        "{} is outside {}..{}: {what}",
                        crate::short(*x),
                        crate::short(min),
                        crate::short(max)
                    ),
                )),
                None => Ok(v),
            }
        };
        Ok(Info {
            gyro_bias: calibration(
                "imu_init_gyro_bias",
                (-MAX_GYRO_BIAS, MAX_GYRO_BIAS),
                "a gyro bias in rad/s (phones: under 0.05)",
            )?,
            acce_bias: calibration(
                "imu_acce_bias",
                (-MAX_ACCE_BIAS, MAX_ACCE_BIAS),
                "an accelerometer bias in m/s^2 (phones: under 0.5)",
            )?,
            acce_scale: calibration(
                "imu_acce_scale",
                ACCE_SCALE_RANGE,
                "an accelerometer scale near 1 (phones: within 0.05 of it)",
            )?,
            start_calibration,
            ori_errors: [e0?, e1?, e2?],
            start_frame,
            device: object
                .get("device")
                .and_then(Value::as_str)
                .filter(|d| *d != "unknown")
                .map(str::to_owned),
        })
    }
}

/// `text` with Python's `NaN`, `Infinity` and `-Infinity` (what `json.dump` writes for
/// non-finite floats) outside strings replaced by `null`, which strict JSON parsers accept.
fn python_json(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut in_string = false;
    let mut escaped = false;
    let mut rest = text;
    while let Some(c) = rest.chars().next() {
        if in_string {
            if escaped {
                escaped = false;
            } else if c == '\\' {
                escaped = true;
            } else if c == '"' {
                in_string = false;
            }
        } else if c == '"' {
            in_string = true;
        } else if let Some(token) = ["-Infinity", "Infinity", "NaN"]
            .into_iter()
            .find(|t| rest.starts_with(t))
        {
            out.push_str("null");
            rest = &rest[token.len()..];
            continue;
        }
        out.push(c);
        rest = &rest[c.len_utf8()..];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn argmin_is_numpys() {
        assert_eq!(argmin(&[3.0, 1.0, 1.0]), 1);
        assert_eq!(argmin(&[0.5, 1.0, 0.2]), 2);
        assert_eq!(argmin(&[0.5, f64::NAN, 0.2]), 1);
    }

    #[test]
    fn python_non_finite_floats_become_null_outside_strings() {
        assert_eq!(
            python_json(r#"{"a": NaN, "b": [-Infinity, Infinity], "c": "NaN \" NaN"}"#),
            r#"{"a": null, "b": [null, null], "c": "NaN \" NaN"}"#
        );
    }

    #[test]
    fn gyro_integration_turns_at_the_gyro_rate() {
        let n = 201;
        let time: Vec<f64> = (0..n).map(|i| i as f64 / 200.0).collect();
        let gyro = vec![[0.0, 0.0, 0.5]; n];
        let q = gyro_integration(&time, &gyro, [1.0, 0.0, 0.0, 0.0]);
        let angle = 2.0 * q[n - 1][3].atan2(q[n - 1][0]);
        assert!((angle - 0.5).abs() < 1e-4, "{angle}");
    }
}
