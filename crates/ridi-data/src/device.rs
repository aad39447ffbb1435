//! Which phone a sequence was recorded with: what evaluation groups results by, and what
//! `ridi convert` names its per-device list files after.

use std::fmt;

use serde::Serialize;

/// The phone a sequence was recorded with, as far as its source says: the model name
/// (`"Nexus 5"`, `"iPhone 4S"`, `"OPPO PBCM10"`) and the rate its IMU sampled at before any
/// resampling.
///
/// Valid by construction ([`DeviceInfo::new`], [`DeviceInfo::with_imu_rate`]): the model is a
/// non-empty line of at most [`DeviceInfo::MAX_MODEL_LEN`] characters without control
/// characters and with at least one ASCII letter or digit (its [`key`](DeviceInfo::key)), and
/// the rate, when given, is a finite number above 0.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DeviceInfo {
    model: String,
    imu_rate_hz: Option<f64>,
}

/// Why a model name or rate is not a valid [`DeviceInfo`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DeviceError {
    /// Nothing but white space.
    #[error("empty device model")]
    Empty,
    /// Longer than [`DeviceInfo::MAX_MODEL_LEN`] characters.
    #[error("device model of {found} characters, at most {max} allowed")]
    TooLong {
        /// Its length in characters.
        found: usize,
        /// The limit.
        max: usize,
    },
    /// A line break, tab or other control character.
    #[error("device model `{model}` holds a control character (a line break, a tab)")]
    ControlCharacter {
        /// The model, with the character escaped.
        model: String,
    },
    /// No ASCII letter or digit, so no file-name-safe key.
    #[error("device model `{model}` has no ASCII letter or digit to name its list file after")]
    NoKey {
        /// The model.
        model: String,
    },
    /// A rate that is not a finite number above 0.
    #[error("device IMU rate {rate_hz} Hz: must be a finite number above 0")]
    Rate {
        /// The rate given.
        rate_hz: f64,
    },
}

impl DeviceInfo {
    /// The longest model name accepted, in characters.
    pub const MAX_MODEL_LEN: usize = 100;

    /// The device `model` (white space around it removed), rate unknown.
    ///
    /// ```
    /// use ridi_data::DeviceInfo;
    /// let d = DeviceInfo::new(" iPhone 4S ")?;
    /// assert_eq!((d.model(), d.key().as_str()), ("iPhone 4S", "iphone4s"));
    /// assert!(DeviceInfo::new("a\nb").is_err());
    /// # Ok::<(), ridi_data::DeviceError>(())
    /// ```
    pub fn new(model: &str) -> Result<Self, DeviceError> {
        let model = model.trim();
        if model.is_empty() {
            return Err(DeviceError::Empty);
        }
        let found = model.chars().count();
        if found > Self::MAX_MODEL_LEN {
            return Err(DeviceError::TooLong {
                found,
                max: Self::MAX_MODEL_LEN,
            });
        }
        if model.chars().any(char::is_control) {
            return Err(DeviceError::ControlCharacter {
                model: model.escape_debug().to_string(),
            });
        }
        if !model.chars().any(|c| c.is_ascii_alphanumeric()) {
            return Err(DeviceError::NoKey {
                model: model.to_owned(),
            });
        }
        Ok(Self {
            model: model.to_owned(),
            imu_rate_hz: None,
        })
    }

    /// With the rate of the device's IMU, Hz.
    pub fn with_imu_rate(mut self, rate_hz: f64) -> Result<Self, DeviceError> {
        if !(rate_hz.is_finite() && rate_hz > 0.0) {
            return Err(DeviceError::Rate { rate_hz });
        }
        self.imu_rate_hz = Some(rate_hz);
        Ok(self)
    }

    /// The model name (`"iPhone 4S"`).
    pub fn model(&self) -> &str {
        &self.model
    }

    /// The rate the device's IMU sampled at, Hz, before any resampling: for the readers that
    /// set it, the slower of the accelerometer's and the gyroscope's (one over the median
    /// interval between their samples). `None` when the source does not tell.
    pub fn imu_rate_hz(&self) -> Option<f64> {
        self.imu_rate_hz
    }

    /// The model as a file-name-safe key: its ASCII letters and digits, lower case (`"Nexus 5"`
    /// gives `nexus5`, `"iPhone 4S"` `iphone4s`). `ridi convert` writes `list_<key>.txt`.
    pub fn key(&self) -> String {
        self.model
            .chars()
            .filter(char::is_ascii_alphanumeric)
            .map(|c| c.to_ascii_lowercase())
            .collect()
    }
}

/// One over the median interval between the sorted timestamps `time` (seconds); `None` with
/// fewer than two, or when that is not a finite rate above 0.
pub(crate) fn median_rate_hz(time: &[f64]) -> Option<f64> {
    let mut dt: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
    if dt.is_empty() {
        return None;
    }
    let mid = dt.len() / 2;
    let (_, median, _) = dt.select_nth_unstable_by(mid, f64::total_cmp);
    let rate = 1.0 / *median;
    (rate.is_finite() && rate > 0.0).then_some(rate)
}

/// `device` with the slower of the rates of the accelerometer's and the gyroscope's timestamps
/// (what [`DeviceInfo::imu_rate_hz`] means), when both are known.
pub(crate) fn with_imu_rate(device: DeviceInfo, acce: &[f64], gyro: &[f64]) -> DeviceInfo {
    match (median_rate_hz(acce), median_rate_hz(gyro)) {
        (Some(a), Some(g)) => device.clone().with_imu_rate(a.min(g)).unwrap_or(device),
        _ => device,
    }
}

impl fmt::Display for DeviceInfo {
    /// `iPhone 4S`, or `iPhone 4S (IMU at 90 Hz)` when the rate is known.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.imu_rate_hz {
            Some(r) => write!(f, "{} (IMU at {r:.0} Hz)", self.model),
            None => f.write_str(&self.model),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn models_are_checked_and_keyed() {
        let d = DeviceInfo::new("Nexus 5").unwrap();
        assert_eq!(d.key(), "nexus5");
        assert_eq!(d.to_string(), "Nexus 5");
        let d = d.with_imu_rate(198.6).unwrap();
        assert_eq!(d.to_string(), "Nexus 5 (IMU at 199 Hz)");
        assert_eq!(DeviceInfo::new("  ").unwrap_err(), DeviceError::Empty);
        assert_eq!(DeviceInfo::new("OPPO PBCM10").unwrap().key(), "oppopbcm10");
        let e = DeviceInfo::new("a\tb").unwrap_err();
        assert_eq!(
            e.to_string(),
            "device model `a\\tb` holds a control character (a line break, a tab)"
        );
        assert!(matches!(
            DeviceInfo::new("--- ü"),
            Err(DeviceError::NoKey { .. })
        ));
        assert!(matches!(
            DeviceInfo::new(&"x".repeat(101)),
            Err(DeviceError::TooLong {
                found: 101,
                max: 100
            })
        ));
        assert!(DeviceInfo::new(&"é".repeat(99)).is_err());
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(DeviceInfo::new("x").unwrap().with_imu_rate(bad).is_err());
        }
    }

    #[test]
    fn the_imu_rate_is_the_slower_stream_s_median_rate() {
        let every = |dt: f64, n: usize| (0..n).map(|i| i as f64 * dt).collect::<Vec<_>>();
        let mut acce = every(0.01, 50);
        acce[20] += 0.004;
        let d = with_imu_rate(DeviceInfo::new("x").unwrap(), &acce, &every(0.005, 99));
        assert!((d.imu_rate_hz().unwrap() - 100.0).abs() < 1e-6, "{d:?}");
        assert_eq!(median_rate_hz(&[1.0]), None);
        assert_eq!(median_rate_hz(&[1.0, 1.0, 1.0]), None);
        let d = with_imu_rate(DeviceInfo::new("x").unwrap(), &[0.0], &every(0.005, 9));
        assert_eq!(d.imu_rate_hz(), None);
    }
}
