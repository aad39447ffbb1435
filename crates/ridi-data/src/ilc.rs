//! Reader for the path files of the Indoor Location Competition 2.0 (Microsoft Research and
//! XYZ10, 2020; <https://github.com/location-competition/indoor-location-competition-20>, MIT
//! licence): Android recordings of surveyors walking through buildings with the phone held flat
//! in front of the body, with sparse surveyor-marked waypoints as ground truth.
//!
//! # Layout
//! One text file per walk, `data/<site>/<floor>/path_data_files/<path id>.txt`:
//! ```text
//! #  startTime:1574559495255
//! #  SiteID:5dd3d7732a57a34356595932  SiteName:...  FloorId:...  FloorName:F1
//! #  Brand:OPPO  Model:PBCM10  AndroidName:8.1.0  APILevel:27
//! #  type:1  name:BMI160 Accelerometer  vendor:BOSCH  resolution:0.0023956299  ...
//! 1574559495263  TYPE_WAYPOINT  81.317215  93.31349
//! 1574559495401  TYPE_ACCELEROMETER  -0.85562134  1.8243561  9.826508  2
//! 1574559495401  TYPE_GYROSCOPE  -0.3919525  -0.07966614  0.09211731  3
//! 1574559495401  TYPE_ROTATION_VECTOR  0.062149726  0.0793645  0.57060283  3
//! ...
//! #  endTime:1574559526762
//! ```
//! Records are tab-separated, `unix_ms TYPE values...`; `#` lines are the header (start time,
//! site and floor, phone, one line per sensor) and the `endTime` footer. Read are
//!
//! | type | values | unit |
//! | --- | --- | --- |
//! | `TYPE_ACCELEROMETER` | `x y z [accuracy]` | m/s², with gravity |
//! | `TYPE_GYROSCOPE` | `x y z [accuracy]` | rad/s, calibrated |
//! | `TYPE_MAGNETIC_FIELD` (optional) | `x y z [accuracy]` | µT, calibrated |
//! | `TYPE_ROTATION_VECTOR` | `x y z [accuracy]` | vector part of the quaternion |
//! | `TYPE_WAYPOINT` | `x y` | metres, floor-map frame |
//!
//! as the competition's own reader (`io_f.py`) reads them: the fourth value the recorder adds is
//! the sensor's accuracy status (0..3), not the quaternion's `w`, and is ignored. Every other type
//! (`*_UNCALIBRATED`, `TYPE_WIFI`, `TYPE_BEACON`, ...) is skipped unread. The types interleave
//! and the file as a whole is not in time order (WiFi scans are logged when they complete, the
//! last waypoint may be the last record); each type on its own must be. IMU records come at
//! about 50 Hz; a walk lasts 20-40 s with 4-8 waypoints.
//!
//! # What the sequence holds
//! - Device frame: the Android sensor frame. Orientation: the rotation vector
//!   ([`OrientationSource::RotationVector`]: magnetometer-based, world = east-north-up) with
//!   `w = sqrt(1 - x² - y² - z²)`. Gravity is derived from it as for Tyrex (there is no gravity
//!   sensor): `gravity_in_device(orientation, g)` with `g` = [`IlcOptions::gravity`], and linear
//!   acceleration = accelerometer − gravity. The magnetometer is kept.
//! - Timeline: uniform at [`IlcOptions::rate_hz`] (200 Hz, what the RIDI models expect: the
//!   50 Hz samples are interpolated linearly, the rotation vector by slerp) over the time every
//!   IMU stream and the waypoints cover. Nothing is extrapolated: IMU data before the first or
//!   after the last waypoint (usually under 1.5 s) is dropped, and a dropout of the
//!   accelerometer, gyroscope or rotation vector longer than [`MAX_SENSOR_GAP_S`] stays a gap
//!   in the timeline (which tracking refuses and [`Sequence::split_at_gaps`] cuts), named in
//!   [`IlcPath::warnings`] with the stray records beside one that were left out and the
//!   magnetometer's own dropouts (interpolated across). Times are Unix seconds.
//! - Ground truth: none without waypoints (the competition's test paths have none; the
//!   timeline is then the time every IMU type covers; a single waypoint is refused). Otherwise the waypoints, linearly
//!   interpolated in time, `z = 0`, in the floor-map frame
//!   (metres on the floor plan, x right, y up; its heading has nothing to do with the device's
//!   world frame, so compare trajectories after a 2D alignment). It is a straight line at
//!   constant speed between marks 2-10 s apart: exact at the waypoint times, corners cut and speed
//!   changes smoothed between them. Good for position errors over the walk; not for velocities,
//!   so do not train on it. The ground-truth orientation is the rotation vector itself, the
//!   phone's own estimate and not an independent measurement, so orientation errors against it
//!   mean nothing. Its world (magnetic east-north-up) is not the floor-map frame the positions
//!   are in, as [`GroundTruth`] assumes: velocity targets in the stabilized frame (a velocity
//!   error, training) are turned by the yaw between the two, about 3 degrees on the shared
//!   site1/F1 files and unknown elsewhere.
//! - Placement: [`IlcOptions::placement`], `hand` by default (the competition's phones were held
//!   flat in front of the body); a list file's placement overrides it.
//! - Name: the file name without `.txt` (the path id).
//! - Device: `Brand Model` from the header (`OPPO PBCM10`; none when the header names neither
//!   or names it unusably, as [`DeviceInfo::new`] says), its IMU rate the slower of the
//!   accelerometer's and the gyroscope's records (about 50 Hz).
//!
//! # Errors
//! Every error names the file, and the line and field when one is to blame: a non-numeric or
//! non-finite value, too few values (a truncated line), too many (named as two records run together
//! when the next record's type is among them), a record line that is not `unix_ms<TAB>TYPE_...`,
//! timestamps of one type that go back or leave a gap longer than the validation's `max_gap_s`
//! (repeated timestamps keep their first record; with that limit raised, as `ridi convert
//! --split-at-gaps` reads, a pause stays a gap of the timeline and a magnetometer dropout over
//! [`MAX_MAGNET_FILL_S`] leaves the magnetometer out), a rotation vector longer than 1, a missing
//! accelerometer, gyroscope or rotation vector, a single waypoint, waypoints that do not overlap
//! the IMU data, a last record without a line break after it (a file cut off while being written;
//! complete files end with the `#<TAB>endTime` line), a value beyond its channel's physical bound
//! (accelerometer, gyroscope, magnetic field, waypoint) and a record type in the wrong unit (an IMU
//! type whose timestamps step by less than 0.1 ms, a gyroscope in deg/s, an accelerometer in g):
//! the [`Validation`] limits, applied to each record type before resampling.
//!
//! # Example
//! ```no_run
//! use ridi_data::ilc::{self, IlcOptions};
//!
//! let root = std::path::Path::new("indoor-location-competition-20/data");
//! for file in ilc::list_paths(root)? {
//!     let path = ilc::read(&file, &IlcOptions::default())?;
//!     let seq = &path.sequence;
//!     println!("{} {:.0} s, {} waypoints, {:.1} m", seq.name(), seq.duration(),
//!              path.waypoints.len(), seq.path_length().unwrap_or(0.0));
//! }
//! # Ok::<(), ridi_data::DataError>(())
//! ```

use std::io::Read as _;
use std::path::{Path, PathBuf};

use ridi_frames::{Frame, STANDARD_GRAVITY, Vec3, World, WorldFromDevice, WorldVec};

use crate::android;
use crate::error::{DataError, Location, Result};
use crate::options::ReadOptions;
use crate::resample::{interpolate_rot, interpolate_vec3, intersect, intervals, uniform_timeline};
use crate::text::{self, Nan};
use crate::{
    Channel, DeviceInfo, GroundTruth, OrientationSource, Sequence, SequenceParts, Validation,
};

/// Placement label of every path unless [`IlcOptions::placement`] says otherwise.
pub const DEFAULT_PLACEMENT: &str = "hand";

/// The longest interval between two records of the accelerometer, gyroscope or rotation
/// vector that the timeline is resampled across, seconds: 0.1, five records at the
/// competition's 50 Hz (its shared walks never exceed one, 20 ms). Longer dropouts stay gaps
/// in the timeline.
pub const MAX_SENSOR_GAP_S: f64 = 0.1;

/// Longest magnetometer dropout inside the timeline that is interpolated across, seconds: the
/// readers' default longest gap ([`Validation::max_gap_s`](crate::Validation::max_gap_s)), which
/// every record type is held to unless the limit is raised (`ridi inspect`, `ridi convert
/// --split-at-gaps`: pauses then stay gaps, and a longer magnetometer dropout leaves it out).
pub const MAX_MAGNET_FILL_S: f64 = 1.0;

/// How path files are turned into sequences.
#[derive(Debug, Clone, PartialEq)]
pub struct IlcOptions {
    /// Rate of the output timeline, Hz.
    pub rate_hz: f64,
    /// Gravity magnitude used to build the gravity channel from the orientation, m/s².
    pub gravity: f64,
    /// Placement label of the sequences ([`DEFAULT_PLACEMENT`] by default).
    pub placement: Option<String>,
    /// Limits the sequence is checked against; `max_gap_s` also applies to each IMU type's own
    /// timestamps.
    pub validation: Validation,
}

impl Default for IlcOptions {
    fn default() -> Self {
        Self {
            rate_hz: 200.0,
            gravity: STANDARD_GRAVITY,
            placement: Some(DEFAULT_PLACEMENT.to_owned()),
            validation: Validation::default(),
        }
    }
}

impl From<&ReadOptions> for IlcOptions {
    /// The validation limits and timeline rate of the generic reader options, ILC defaults for
    /// the rest.
    fn from(o: &ReadOptions) -> Self {
        Self {
            rate_hz: o.rate_without_pose_hz,
            validation: o.validation.clone(),
            ..Self::default()
        }
    }
}

/// One `TYPE_WAYPOINT` record: where the surveyor marked the phone to be.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Waypoint {
    /// Unix time, seconds.
    pub time: f64,
    /// `[x, y]` in the floor-map frame, metres.
    pub position: [f64; 2],
    /// 1-based line of the record.
    pub line: usize,
}

/// What [`read`] found in one path file.
#[derive(Debug, Clone, PartialEq)]
pub struct IlcPath {
    /// The walk, on the waypoints' time span (see the module documentation).
    pub sequence: Sequence,
    /// Every waypoint of the file, in time order, also those outside the sequence's span.
    pub waypoints: Vec<Waypoint>,
    /// `Brand Model (Android version)` from the header, when given.
    pub device: Option<String>,
    /// `SiteID` from the header, when given.
    pub site: Option<String>,
    /// `FloorName` from the header, when given.
    pub floor: Option<String>,
    /// What the reader did that the sequence does not show, one line each, naming the file:
    /// dropouts kept as gaps, stray records beside them left out (times in the file's
    /// `unix_ms`), magnetometer dropouts interpolated across.
    pub warnings: Vec<String>,
}

/// A record type that is read: its name, the names of its values (for errors), how many
/// more values it may carry (the accuracy status) and the channel its values are checked as.
struct Kind {
    name: &'static str,
    fields: &'static [&'static str],
    extra: usize,
    channel: Option<Channel>,
}

const ACCE: usize = 0;
const GYRO: usize = 1;
const MAGNET: usize = 2;
const RV: usize = 3;
const WAYPOINT: usize = 4;

const KINDS: [Kind; 5] = [
    Kind {
        name: "TYPE_ACCELEROMETER",
        fields: &[
            "TYPE_ACCELEROMETER x",
            "TYPE_ACCELEROMETER y",
            "TYPE_ACCELEROMETER z",
        ],
        extra: 1,
        channel: Some(Channel::Acce),
    },
    Kind {
        name: "TYPE_GYROSCOPE",
        fields: &["TYPE_GYROSCOPE x", "TYPE_GYROSCOPE y", "TYPE_GYROSCOPE z"],
        extra: 1,
        channel: Some(Channel::Gyro),
    },
    Kind {
        name: "TYPE_MAGNETIC_FIELD",
        fields: &[
            "TYPE_MAGNETIC_FIELD x",
            "TYPE_MAGNETIC_FIELD y",
            "TYPE_MAGNETIC_FIELD z",
        ],
        extra: 1,
        channel: Some(Channel::Magnet),
    },
    Kind {
        name: "TYPE_ROTATION_VECTOR",
        fields: &[
            "TYPE_ROTATION_VECTOR x",
            "TYPE_ROTATION_VECTOR y",
            "TYPE_ROTATION_VECTOR z",
        ],
        extra: 1,
        channel: None,
    },
    Kind {
        name: "TYPE_WAYPOINT",
        fields: &["TYPE_WAYPOINT x", "TYPE_WAYPOINT y"],
        extra: 0,
        channel: Some(Channel::Position),
    },
];

/// The path files' names: `unix_ms`, `TYPE_GYROSCOPE x`, and the record type for the whole
/// channel; the channels built from the orientation by their sequence names (`gravity.x`).
struct IlcFields;

impl text::Fields for IlcFields {
    fn field(&self, channel: Channel, axis: Option<usize>) -> String {
        if channel == Channel::Time {
            return "unix_ms".to_owned();
        }
        match KINDS.iter().find(|k| k.channel == Some(channel)) {
            Some(kind) => axis
                .and_then(|a| kind.fields.get(a))
                .copied()
                .unwrap_or(kind.name)
                .to_owned(),
            None => text::sequence_field(channel, axis),
        }
    }
    fn time_unit(&self) -> &str {
        "milliseconds"
    }
}

/// The records of one type: times in seconds, values (unused ones 0) and their lines.
#[derive(Default)]
struct Stream {
    time: Vec<f64>,
    values: Vec<[f64; 3]>,
    lines: Vec<usize>,
}

impl Stream {
    fn span(&self) -> (f64, f64) {
        (self.time[0], self.time[self.time.len() - 1])
    }

    /// The values as vectors of frame `F`, interpolated at `time`.
    fn resample<F: Frame>(&self, time: &[f64]) -> Vec<Vec3<F>> {
        let v: Vec<Vec3<F>> = self.values.iter().map(|&v| Vec3::from_array(v)).collect();
        interpolate_vec3(&self.time, &v, time)
    }
}

/// The header fields kept.
#[derive(Default)]
struct Header {
    site: Option<String>,
    floor: Option<String>,
    brand: Option<String>,
    model: Option<String>,
    android: Option<String>,
}

impl Header {
    /// Takes the `key:value` cells of a `#` line; the first value of a key wins.
    fn read(&mut self, line: &str) {
        for cell in text::cells(line, b'\t') {
            let Some((key, value)) = cell.split_once(':') else {
                continue;
            };
            let slot = match key.trim() {
                "SiteID" => &mut self.site,
                "FloorName" => &mut self.floor,
                "Brand" => &mut self.brand,
                "Model" => &mut self.model,
                "AndroidName" => &mut self.android,
                _ => continue,
            };
            let value = value.trim();
            if slot.is_none() && !value.is_empty() {
                *slot = Some(value.to_owned());
            }
        }
    }

    /// The phone as a sequence's device: `Brand Model` (no Android version), with the IMU rate
    /// of the records; `None` when the header does not name it or names it unusably.
    fn phone(&self, streams: &[Stream; 5]) -> Option<DeviceInfo> {
        let name = match (&self.brand, &self.model) {
            (Some(b), Some(m)) => format!("{b} {m}"),
            (Some(x), None) | (None, Some(x)) => x.clone(),
            (None, None) => return None,
        };
        let device = DeviceInfo::new(&name).ok()?;
        Some(crate::device::with_imu_rate(
            device,
            &streams[ACCE].time,
            &streams[GYRO].time,
        ))
    }

    fn device(&self) -> Option<String> {
        let name = match (&self.brand, &self.model) {
            (Some(b), Some(m)) => format!("{b} {m}"),
            (Some(x), None) | (None, Some(x)) => x.clone(),
            (None, None) => return None,
        };
        Some(match &self.android {
            Some(a) => format!("{name} (Android {a})"),
            None => name,
        })
    }
}

/// Reads one path file (plain or gzip-compressed). See the module documentation.
pub fn read(path: impl AsRef<Path>, options: &IlcOptions) -> Result<IlcPath> {
    let path = path.as_ref();
    parse(&text::read_file(path)?, path, options)
}

/// The sequence name of a path file: its file name without `.txt` (and `.gz`).
fn name_of(path: &Path) -> String {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let name = name.strip_suffix(".gz").unwrap_or(&name);
    name.strip_suffix(".txt").unwrap_or(name).to_owned()
}

/// Parses the content of a path file; `path` names it in errors and gives the sequence name.
pub fn parse(bytes: &[u8], path: &Path, options: &IlcOptions) -> Result<IlcPath> {
    let rate = options.rate_hz;
    options
        .validation
        .check_output_rate(rate, path, "rate_hz")?;
    let content = text::as_text(bytes, path)?;
    let (streams, header) = parse_records(content, path)?;

    for k in [ACCE, GYRO, RV] {
        if streams[k].time.is_empty() {
            return Err(DataError::format(
                Location::file(path).with_field(KINDS[k].name),
                format!(
                    "no {} records: a path file needs TYPE_ACCELEROMETER, TYPE_GYROSCOPE and \
                     TYPE_ROTATION_VECTOR",
                    KINDS[k].name
                ),
            ));
        }
    }
    let wp = &streams[WAYPOINT];
    // Two waypoints make a ground truth; a path without any (the competition's test paths) has
    // none. One alone is a damaged walk rather than a test path: refused, not read without.
    if wp.time.len() == 1 {
        return Err(DataError::format(
            Location::file(path).with_field(KINDS[WAYPOINT].name),
            "1 TYPE_WAYPOINT record: the ground truth needs at least 2 (a path without any is \
             read without ground truth)",
        ));
    }
    let has_truth = wp.time.len() >= 2;
    let limits = &options.validation;
    for (k, s) in streams.iter().enumerate() {
        // Waypoints are seconds apart: neither their gaps nor their step say anything.
        let (gap, time) = if k == WAYPOINT {
            (f64::INFINITY, &[][..])
        } else {
            (limits.max_gap_s, &s.time[..])
        };
        // The median step first: a time in another unit shows as gaps too, and its error
        // names the unit.
        let values = s.values.iter().copied();
        text::check_stream(
            limits,
            path,
            &s.lines,
            &IlcFields,
            time,
            KINDS[k].channel,
            values,
        )?;
        text::check_time(&s.time, &s.lines, path, "unix_ms", gap)?;
    }

    // A waypoint far off is named on its line here: resampled, it would be a frame's.
    let marks: Vec<WorldVec> = wp
        .values
        .iter()
        .map(|v| WorldVec::new(v[0], v[1], 0.0))
        .collect();
    limits
        .check_speed(&wp.time, &marks)
        .map_err(|e| text::sequence_error(path, Some(&wp.lines), &IlcFields, e))?;

    let rv = &streams[RV];
    let rotations = rv
        .values
        .iter()
        .zip(&rv.lines)
        .map(|(v, &line)| {
            android::rotation_vector(*v, None).map_err(|message| {
                DataError::format(
                    Location::line(path, line).with_field("TYPE_ROTATION_VECTOR x..z"),
                    message,
                )
            })
        })
        .collect::<Result<Vec<WorldFromDevice>>>()?;

    let (start, end) = span(&streams, has_truth, path)?;
    let mut warnings = Vec::new();
    let spans = imu_spans(
        &streams,
        (start, end),
        limits.max_gap_s,
        path,
        &mut warnings,
    )?;
    let (magnet_warning, keep_magnet) = magnet_dropouts(&streams[MAGNET], &spans, path);
    warnings.extend(magnet_warning);
    let time: Vec<f64> = spans
        .iter()
        .flat_map(|&(a, b)| uniform_timeline(a, b, options.rate_hz))
        .collect();
    let orientation = interpolate_rot(&rv.time, &rotations, &time);
    let acce = streams[ACCE].resample(&time);
    let (gravity, linacce) = android::gravity_and_linacce(&orientation, &acce, options.gravity);
    let waypoints: Vec<Waypoint> = (0..wp.time.len())
        .map(|i| Waypoint {
            time: wp.time[i],
            position: [wp.values[i][0], wp.values[i][1]],
            line: wp.lines[i],
        })
        .collect();
    let ground_truth = has_truth.then(|| GroundTruth {
        // The waypoints' third value is 0.
        position: wp.resample::<World>(&time),
        orientation: orientation.clone(),
    });
    let parts = SequenceParts {
        name: name_of(path),
        placement: options.placement.clone(),
        gyro: streams[GYRO].resample(&time),
        acce,
        linacce,
        gravity,
        magnet: (keep_magnet && !streams[MAGNET].time.is_empty())
            .then(|| streams[MAGNET].resample(&time)),
        orientation,
        orientation_source: Some(OrientationSource::RotationVector),
        ground_truth,
        steps: None,
        device: header.phone(&streams),
        time,
    };
    let sequence = Sequence::with_validation(parts, limits)
        .map_err(|e| text::sequence_error(path, None, &IlcFields, e))?;
    Ok(IlcPath {
        sequence,
        waypoints,
        device: header.device(),
        site: header.site,
        floor: header.floor,
        warnings,
    })
}

/// The records of the read types and the header, checked line by line.
fn parse_records(content: &str, path: &Path) -> Result<([Stream; 5], Header)> {
    let mut streams: [Stream; 5] = Default::default();
    let mut header = Header::default();
    // The last non-blank line and its record type, if it is a record (read or not).
    let mut last: Option<(usize, Option<&str>)> = None;
    for (line, l) in text::lines(content) {
        // Some recorders end lines with a tab.
        let l = l.trim_end();
        if l.trim_start().starts_with('#') {
            header.read(l);
            last = Some((line, None));
            continue;
        }
        let mut cells = text::cells(l, b'\t');
        let stamp = cells.next().unwrap_or("");
        let ty = cells.next().map(str::trim).unwrap_or("");
        if !ty.starts_with("TYPE_") {
            // A file re-saved with other separators: say which.
            let separator = other_separator(l).map_or(String::new(), |name| {
                format!(": its cells are separated by {name}, the format's by tabs")
            });
            return Err(DataError::format(
                Location::line(path, line).with_field("type"),
                format!(
                    "expected a record `unix_ms<TAB>TYPE_...<TAB>values`, found `{}`{separator}",
                    text::snippet(l)
                ),
            ));
        }
        let Some(k) = KINDS.iter().position(|k| k.name == ty) else {
            // Unread, but a cut-off file may end in one.
            last = Some((line, Some(ty)));
            continue;
        };
        let kind = &KINDS[k];
        let want = kind.fields.len();
        let t_ms = text::number(stamp, path, line, "unix_ms", Nan::Reject)?;
        let mut v = [0.0; 3];
        let mut n = 0;
        // The next record's type among the values: its line break is missing.
        let mut run_together = false;
        for cell in cells {
            if n < want {
                v[n] = text::number(cell, path, line, kind.fields[n], Nan::Reject)?;
            }
            run_together |= cell.trim_start().starts_with("TYPE_");
            n += 1;
        }
        let expected = || {
            let names: Vec<&str> = kind
                .fields
                .iter()
                .filter_map(|f| f.split(' ').nth(1))
                .collect();
            let extra = if kind.extra > 0 { " [accuracy]" } else { "" };
            format!("`{}{extra}`", names.join(" "))
        };
        if n < want {
            return Err(DataError::format(
                Location::line(path, line).with_field(kind.fields[n]),
                format!(
                    "{n} values for {ty}, expected {}: truncated line?",
                    expected()
                ),
            ));
        }
        if n > want + kind.extra {
            return Err(DataError::format(
                Location::line(path, line).with_field(ty),
                format!(
                    "{n} values for {ty}, expected {}: {}",
                    expected(),
                    if run_together {
                        "two records run together (a missing line break)"
                    } else {
                        "a recorder that writes more values than the competition's files do"
                    }
                ),
            ));
        }
        // Division by the exact 1000 rounds once.
        let t = t_ms / 1000.0;
        let s = &mut streams[k];
        // A repeated IMU timestamp keeps its first record; repeated waypoint times are an
        // error (two positions at one time), found by the time check.
        if k == WAYPOINT || s.time.last() != Some(&t) {
            s.time.push(t);
            s.values.push(v);
            s.lines.push(line);
        }
        last = Some((line, Some(kind.name)));
    }
    let last_record = last.and_then(|(line, ty)| Some(Location::line(path, line).with_field(ty?)));
    text::check_line_break(
        content,
        last_record,
        " (complete path files end with a `#\tendTime` line)",
    )?;
    Ok((streams, header))
}

/// A time in the file's own unit, Unix milliseconds, for a message.
fn ms(t: f64) -> String {
    format!("{:.0}", t * 1000.0)
}

/// The stretches of `span` where the accelerometer, gyroscope and rotation vector all have
/// records without a dropout longer than [`MAX_SENSOR_GAP_S`]: the timeline is not resampled
/// across one (it keeps the hole, which tracking refuses and `split_at_gaps` cuts, as in any
/// other format). Stretches shorter than [`MAX_SENSOR_GAP_S`] (a stray record beside a
/// dropout) are left out; a file shorter than that is kept whole. The magnetometer, which
/// tracking does not use, is interpolated across its own dropouts. A hole longer than
/// `max_gap_s` where dropouts of several types overlap is an error, as a gap that long in one
/// type is.
fn imu_spans(
    streams: &[Stream; 5],
    span: (f64, f64),
    max_gap_s: f64,
    path: &Path,
    warnings: &mut Vec<String>,
) -> Result<Vec<(f64, f64)>> {
    let mut spans = vec![span];
    for k in [ACCE, GYRO, RV] {
        spans = intersect(
            &spans,
            &intervals(&streams[k].time, MAX_SENSOR_GAP_S, |_| {}),
        );
    }
    // Beside a dropout, a stray record is no stretch of its own (a short file alone is).
    let mut strays = Vec::new();
    if spans.iter().any(|(a, b)| b - a >= MAX_SENSOR_GAP_S) {
        (spans, strays) = spans
            .into_iter()
            .partition(|(a, b)| b - a >= MAX_SENSOR_GAP_S);
    }
    if spans.len() != 1 && spans.iter().all(|(a, b)| b - a < MAX_SENSOR_GAP_S) {
        return Err(DataError::format(
            Location::file(path).with_field("unix_ms"),
            format!(
                "no stretch of {MAX_SENSOR_GAP_S} s from {} to {} ms where the accelerometer, \
                 gyroscope and rotation vector all record without a dropout",
                ms(span.0),
                ms(span.1)
            ),
        ));
    }
    if let Some(w) = spans.windows(2).find(|w| w[1].0 - w[0].1 > max_gap_s) {
        return Err(DataError::format(
            Location::file(path).with_field("unix_ms"),
            format!(
                "the accelerometer, gyroscope and rotation vector together have no data for \
                 {:.3} s, from {} to {} ms (dropouts of several types overlapping): longer than \
                 the {} s a recording may pause",
                w[1].0 - w[0].1,
                ms(w[0].1),
                ms(w[1].0),
                crate::short(max_gap_s)
            ),
        ));
    }
    let file = crate::shown(path);
    if let Some(w) = spans
        .windows(2)
        .max_by(|a, b| (a[1].0 - a[0].1).total_cmp(&(b[1].0 - b[0].1)))
    {
        // Read to describe or cut the pauses (`ReadOptions::reading_pauses`): no advice to cut.
        let advice = if max_gap_s.is_finite() {
            format!(
                ", which `ridi track` refuses and `ridi convert --split-at-gaps \
                 {MAX_SENSOR_GAP_S}` cuts (in Python `ridi.read_any(path, split_at_gaps=\
                 {MAX_SENSOR_GAP_S})`)"
            )
        } else {
            String::new()
        };
        warnings.push(format!(
            "{file}: dropouts of the accelerometer, gyroscope or rotation vector over \
             {MAX_SENSOR_GAP_S} s leave {} in the timeline (the longest {:.3} s, from {} to {} \
             ms){advice}",
            crate::counted(spans.len() - 1, "gap"),
            w[1].0 - w[0].1,
            ms(w[0].1),
            ms(w[1].0)
        ));
    }
    if let Some(first) = strays.first() {
        warnings.push(format!(
            "{file}: {} of records shorter than {MAX_SENSOR_GAP_S} s beside a dropout left \
             out (the first from {} to {} ms)",
            crate::counted(strays.len(), "stretch"),
            ms(first.0),
            ms(first.1)
        ));
    }
    Ok(spans)
}

/// The warning about the magnetometer's dropouts over [`MAX_SENSOR_GAP_S`] inside the kept
/// `spans`, which the sequence interpolates across, and whether it keeps the magnetometer: not
/// when a dropout there is longer than [`MAX_MAGNET_FILL_S`] (which only a `max_gap_s` above
/// that lets through, as `ridi convert --split-at-gaps` reads), whose filling would be made up.
fn magnet_dropouts(magnet: &Stream, spans: &[(f64, f64)], path: &Path) -> (Option<String>, bool) {
    let (mut holes, mut longest) = (0, 0.0f64);
    for hole in intervals(&magnet.time, MAX_SENSOR_GAP_S, |_| {})
        .windows(2)
        .map(|w| (w[0].1, w[1].0))
    {
        let filled = spans
            .iter()
            .map(|&(a, b)| hole.1.min(b) - hole.0.max(a))
            .fold(0.0, f64::max);
        if filled > MAX_SENSOR_GAP_S {
            holes += 1;
            longest = longest.max(filled);
        }
    }
    let file = crate::shown(path);
    if longest > MAX_MAGNET_FILL_S {
        let warning = format!(
            "{file}: the magnetometer drops out for {longest:.3} s while the other sensors \
             record, longer than the {MAX_MAGNET_FILL_S} s it is interpolated across: left out \
             (only the RIDI-MAG baseline uses it)"
        );
        return (Some(warning), false);
    }
    let warning = (holes > 0).then(|| {
        format!(
            "{file}: the magnetometer drops out {} for over {MAX_SENSOR_GAP_S} s (the longest \
             {longest:.3} s): interpolated across (only the RIDI-MAG baseline uses it)",
            crate::error::times(holes)
        )
    });
    (warning, true)
}

/// The time every IMU stream and (`with_waypoints`) the waypoints cover.
fn span(streams: &[Stream; 5], with_waypoints: bool, path: &Path) -> Result<(f64, f64)> {
    let imu: Vec<&Stream> = [ACCE, GYRO, RV, MAGNET]
        .iter()
        .map(|&k| &streams[k])
        .filter(|s| !s.time.is_empty())
        .collect();
    let imu_start = imu.iter().map(|s| s.span().0).fold(f64::MIN, f64::max);
    let imu_end = imu.iter().map(|s| s.span().1).fold(f64::MAX, f64::min);
    if imu_start >= imu_end {
        return Err(DataError::format(
            Location::file(path),
            "the IMU record types (accelerometer, gyroscope, rotation vector, magnetic field) \
             do not overlap in time",
        ));
    }
    if !with_waypoints {
        return Ok((imu_start, imu_end));
    }
    let (wp_start, wp_end) = streams[WAYPOINT].span();
    let (start, end) = (imu_start.max(wp_start), imu_end.min(wp_end));
    if start >= end {
        return Err(DataError::format(
            Location::file(path).with_field("TYPE_WAYPOINT"),
            format!(
                "the waypoints ({}..{} ms) and the time every IMU type covers ({}..{} ms) do \
                 not overlap: no frame has ground truth",
                ms(wp_start),
                ms(wp_end),
                ms(imu_start),
                ms(imu_end)
            ),
        ));
    }
    Ok((start, end))
}

/// How many bytes [`is_path_file`] looks at.
const SNIFF_BYTES: u64 = 8192;

/// Whether `head`, the first bytes of a file, look like a path file: a `#\tstartTime:` line or
/// a `unix_ms<TAB>TYPE_...` record among its first lines, also with commas, semicolons or
/// spaces for the tabs.
pub fn looks_like_path_file(head: &[u8]) -> bool {
    let head = String::from_utf8_lossy(head);
    // Also with another separator than the tab (a file re-saved by a spreadsheet), so that
    // its reader, not the data_plain.txt one, names the separator.
    head.lines().take(64).any(|l| {
        if l.strip_prefix('#')
            .and_then(after_separator)
            .is_some_and(|rest| rest.starts_with("startTime:"))
        {
            return true;
        }
        let digits = l.bytes().take_while(u8::is_ascii_digit).count();
        digits > 0 && after_separator(&l[digits..]).is_some_and(|rest| rest.starts_with("TYPE_"))
    })
}

/// `rest` after the separators it starts with (tabs, or what a file re-saved by a spreadsheet
/// has instead: commas, semicolons, spaces); `None` if it starts with none.
fn after_separator(rest: &str) -> Option<&str> {
    let cells = rest.trim_start_matches(['\t', ',', ';', ' ']);
    (cells.len() < rest.len()).then_some(cells)
}

/// The separator of a record `l` re-saved without tabs (`unix_ms`, then commas, semicolons or
/// spaces before `TYPE_`), named for a message.
fn other_separator(l: &str) -> Option<&'static str> {
    let digits = l.bytes().take_while(u8::is_ascii_digit).count();
    let rest = &l[digits..];
    after_separator(rest).filter(|cells| digits > 0 && cells.starts_with("TYPE_"))?;
    match rest.chars().next()? {
        ',' => Some("commas"),
        ';' => Some("semicolons"),
        ' ' => Some("spaces"),
        _ => None,
    }
}

/// Whether the file at `path` is a path file (plain or gzip-compressed), judged by its first
/// bytes (see [`looks_like_path_file`]); `false` when it cannot be read.
pub fn is_path_file(path: &Path) -> bool {
    let mut head = Vec::new();
    let Ok(file) = std::fs::File::open(path) else {
        return false;
    };
    if file.take(SNIFF_BYTES).read_to_end(&mut head).is_err() {
        return false;
    }
    if head.starts_with(&[0x1f, 0x8b]) {
        let Ok(file) = std::fs::File::open(path) else {
            return false;
        };
        head.clear();
        // A short or broken stream still leaves what it decoded in `head`.
        let _ = flate2::read::MultiGzDecoder::new(file)
            .take(SNIFF_BYTES)
            .read_to_end(&mut head);
    }
    looks_like_path_file(&head)
}

/// Folder levels [`list_paths`] descends (the dataset root is `data/<site>/<floor>/
/// path_data_files/` deep).
const MAX_DEPTH: usize = 6;

fn walk(dir: &Path, depth: usize, out: &mut Vec<PathBuf>) -> Result<()> {
    let mut entries = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| DataError::io(dir, e))? {
        entries.push(entry.map_err(|e| DataError::io(dir, e))?.path());
    }
    entries.sort();
    for p in entries {
        if p.is_dir() {
            if depth < MAX_DEPTH {
                walk(&p, depth + 1, out)?;
            }
        } else {
            let name = p.file_name().map(|n| n.to_string_lossy().to_lowercase());
            let txt = name.is_some_and(|n| n.ends_with(".txt") || n.ends_with(".txt.gz"));
            if txt && is_path_file(&p) {
                out.push(p);
            }
        }
    }
    Ok(())
}

/// The path files at `root`: the file itself, or every `.txt` (`.txt.gz`) path file in the
/// folder and its sub-folders (a few levels deep, enough for the dataset root), sorted.
pub fn list_paths(root: impl AsRef<Path>) -> Result<Vec<PathBuf>> {
    let root = root.as_ref();
    let mut out = Vec::new();
    if root.is_dir() {
        walk(root, 0, &mut out)?;
    } else if is_path_file(root) {
        out.push(root.to_path_buf());
    }
    if out.is_empty() {
        return Err(DataError::format(
            Location::file(root),
            "no Indoor Location Competition path file (a `.txt` of `unix_ms<TAB>TYPE_...` \
             records) here or in its sub-folders",
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A walk of `seconds` at 50 Hz: the phone lies flat (screen up) and turns about z at
    /// 0.1 rad/s; a waypoint every second along x at 1 m/s, the last one written at the end of
    /// the file as the recorder does.
    fn synthetic(seconds: usize) -> String {
        let t0 = 1_574_559_495_000_i64;
        let mut s = String::from(
            "#\tstartTime:1574559495000\n#\tSiteID:site\tFloorName:F1\n\
             #\tBrand:OPPO\tModel:PBCM10\tAndroidName:8.1.0\tAPILevel:27\t\n",
        );
        let n = seconds * 50;
        let mut waypoints = Vec::new();
        for i in 0..=n {
            let ms = t0 + 20 * i as i64;
            let t = i as f64 / 50.0;
            if i % 50 == 0 {
                waypoints.push(format!("{ms}\tTYPE_WAYPOINT\t{t}\t5\n"));
            }
            let half = 0.05 * t;
            s += &format!("{ms}\tTYPE_ACCELEROMETER\t0.1\t0.2\t9.81\t3\n");
            s += &format!("{ms}\tTYPE_GYROSCOPE\t0\t0\t0.1\t3\n");
            s += &format!("{ms}\tTYPE_MAGNETIC_FIELD\t20\t0\t-40\t3\n");
            s += &format!("{ms}\tTYPE_ROTATION_VECTOR\t0\t0\t{}\t3\n", half.sin());
            s += &format!("{ms}\tTYPE_GYROSCOPE_UNCALIBRATED\t0\t0\t0.1\t0\t0\t0\t3\t\n");
            if i % 25 == 0 {
                s += &format!("{}\tTYPE_WIFI\tssid\tbssid\t-60\t5180\t{ms}\n", ms - 700);
            }
            if i % 50 == 0 && i < n {
                s += &waypoints[i / 50];
            }
        }
        s += &waypoints[n / 50];
        s += &format!("#\tendTime:{}\n", t0 + 20 * n as i64);
        s
    }

    /// `s` with each line replaced by `f(line)`, or dropped when that is `None`.
    fn map_lines(s: &str, f: impl Fn(&str) -> Option<String>) -> String {
        s.lines().filter_map(f).map(|l| l + "\n").collect()
    }

    fn parse_str(s: &str) -> Result<IlcPath> {
        parse(s.as_bytes(), Path::new("p/abc.txt"), &IlcOptions::default())
    }

    fn err(s: &str) -> String {
        parse_str(s).unwrap_err().to_string()
    }

    #[test]
    fn a_synthetic_walk_is_read() {
        let p = parse_str(&synthetic(6)).unwrap();
        let seq = &p.sequence;
        assert_eq!(seq.name(), "abc");
        assert_eq!(seq.placement(), Some("hand"));
        assert_eq!(
            seq.orientation_source(),
            Some(OrientationSource::RotationVector)
        );
        assert_eq!(p.device.as_deref(), Some("OPPO PBCM10 (Android 8.1.0)"));
        assert_eq!(
            (p.site.as_deref(), p.floor.as_deref()),
            (Some("site"), Some("F1"))
        );
        assert_eq!(p.waypoints.len(), 7);
        assert!(p.waypoints.windows(2).all(|w| w[0].time < w[1].time));
        // 6 s at 200 Hz, both ends included.
        assert_eq!(seq.len(), 1201);
        assert!((seq.rate_hz() - 200.0).abs() < 1e-6);
        assert!((seq.time()[0] - 1_574_559_495.0).abs() < 1e-6);
        let gt = seq.ground_truth().unwrap();
        // Waypoints every second: x = t, y = 5.
        for (i, &t) in seq.time().iter().enumerate().step_by(37) {
            let x = t - 1_574_559_495.0;
            let p = gt.position[i];
            assert!((p.x() - x).abs() < 1e-6 && (p.y() - 5.0).abs() < 1e-12 && p.z() == 0.0);
        }
        assert!((seq.path_length().unwrap() - 6.0).abs() < 1e-6);
        assert_eq!(gt.orientation, seq.orientation());
        // Flat, screen up: gravity along +z, yaw 0.1 rad/s.
        let g = seq.gravity()[600];
        assert!((g.z() - STANDARD_GRAVITY).abs() < 1e-9 && g.x().abs() < 1e-9);
        let yaw = seq.orientation()[1200].angle_to(&seq.orientation()[0]);
        assert!((yaw - 0.6).abs() < 1e-6, "{yaw}");
        let l = seq.linacce()[10];
        assert!((l.x() - 0.1).abs() < 1e-9 && (l.z() - (9.81 - STANDARD_GRAVITY)).abs() < 1e-9);
        assert!(seq.magnet().is_some_and(|m| (m[5].x() - 20.0).abs() < 1e-9));
        assert!((seq.gyro()[3].z() - 0.1).abs() < 1e-12);
    }

    #[test]
    fn frames_outside_the_waypoints_are_cut_and_placement_is_an_option() {
        // Waypoints from 1 s to 5 s only.
        let s = map_lines(&synthetic(6), |l| {
            (!l.contains("TYPE_WAYPOINT")).then(|| l.to_owned())
        })
        .replace(
            "#\tendTime",
            "1574559496000\tTYPE_WAYPOINT\t0\t0\n1574559500000\tTYPE_WAYPOINT\t4\t0\n#\tendTime",
        );
        let opts = IlcOptions {
            placement: None,
            ..IlcOptions::default()
        };
        let p = parse(s.as_bytes(), Path::new("x.txt.gz"), &opts).unwrap();
        let seq = p.sequence;
        assert_eq!(seq.name(), "x");
        assert_eq!(seq.placement(), None);
        assert_eq!(seq.len(), 801);
        assert!((seq.time()[0] - 1_574_559_496.0).abs() < 1e-6);
        assert!((seq.path_length().unwrap() - 4.0).abs() < 1e-9);
    }

    #[test]
    fn bad_input_names_file_line_and_field() {
        let good = synthetic(3);
        let cases: &[(&str, &str, &str)] = &[
            (
                "1574559495020\tTYPE_ACCELEROMETER\t0.1\t0.2\t9.81\t3",
                "1574559495020\tTYPE_ACCELEROMETER\t0.1\tabc\t9.81\t3",
                "p/abc.txt:11: field `TYPE_ACCELEROMETER y`: `abc` is not a number",
            ),
            (
                "1574559495020\tTYPE_ACCELEROMETER\t0.1\t0.2\t9.81\t3",
                "1574559495020\tTYPE_ACCELEROMETER\t0.1\t0.2\tinf\t3",
                "p/abc.txt:11: field `TYPE_ACCELEROMETER z`: `inf` is not a finite number",
            ),
            (
                "1574559495020\tTYPE_GYROSCOPE\t0\t0\t0.1\t3",
                "1574559495020\tTYPE_GYROSCOPE\t0\t0",
                "p/abc.txt:12: field `TYPE_GYROSCOPE z`: 2 values for TYPE_GYROSCOPE, expected \
                 `x y z [accuracy]`: truncated line?",
            ),
            (
                "1574559495020\tTYPE_GYROSCOPE\t0\t0\t0.1\t3",
                "1574559495020\tTYPE_GYROSCOPE\t0\t0\t0.1\t31574559495020\tTYPE_MAGNETIC_FIELD",
                "p/abc.txt:12: field `TYPE_GYROSCOPE`: 5 values for TYPE_GYROSCOPE, expected \
                 `x y z [accuracy]`: two records run together",
            ),
            (
                "1574559495020\tTYPE_ACCELEROMETER\t0.1\t0.2\t9.81\t3",
                "1574559495020x\tTYPE_ACCELEROMETER\t0.1\t0.2\t9.81\t3",
                "p/abc.txt:11: field `unix_ms`: `1574559495020x` is not a number",
            ),
            (
                "1574559495040\tTYPE_ROTATION_VECTOR",
                "1574559495000\tTYPE_ROTATION_VECTOR",
                // Unix milliseconds as f64 seconds: 0.24 µs resolution.
                "p/abc.txt:19: field `unix_ms`: timestamp goes back by 0.0199999",
            ),
            (
                "1574559495020\tTYPE_ROTATION_VECTOR\t0\t0\t0.0009999998333333417",
                "1574559495020\tTYPE_ROTATION_VECTOR\t0.9\t0.9\t0.0009999998333333417",
                "p/abc.txt:14: field `TYPE_ROTATION_VECTOR x..z`: quaternion x,y,z,w has norm \
                 1.2728, not 1",
            ),
            (
                "1574559494300\tTYPE_WIFI",
                "1574559494300 TYPE_WIFI",
                "p/abc.txt:9: field `type`: expected a record `unix_ms<TAB>TYPE_...<TAB>values`, \
                 found `1574559494300 TYPE_WIFI\\tssid\\tbssid\\t-60\\t5...`: its cells are \
                 separated by spaces, the format's by tabs",
            ),
            (
                "1574559496000\tTYPE_WAYPOINT\t1\t5",
                "1574559494000\tTYPE_WAYPOINT\t1\t5",
                "p/abc.txt:263: field `unix_ms`: timestamp goes back by 1.000000000 s from line 10",
            ),
            (
                "1574559496000\tTYPE_WAYPOINT\t1\t5",
                "1574559496000\tTYPE_WAYPOINT\t1\t5\t0",
                "p/abc.txt:263: field `TYPE_WAYPOINT`: 3 values for TYPE_WAYPOINT, expected \
                 `x y`: a recorder that writes more values than the competition's files do",
            ),
            (
                // Android's rotation vector has a fifth value, w, before the accuracy.
                "1574559495020\tTYPE_ROTATION_VECTOR\t0\t0\t0.0009999998333333417\t3",
                "1574559495020\tTYPE_ROTATION_VECTOR\t0\t0\t0.0009999998333333417\t1\t3",
                "p/abc.txt:14: field `TYPE_ROTATION_VECTOR`: 5 values for TYPE_ROTATION_VECTOR, \
                 expected `x y z [accuracy]`: a recorder that writes more values",
            ),
        ];
        for (from, to, want) in cases {
            assert!(good.contains(from), "{from}");
            let e = err(&good.replacen(from, to, 1));
            assert!(e.starts_with(want), "{e}\nwant {want}");
        }
    }

    #[test]
    fn waypoint_problems_are_reported() {
        let good = synthetic(3);
        // One waypoint is a damaged walk; none (a competition test path) no ground truth, the
        // timeline over the IMU's span (here a second longer than the waypoints').
        let only_first = map_lines(&good, |l| {
            (!l.contains("TYPE_WAYPOINT") || l.starts_with("1574559495000")).then(|| l.to_owned())
        });
        assert_eq!(
            err(&only_first),
            "p/abc.txt: field `TYPE_WAYPOINT`: 1 TYPE_WAYPOINT record: the ground truth needs at \
             least 2 (a path without any is read without ground truth)"
        );
        let late = map_lines(&good, |l| {
            (!l.starts_with("1574559495000\tTYPE_WAYPOINT")).then(|| l.to_owned())
        });
        let with_truth = parse_str(&late).unwrap().sequence;
        let none = map_lines(&good, |l| {
            (!l.contains("TYPE_WAYPOINT")).then(|| l.to_owned())
        });
        let read = parse_str(&none).unwrap();
        assert!(read.sequence.ground_truth().is_none() && read.waypoints.is_empty());
        assert!(read.sequence.time()[0] < with_truth.time()[0] - 0.9);
        let same = good.replace(
            "1574559496000\tTYPE_WAYPOINT\t1\t5",
            "1574559495000\tTYPE_WAYPOINT\t1\t5",
        );
        assert!(
            err(&same).starts_with(
                "p/abc.txt:263: field `unix_ms`: duplicate timestamp (same as line 10)"
            ),
            "{}",
            err(&same)
        );
        // Every waypoint 100 s after the IMU data.
        let late = map_lines(&good, |l| {
            Some(match l.split_once("\tTYPE_WAYPOINT") {
                Some((ms, rest)) => {
                    format!(
                        "{}\tTYPE_WAYPOINT{rest}",
                        ms.parse::<i64>().unwrap() + 100_000
                    )
                }
                None => l.to_owned(),
            })
        });
        let e = err(&late);
        assert_eq!(
            e,
            "p/abc.txt: field `TYPE_WAYPOINT`: the waypoints (1574559595000..1574559598000 ms) \
             and the time every IMU type covers (1574559495000..1574559498000 ms) do not \
             overlap: no frame has ground truth"
        );
    }

    #[test]
    fn missing_streams_gaps_and_truncation_are_reported() {
        let good = synthetic(3);
        for ty in [
            "TYPE_ACCELEROMETER",
            "TYPE_GYROSCOPE",
            "TYPE_ROTATION_VECTOR",
        ] {
            let without = map_lines(&good, |l| {
                (l.split('\t').nth(1) != Some(ty)).then(|| l.to_owned())
            });
            let e = err(&without);
            assert!(
                e.starts_with(&format!("p/abc.txt: field `{ty}`: no {ty} records")),
                "{e}"
            );
        }
        // No magnetometer is fine.
        let no_mag = map_lines(&good, |l| {
            (!l.contains("TYPE_MAGNETIC_FIELD\t")).then(|| l.to_owned())
        });
        assert!(parse_str(&no_mag).unwrap().sequence.magnet().is_none());
        // `good` without the `ty` records from `from` to `to` (unix ms).
        let drop = |ty: &str, from: i64, to: i64| {
            let ty = format!("{ty}\t");
            map_lines(&good, |l| {
                let t: i64 = l.split('\t').next().unwrap().parse().unwrap_or(0);
                (!((from..to).contains(&t) && l.contains(&ty))).then(|| l.to_owned())
            })
        };
        // A 1.5 s hole in the accelerometer.
        let holed = drop("TYPE_ACCELEROMETER", 1_574_559_496_000, 1_574_559_497_500);
        let e = err(&holed);
        assert!(e.contains("field `unix_ms`: gap of 1.520 s"), "{e}");
        // A 0.5 s dropout of the gyroscope stays a gap in the timeline, not interpolated
        // across: tracking refuses it and `split_at_gaps` cuts there.
        let dropout = drop("TYPE_GYROSCOPE", 1_574_559_496_000, 1_574_559_496_500);
        let widest = |s: &Sequence| s.time().windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
        // The magnetometer is interpolated across its own dropout.
        let mag = parse_str(&drop(
            "TYPE_MAGNETIC_FIELD",
            1_574_559_496_000,
            1_574_559_496_500,
        ));
        let mag = mag.unwrap();
        assert!(widest(&mag.sequence) < 0.0051);
        assert_eq!(
            mag.warnings,
            [
                "p/abc.txt: the magnetometer drops out once for over 0.1 s (the longest 0.520 s): \
              interpolated across (only the RIDI-MAG baseline uses it)"
            ]
        );
        // A 1.5-s magnetometer dropout is refused as a gap; with pauses read (`ridi convert
        // --split-at-gaps`), the magnetometer is left out rather than filled across it.
        let long = drop("TYPE_MAGNETIC_FIELD", 1_574_559_496_000, 1_574_559_497_500);
        assert!(err(&long).contains("field `unix_ms`: gap of 1.520 s"));
        let mut pausing = IlcOptions::default();
        pausing.validation.max_gap_s = f64::INFINITY;
        let read = parse(long.as_bytes(), Path::new("p/abc.txt"), &pausing).unwrap();
        assert!(read.sequence.magnet().is_none());
        assert_eq!(
            read.warnings,
            [
                "p/abc.txt: the magnetometer drops out for 1.520 s while the other sensors \
                 record, longer than the 1 s it is interpolated across: left out (only the \
                 RIDI-MAG baseline uses it)"
            ]
        );
        // Overlapping dropouts leaving no data for over 1 s: named as such.
        let both = map_lines(
            &drop("TYPE_GYROSCOPE", 1_574_559_496_000, 1_574_559_496_600),
            |l| {
                let t: i64 = l.split('\t').next().unwrap().parse().unwrap_or(0);
                let hole = (1_574_559_496_580..1_574_559_497_200).contains(&t);
                (!(hole && l.contains("TYPE_ACCELEROMETER\t"))).then(|| l.to_owned())
            },
        );
        let e = err(&both);
        assert!(
            e.contains(
                "field `unix_ms`: the accelerometer, gyroscope and rotation vector \
                        together have no data for 1.2"
            ),
            "{e}"
        );
        // A stray record before a dropout at the start is left out, not a frame of its own.
        let stray = drop("TYPE_GYROSCOPE", 1_574_559_495_010, 1_574_559_495_400);
        let read = parse_str(&stray).unwrap();
        assert!(
            widest(&read.sequence) < 0.0051,
            "{}",
            widest(&read.sequence)
        );
        assert_eq!(
            read.warnings,
            [
                "p/abc.txt: 1 stretch of records shorter than 0.1 s beside a dropout left out \
              (the first from 1574559495000 to 1574559495000 ms)"
            ]
        );
        let read = parse_str(&dropout).unwrap();
        let seq = &read.sequence;
        assert!((widest(seq) - 0.52).abs() < 0.006, "{}", widest(seq));
        assert_eq!(seq.clone().split_at_gaps(0.1, 0.0).unwrap().parts.len(), 2);
        assert_eq!(read.warnings.len(), 1, "{:?}", read.warnings);
        assert!(
            read.warnings[0].starts_with(
                "p/abc.txt: dropouts of the accelerometer, gyroscope or rotation vector over 0.1 \
                 s leave 1 gap in the timeline (the longest 0.5"
            ) && read.warnings[0].ends_with(
                "which `ridi track` refuses and `ridi convert --split-at-gaps 0.1` cuts (in \
                 Python `ridi.read_any(path, split_at_gaps=0.1)`)"
            ),
            "{}",
            read.warnings[0]
        );
        // Read to describe or cut its pauses (`ridi inspect`, `ridi convert --split-at-gaps`):
        // the gap is said, with no advice to cut it.
        let mut pauses = IlcOptions::default();
        pauses.validation.max_gap_s = f64::INFINITY;
        let read = parse(dropout.as_bytes(), Path::new("p/abc.txt"), &pauses).unwrap();
        assert!(
            read.warnings.len() == 1
                && read.warnings[0].contains("leave 1 gap")
                && read.warnings[0].ends_with(" ms)"),
            "{:?}",
            read.warnings
        );
        // Every sensor stopping at once (a stalled logger) leaves a gap; the magnetometer is
        // not interpolated there, so no warning of its own.
        let stall = map_lines(&good, |l| {
            let t: i64 = l.split('\t').next().unwrap().parse().unwrap_or(0);
            let hole = (1_574_559_496_000..1_574_559_496_500).contains(&t);
            (!hole || l.contains("TYPE_WAYPOINT")).then(|| l.to_owned())
        });
        let read = parse_str(&stall).unwrap();
        assert_eq!(read.warnings.len(), 1, "{:?}", read.warnings);
        assert!(
            read.warnings[0].contains("leave 1 gap"),
            "{:?}",
            read.warnings
        );
        let whole = parse_str(&good).unwrap();
        assert!(
            widest(&whole.sequence) < 0.0051,
            "{}",
            widest(&whole.sequence)
        );
        assert!(whole.warnings.is_empty(), "{:?}", whole.warnings);
        // Cut off inside an accelerometer record.
        let cut_at = good.find("1574559496500\tTYPE_ACCELEROMETER").unwrap() + 44;
        assert!(good[..cut_at].ends_with("\t0.1\t0.2\t9.8"));
        let e = err(&good[..cut_at]);
        assert!(
            e.contains("field `TYPE_ACCELEROMETER`: the file ends inside this record"),
            "{e}"
        );
        // Cut off after a complete line: nothing tells, the data are usable. Inside a record of
        // a type that is not read: still a cut-off file.
        let after_line = good.find("1574559496500\tTYPE_ACCELEROMETER").unwrap();
        assert!(parse_str(&good[..after_line]).is_ok());
        let in_wifi = good.rfind("\tTYPE_WIFI\tssid").unwrap() + 12;
        let e = err(&good[..in_wifi]);
        assert!(
            e.contains("field `TYPE_WIFI`: the file ends inside this record"),
            "{e}"
        );
        // Repeated IMU timestamps keep the first record.
        let dup = good.replacen(
            "1574559495020\tTYPE_GYROSCOPE\t0\t0\t0.1\t3\n",
            "1574559495020\tTYPE_GYROSCOPE\t0\t0\t0.1\t3\n1574559495020\tTYPE_GYROSCOPE\t9\t9\t9\t3\n",
            1,
        );
        let seq = parse_str(&dup).unwrap().sequence;
        assert!(seq.gyro().iter().all(|g| g.x() == 0.0));
        // Nothing at all.
        assert!(err("").contains("no TYPE_ACCELEROMETER records"));
        for rate_hz in [0.0, 1e12] {
            let e = parse(
                b"x",
                Path::new("a.txt"),
                &IlcOptions {
                    rate_hz,
                    ..Default::default()
                },
            )
            .unwrap_err();
            let want = format!("a.txt: field `rate_hz`: output rate {rate_hz} Hz: expected from");
            assert!(e.to_string().starts_with(&want), "{e}");
        }
    }

    /// A waypoint far off is named on its line, not on a frame of the resampled timeline.
    #[test]
    fn a_waypoint_far_off_is_named_on_its_line() {
        let good = synthetic(10);
        let far = good.replacen("TYPE_WAYPOINT\t2\t5", "TYPE_WAYPOINT\t100000\t5", 1);
        assert_ne!(far, good);
        let line = far.lines().position(|l| l.contains("\t100000\t")).unwrap() + 1;
        let e = err(&far);
        assert!(
            e.starts_with(&format!(
                "p/abc.txt:{line}: field `TYPE_WAYPOINT x`: jumps 99999 m in 1 s (99999 m/s)"
            )),
            "{e}"
        );
    }

    #[test]
    fn path_files_are_recognized_by_their_first_lines() {
        assert!(looks_like_path_file(synthetic(1).as_bytes()));
        assert!(looks_like_path_file(
            b"1574559495263\tTYPE_WAYPOINT\t1\t2\n"
        ));
        assert!(!looks_like_path_file(b"3 27\n1\t2\t3\n"));
        assert!(!looks_like_path_file(b"# t x y z\n12 0.1 0.2 0.3\n"));
        assert!(!looks_like_path_file(b""));
        // Re-saved with other separators: its reader names them.
        assert!(looks_like_path_file(b"#,startTime:1574559529168\n"));
        assert!(looks_like_path_file(b"1574559495263 TYPE_WAYPOINT 1 2\n"));
        assert!(looks_like_path_file(b"1574559495263;TYPE_WAYPOINT;1;2\n"));
        assert!(!looks_like_path_file(b"1574559495263TYPE_WAYPOINT\n"));
        for (separator, name) in [(",", "commas"), (", ", "commas"), (";", "semicolons")] {
            let e = err(&synthetic(1).replace('\t', separator));
            assert!(
                e.ends_with(&format!(
                    "its cells are separated by {name}, the format's by tabs"
                )),
                "{e}"
            );
        }
    }
}
