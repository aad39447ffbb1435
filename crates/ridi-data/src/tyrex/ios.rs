//! The iOS layout of a Tyrex run (`datasets/ios/<run>/`), turned into the Android conventions
//! the rest of the reader works in. Each conversion follows the authors' loader,
//! `src/Import/loadiOSDataset.m` (lines cited below), and the helpers it calls; the module
//! documentation of [`tyrex`](super) says what each means and how it was checked.
//!
//! | file | columns | conversion | loader line |
//! | --- | --- | --- | --- |
//! | `accelerometer.txt` | `t ax ay az`, g, Core Motion's sign (gravity reads -1 g up) | `× -9.80665` | 24-25 |
//! | `gyroscope.txt` | `t wx wy wz`, rad/s | none | 20, 42 |
//! | `attitude.txt` | `t qw qx qy qz`, Core Motion attitude | `q_z(+90°) ⊗ q` | 34-39 |
//! | `description.txt` | `[Time] BootTime = s` | every `t` minus `BootTime` | 47-48 |

use std::path::Path;

use ridi_frames::nalgebra::Vector3;
use ridi_frames::{DeviceVec, QuatError, Rot, STANDARD_GRAVITY, World, WorldFromDevice};

use super::{CutOff, PhoneStreams, Stream, device_of, ini_value, read_stream};
use crate::OrientationSource;
use crate::error::{DataError, Location, Result, shown};
use crate::text;

/// Files only the iOS layout has (what [`layout_of`](super::layout_of) looks for).
pub(super) const OWN_FILES: [&str; 2] = ["attitude.txt", "description.txt"];

/// The standard gravity the loader scales the accelerometer's g by (`Constants.STANDARD_GRAVITY`
/// of the authors' `src/Utils/Constants.m`, 9.80665).
const G: f64 = STANDARD_GRAVITY;

/// Share of the range below an axis's largest reading (in one direction) that counts as
/// clipped: the iPhone 4S's readings pile up within 1-2 % of a limit near 2 g that differs by
/// axis and direction and drifts during a run (Core Motion's calibration is applied after the
/// sensor clipped), so the Android rule (exactly at the largest magnitude) finds nothing there.
const CLIP_BAND: f64 = 0.03;

/// The heading turn of the Core Motion attitude: `headingOfX = 90 * pi / 180` turned into
/// `dcm2quat(headingRotation')` (lines 34-38), which with the authors' `dcm2quat` (the quaternion
/// of the transpose of its argument) is `+90°` about z; applied as `quatmultiply(heading, q)`
/// (line 39), the Hamilton product `heading ⊗ q`.
fn heading_turn() -> Rot<World, World> {
    Rot::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_2)
}

/// Reads the streams of an iOS run folder (see the module table).
pub(super) fn read(dir: &Path, name: &str, warnings: &mut Vec<String>) -> Result<PhoneStreams> {
    let description = dir.join("description.txt");
    let boot = boot_time(&description)?;
    let mut acce = read_stream(
        &dir.join("accelerometer.txt"),
        &["t", "ax", "ay", "az"],
        &[4],
        CutOff::Drop(warnings),
        |c, _| Ok(DeviceVec::new(-G * c[1], -G * c[2], -G * c[3])),
    )?;
    let mut gyro = read_stream(
        &dir.join("gyroscope.txt"),
        &["t", "wx", "wy", "wz"],
        &[4],
        CutOff::Drop(warnings),
        |c, _| Ok(DeviceVec::new(c[1], c[2], c[3])),
    )?;
    let path = dir.join("attitude.txt");
    let turn = heading_turn();
    let mut attitude = read_stream(
        &path,
        &["t", "qw", "qx", "qy", "qz"],
        &[5],
        CutOff::Drop(warnings),
        |c, line| {
            let q = WorldFromDevice::from_wxyz([c[1], c[2], c[3], c[4]]).map_err(|e| {
                let message = match e {
                    QuatError::NotUnit { norm } => {
                        format!("quaternion w,x,y,z has norm {norm:.4}, not 1")
                    }
                    other => other.to_string(),
                };
                DataError::format(Location::line(&path, line).with_field("qw"), message)
            })?;
            Ok(turn * q)
        },
    )?;
    for stream in [&mut acce.time, &mut gyro.time, &mut attitude.time] {
        shift(stream, boot, &description)?;
    }
    let device = device_of(&description, Some("Device"), name, &acce, &gyro, warnings)?;
    Ok(PhoneStreams {
        clipping: clipping(&acce),
        acce,
        gyro,
        orientation: attitude,
        source: OrientationSource::CoreMotionAttitude,
        device,
    })
}

/// `BootTime` of the `[Time]` section of `description.txt`, seconds: the offset of the time
/// column (`loadProperty(dl, 'Time', 'BootTime')`, line 47).
fn boot_time(path: &Path) -> Result<f64> {
    if !path.is_file() {
        // Names the file: missing, or not a regular file.
        std::fs::File::open(path)
            .and_then(|f| f.metadata())
            .map_err(|e| DataError::io(path, e))?;
        return Err(DataError::format(
            Location::file(path),
            "not a regular file: the iOS layout needs description.txt for `[Time] BootTime`",
        ));
    }
    match ini_value(path, Some("Time"), "BootTime")? {
        Some((line, value)) => text::number(&value, path, line, "BootTime", text::Nan::Reject),
        None => Err(DataError::format(
            Location::file(path).with_field("BootTime"),
            "no `BootTime = <seconds>` in its `[Time]` section: the offset of the time column \
             of every iOS file",
        )),
    }
}

/// Moves the timestamps `time` (strictly increasing, finite) onto the phone clock, `t -
/// boot`; an error naming `BootTime` when that is not finite and increasing any more (a
/// `BootTime` so far from the times that subtracting it merges them).
fn shift(time: &mut [f64], boot: f64, description: &Path) -> Result<()> {
    for t in time.iter_mut() {
        *t -= boot;
    }
    let ok = time.iter().all(|t| t.is_finite()) && time.windows(2).all(|w| w[1] > w[0]);
    if ok {
        return Ok(());
    }
    Err(DataError::format(
        Location::file(description).with_field("BootTime"),
        format!(
            "{boot} s is so far from the time column that subtracting it merges or overflows \
             timestamps"
        ),
    ))
}

/// A warning when many accelerometer readings sit near the largest reading of their axis and
/// direction (within [`CLIP_BAND`] of it, for directions beyond 1.5 g): the range was exceeded
/// (the iPhone 4S clips near 2 g), so the linear acceleration is wrong there.
fn clipping(acce: &Stream<DeviceVec>) -> Option<String> {
    // Largest reading per axis and direction: +x, -x, +y, -y, +z, -z.
    let mut peak = [0.0f64; 6];
    for v in &acce.values {
        for (axis, c) in v.to_array().into_iter().enumerate() {
            peak[2 * axis] = peak[2 * axis].max(c);
            peak[2 * axis + 1] = peak[2 * axis + 1].max(-c);
        }
    }
    let limit = |d: usize| (peak[d] > 1.5 * STANDARD_GRAVITY).then(|| peak[d] * (1.0 - CLIP_BAND));
    let limits: Vec<Option<f64>> = (0..6).map(limit).collect();
    let mut per_direction = [0usize; 6];
    let mut clipped = 0;
    for v in &acce.values {
        let mut any = false;
        for (axis, c) in v.to_array().into_iter().enumerate() {
            for (d, value) in [(2 * axis, c), (2 * axis + 1, -c)] {
                if limits[d].is_some_and(|l| value >= l) {
                    per_direction[d] += 1;
                    any = true;
                }
            }
        }
        clipped += usize::from(any);
    }
    let n = acce.values.len() as f64;
    let share = clipped as f64 / n;
    if share <= 0.005 {
        return None;
    }
    let axes: Vec<String> = (0..6)
        .filter(|&d| per_direction[d] as f64 > 0.001 * n)
        .map(|d| {
            let sign = if d % 2 == 0 { '+' } else { '-' };
            format!("{sign}{} {:.2}", ["x", "y", "z"][d / 2], peak[d])
        })
        .collect();
    Some(format!(
        "{}: {:.1} % of the samples are clipped near the largest reading of their axis ({} \
         m/s^2, within {:.0} %): the accelerometer range was exceeded",
        shown(&acce.path),
        share * 100.0,
        axes.join(", "),
        CLIP_BAND * 100.0
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_heading_turn_takes_core_motion_north_onto_enu_north() {
        // Core Motion's reference x is magnetic north (z up, y west); ENU's north is +y.
        let north = heading_turn() * ridi_frames::WorldVec::new(1.0, 0.0, 0.0);
        assert!((north - ridi_frames::WorldVec::new(0.0, 1.0, 0.0)).norm() < 1e-15);
        let west = heading_turn() * ridi_frames::WorldVec::new(0.0, 1.0, 0.0);
        assert!((west - ridi_frames::WorldVec::new(-1.0, 0.0, 0.0)).norm() < 1e-15);
        let [w, x, y, z] = heading_turn().to_wxyz();
        let h = std::f64::consts::FRAC_1_SQRT_2;
        assert!((w - h).abs() < 1e-15 && x == 0.0 && y == 0.0 && (z - h).abs() < 1e-15);
    }

    #[test]
    fn a_device_without_a_model_comes_from_the_name() {
        let d =
            crate::DeviceInfo::new(&super::super::phone_of("Jakob_iPhone4S_NoDist_AR").unwrap());
        assert_eq!(d.unwrap().model(), "iPhone 4S");
    }
}
