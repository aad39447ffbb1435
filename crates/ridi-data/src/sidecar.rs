//! The sidecar of a processed data file: what RIDI's layout has no column for (the device, where
//! the orientation comes from), in a small text file beside it.
//!
//! `data.csv` (or `data_plain.txt`, `walk.csv.gz`, ...) gets `data.csv.meta`:
//!
//! ```text
//! # ridi-rs: what data.csv has no column for (RIDI's own readers do not open this file)
//! device = iPhone 4S
//! device_imu_rate_hz = 90.09009029909154
//! orientation_source = core-motion-attitude
//! ```
//!
//! `#` comments and blank lines are skipped; every other line is `key = value`. Keys:
//! `device` (the model, [`DeviceInfo::new`]), `device_imu_rate_hz` (only with `device`,
//! [`DeviceInfo::with_imu_rate`]) and `orientation_source` ([`OrientationSource::key`]; without
//! it, the layout's own: RIDI's game rotation vector, or the estimate for a `data.csv` without
//! orientation columns, beside which a sidecar may name no other source). Other keys are
//! skipped, so that files of a later version with more keys still read. A malformed line, a key
//! given twice or a value that is not valid is an error naming the sidecar, the line and the
//! key.
//!
//! The sidecar is optional: a data file without one (RIDI's own, one written by another tool)
//! reads with no device. The writers replace it together with the data file: both written in
//! full first, then the old sidecar removed, the data file and the new sidecar renamed into
//! place, so an interrupted write leaves at worst a data file without a sidecar (device
//! unknown), never a data file beside the sidecar of another.

use std::path::{Path, PathBuf};

use crate::OrientationSource;
use crate::device::DeviceInfo;
use crate::error::{DataError, Location, Result};
use crate::text::{self, Nan};
use crate::write::RoundTrip;
use crate::{PendingFile, Sequence, write_pending};

/// What a sidecar's name adds to its data file's.
pub const SIDECAR_SUFFIX: &str = ".meta";

/// A sidecar larger than this is no sidecar of ours (it holds two short lines).
const MAX_BYTES: u64 = 64 * 1024;

const DEVICE: &str = "device";
const RATE: &str = "device_imu_rate_hz";
const SOURCE: &str = "orientation_source";

/// What a sidecar holds.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Sidecar {
    pub(crate) device: Option<DeviceInfo>,
    pub(crate) orientation_source: Option<OrientationSource>,
    /// The line naming the orientation source, for [`Self::check_estimated`].
    source_line: Option<usize>,
}

impl Sidecar {
    /// Refuses a sidecar naming another source than [`OrientationSource::Estimated`] beside a
    /// data file without orientation columns, whose orientation the reader estimates.
    /// `data` is the data file's path.
    pub(crate) fn check_estimated(&self, data: &Path) -> Result<()> {
        match (self.orientation_source, self.source_line) {
            (Some(s), Some(line)) if s != OrientationSource::Estimated => Err(DataError::format(
                Location::line(sidecar_path(data), line).with_field(SOURCE),
                format!(
                    "names `{}`, but the data file has no orientation columns \
                         (linacce_*, grav_*, rv_*): its orientation is estimated (`{}`, or no \
                         such line)",
                    s.key(),
                    OrientationSource::Estimated.key()
                ),
            )),
            _ => Ok(()),
        }
    }

    /// Gives `seq` the sidecar's device and, when it names one, its orientation source.
    pub(crate) fn apply(self, seq: &mut Sequence) {
        seq.set_device(self.device);
        if self.orientation_source.is_some() {
            seq.set_orientation_source(self.orientation_source);
        }
    }
}

/// The sidecar of the processed data file `data`: `data.csv` gives `data.csv.meta`, beside it.
pub fn sidecar_path(data: &Path) -> PathBuf {
    let mut name = data.file_name().unwrap_or_default().to_os_string();
    name.push(SIDECAR_SUFFIX);
    data.with_file_name(name)
}

/// What the sidecar of `data` holds; nothing without a sidecar.
pub(crate) fn read(data: &Path) -> Result<Sidecar> {
    let path = sidecar_path(data);
    match std::fs::metadata(&path) {
        Err(e) if !text::present(&path) && e.kind() == std::io::ErrorKind::NotFound => {
            return Ok(Sidecar::default());
        }
        Err(e) => return Err(DataError::io(&path, e)),
        Ok(_) => {}
    }
    let bytes = text::read_file_bounded(&path, MAX_BYTES)?;
    parse(text::as_text(&bytes, &path)?, &path)
}

/// Parses the content of the sidecar `path`.
fn parse(content: &str, path: &Path) -> Result<Sidecar> {
    let mut device: Option<(usize, DeviceInfo)> = None;
    let mut rate: Option<(usize, f64)> = None;
    let mut source: Option<(usize, OrientationSource)> = None;
    for (line, l) in text::lines(content) {
        let l = l.trim();
        if l.starts_with('#') {
            continue;
        }
        let Some((key, value)) = l.split_once('=') else {
            return Err(DataError::format(
                Location::line(path, line),
                format!("expected `key = value`, found `{}`", text::snippet(l)),
            ));
        };
        let (key, value) = (key.trim(), value.trim());
        let at = || Location::line(path, line).with_field(key);
        let first = match key {
            DEVICE => device.as_ref().map(|(l, _)| *l),
            RATE => rate.as_ref().map(|(l, _)| *l),
            SOURCE => source.as_ref().map(|(l, _)| *l),
            // A key of a later version.
            _ => continue,
        };
        if let Some(first) = first {
            return Err(DataError::format(
                at(),
                format!("given twice (first on line {first})"),
            ));
        }
        if key == DEVICE {
            let d = DeviceInfo::new(value).map_err(|e| DataError::format(at(), e.to_string()))?;
            device = Some((line, d));
        } else if key == SOURCE {
            let s = OrientationSource::ALL
                .into_iter()
                .find(|s| s.key() == value)
                .ok_or_else(|| {
                    let keys: Vec<&str> = OrientationSource::ALL.iter().map(|s| s.key()).collect();
                    DataError::format(
                        at(),
                        format!(
                            "unknown orientation source `{}` (one of {})",
                            text::snippet(value),
                            keys.join(", ")
                        ),
                    )
                })?;
            source = Some((line, s));
        } else {
            rate = Some((line, text::number(value, path, line, RATE, Nan::Reject)?));
        }
    }
    let orientation_source = source.map(|(_, s)| s);
    let source_line = source.map(|(line, _)| line);
    let device = match (device, rate) {
        (None, None) => None,
        (None, Some((line, _))) => {
            return Err(DataError::format(
                Location::line(path, line).with_field(RATE),
                format!("a device rate without `{DEVICE} = <model>`"),
            ));
        }
        (Some((_, d)), None) => Some(d),
        (Some((_, d)), Some((line, r))) => Some(d.with_imu_rate(r).map_err(|e| {
            DataError::format(Location::line(path, line).with_field(RATE), e.to_string())
        })?),
    };
    Ok(Sidecar {
        device,
        orientation_source,
        source_line,
    })
}

/// Removes the sidecar of `data`, if there is one: before a data file is renamed into place,
/// so that the new one is never read with the old one's metadata.
pub(crate) fn remove(data: &Path) -> Result<()> {
    let path = sidecar_path(data);
    match std::fs::remove_file(&path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(DataError::io(&path, e)),
        _ => Ok(()),
    }
}

/// The sidecar of `data` for `seq`, written in full to a temporary file ([`write_pending`]) to
/// be committed with the data file, when it has metadata to keep: a device, or an orientation
/// source other than the layout's game rotation vector. Without, nothing.
pub(crate) fn pending(seq: &Sequence, data: &Path) -> Result<Option<PendingFile>> {
    let device = seq.device();
    let source = seq
        .orientation_source()
        .filter(|&s| s != OrientationSource::GameRotationVector);
    if device.is_none() && source.is_none() {
        return Ok(None);
    }
    let name = data.file_name().unwrap_or_default().to_string_lossy();
    write_pending(&sidecar_path(data), |w| {
        writeln!(
            w,
            "# ridi-rs: what {name} has no column for (RIDI's own readers do not open this file)"
        )?;
        if let Some(device) = device {
            writeln!(w, "{DEVICE} = {}", device.model())?;
            if let Some(r) = device.imu_rate_hz() {
                writeln!(w, "{RATE} = {}", RoundTrip(r))?;
            }
        }
        if let Some(s) = source {
            writeln!(w, "{SOURCE} = {}", s.key())?;
        }
        Ok(())
    })
    .map(Some)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p() -> &'static Path {
        Path::new("data.csv.meta")
    }

    #[test]
    fn names_and_values_parse() {
        assert_eq!(
            sidecar_path(Path::new("a/processed/data.csv")),
            Path::new("a/processed/data.csv.meta")
        );
        let s = parse(
            "# c\n\ndevice = iPhone 4S\ndevice_imu_rate_hz=90.5\nlater = x\n\
             orientation_source = core-motion-attitude\n",
            p(),
        )
        .unwrap();
        let d = s.device.unwrap();
        assert_eq!((d.model(), d.imu_rate_hz()), ("iPhone 4S", Some(90.5)));
        assert_eq!(
            s.orientation_source,
            Some(OrientationSource::CoreMotionAttitude)
        );
        assert_eq!(parse("# nothing\n", p()).unwrap(), Sidecar::default());
        // No final line break: a hand-written file.
        assert!(parse("device = x", p()).unwrap().device.is_some());
        // A source without a device.
        let s = parse("orientation_source = rotation-vector\n", p()).unwrap();
        assert_eq!(
            (s.device, s.orientation_source),
            (None, Some(OrientationSource::RotationVector))
        );
        // Every source's key parses back to it.
        for source in OrientationSource::ALL {
            let s = parse(&format!("orientation_source = {}", source.key()), p()).unwrap();
            assert_eq!(s.orientation_source, Some(source));
        }
    }

    #[test]
    fn errors_name_line_and_key() {
        for (text, expect) in [
            (
                "device\n",
                "data.csv.meta:1: expected `key = value`, found `device`",
            ),
            (
                "device = a\n\ndevice = b\n",
                "data.csv.meta:3: field `device`: given twice (first on line 1)",
            ),
            (
                "device = \n",
                "data.csv.meta:1: field `device`: empty device model",
            ),
            (
                "device = x\ndevice_imu_rate_hz = fast\n",
                "data.csv.meta:2: field `device_imu_rate_hz`: `fast` is not a number",
            ),
            (
                "device = x\ndevice_imu_rate_hz = -3\n",
                "data.csv.meta:2: field `device_imu_rate_hz`: device IMU rate -3 Hz",
            ),
            (
                "device_imu_rate_hz = 100\n",
                "data.csv.meta:1: field `device_imu_rate_hz`: a device rate without `device",
            ),
            (
                "\norientation_source = compass\n",
                "data.csv.meta:2: field `orientation_source`: unknown orientation source `compass` (one of game-rotation-vector,",
            ),
            (
                "orientation_source = estimated\norientation_source = estimated\n",
                "data.csv.meta:2: field `orientation_source`: given twice (first on line 1)",
            ),
        ] {
            let e = parse(text, p()).unwrap_err().to_string();
            assert!(e.starts_with(expect), "{text:?}: {e}");
        }
    }
}
