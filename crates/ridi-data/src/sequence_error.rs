//! Why a sequence is refused, and the wording of its messages.

use crate::sequence::Channel;

/// The likeliest cause of a linear acceleration `scale` times off accelerometer minus gravity.
fn linacce_cause(scale: f64) -> &'static str {
    match scale {
        s if (5.0..20.0).contains(&s) => "linear acceleration in g instead of m/s^2",
        s if (0.0005..0.002).contains(&s) => "linear acceleration in mm/s^2 instead of m/s^2",
        // Gravity left in: the accelerometer's reading given for the linear acceleration.
        s if s.abs() < 0.3 => "gravity not taken out of the linear acceleration",
        s if s.is_infinite() => "a linear acceleration of zero where the phone accelerates",
        _ => "linear acceleration in another unit than m/s^2, or another column",
    }
}

/// A number for a message: plain with at most 3 decimals, or in scientific notation when very
/// large or small (`1e308`, not 309 digits).
pub fn short(v: f64) -> String {
    let a = v.abs();
    if !v.is_finite() {
        v.to_string()
    } else if a != 0.0 && !(1e-3..1e6).contains(&a) {
        let s = format!("{v:.3e}");
        let (mantissa, exp) = s.split_once('e').unwrap_or((&s, "0"));
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        format!("{mantissa}e{exp}")
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    }
}

/// A timestamp for a message, to `decimals` places, trailing zeros dropped (`0.495`, not
/// `0.49500000000000005`); unlike [`short`], never in scientific notation (a unix time). To
/// the nanosecond the files store (9), two timestamps that differ print differently.
fn time_text(t: f64, decimals: usize) -> String {
    let s = format!("{t:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        s
    }
}

/// Time units a file may hold its timestamps in, with their length in seconds.
const TIME_UNITS: [(&str, f64); 4] = [
    ("seconds", 1.0),
    ("milliseconds", 1e-3),
    ("microseconds", 1e-6),
    ("nanoseconds", 1e-9),
];

/// The message of [`SequenceError::TimeStep`] for timestamps read as `expected` units (one of
/// [`TIME_UNITS`]): the other unit in which the file's numbers would step by 1-100 ms, the
/// intervals of phone sensors, if one does.
pub(crate) fn time_step_message(median: f64, (min, max): (f64, f64), expected: &str) -> String {
    let unit = TIME_UNITS.iter().find(|u| u.0 == expected);
    debug_assert!(unit.is_some(), "`{expected}` is no unit of TIME_UNITS");
    let scale = unit.map_or(1.0, |u| u.1);
    let guess = TIME_UNITS
        .iter()
        .filter(|u| u.0 != expected)
        .find(|(_, s)| (1e-3..=0.1).contains(&(median / scale * s)))
        .map_or_else(
            || "time in the wrong unit?".to_owned(),
            |&(unit, s)| {
                let factor = s / scale;
                let fix = if factor < 1.0 {
                    format!("divide by {}", short((1.0 / factor).round()))
                } else {
                    format!("multiply by {}", short(factor.round()))
                };
                format!("time in {unit} instead of {expected} ({fix})?")
            },
        );
    format!(
        "timestamps step by {} s (median), outside {}..{} s: {guess}",
        short(median),
        short(min),
        short(max)
    )
}

/// Axis names of the 3-vector channels.
pub(crate) const AXES: [&str; 3] = ["x", "y", "z"];

/// The name of `axis` (0..3) in an error's message; `?` for another (the errors' fields are
/// public: a message never panics).
pub(crate) fn axis_name(axis: usize) -> &'static str {
    AXES.get(axis).copied().unwrap_or("?")
}

/// What is wrong with a value beyond its channel's bound, e.g. `1e308 m/s^2 is beyond any phone
/// accelerometer (|value| <= 2000 m/s^2)`.
pub(crate) fn beyond(channel: Channel, value: f64, limit: f64) -> String {
    let unit = channel.unit();
    format!(
        "{} {unit} is beyond {} (|value| <= {} {unit})",
        short(value),
        channel.beyond(),
        short(limit)
    )
}

/// What is wrong with a ground-truth step too fast for a pedestrian, e.g. `jumps 1000 m in
/// 0.005 s (200000 m/s): faster than any pedestrian (speed <= 100 m/s), a corrupt position?`.
pub(crate) fn jump(distance: f64, dt: f64, max: f64) -> String {
    if dt.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        // Only reachable by calling `check_speed` directly: `Sequence::new` refuses such times.
        return format!(
            "jumps {} m between frames {} s apart: time must increase",
            short(distance),
            short(dt)
        );
    }
    format!(
        "jumps {} m in {} s ({} m/s): faster than any pedestrian (speed <= {} m/s), a corrupt \
         position?",
        short(distance),
        short(dt),
        short(distance / dt),
        short(max)
    )
}

/// Why a set of [`SequenceParts`](crate::SequenceParts) is not a valid sequence.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SequenceError {
    /// No frames.
    #[error("sequence has no frames")]
    Empty,
    /// A channel's length differs from the timeline's.
    #[error("`{what}` has {found} frames, the timeline has {expected}")]
    LengthMismatch {
        /// The channel.
        what: &'static str,
        /// Length of the timeline.
        expected: usize,
        /// Length of the channel.
        found: usize,
    },
    /// NaN or infinity.
    #[error("`{what}` is not finite at frame {index}")]
    NonFinite {
        /// The channel.
        what: &'static str,
        /// 0-based frame index.
        index: usize,
    },
    /// Time does not strictly increase.
    #[error(
        "time does not increase at frame {index}: {} s then {} s",
        time_text(*previous, 9),
        time_text(*next, 9)
    )]
    TimeNotIncreasing {
        /// 0-based index of the later frame.
        index: usize,
        /// Time of the earlier frame.
        previous: f64,
        /// Time of the later frame.
        next: f64,
    },
    /// Two frames are too far apart.
    #[error(
        "gap of {gap_s:.3} s before frame {index} (at {} s) exceeds {} s",
        time_text(*time, 3),
        short(*max_gap_s)
    )]
    Gap {
        /// 0-based index of the frame after the gap.
        index: usize,
        /// Its time.
        time: f64,
        /// Length of the gap.
        gap_s: f64,
        /// The limit.
        max_gap_s: f64,
    },
    /// A gap to split at that is not a finite number of seconds above 0, or a shortest part
    /// that is not a number of at least 0
    /// ([`Sequence::split_at_gaps`](crate::Sequence::split_at_gaps)).
    #[error(
        "cannot split at gaps longer than {} s into parts of at least {} s: the gap must be a \
         finite number above 0, the duration a number of at least 0",
        short(*max_gap_s),
        short(*min_duration_s)
    )]
    InvalidGap {
        /// The gap asked for.
        max_gap_s: f64,
        /// The shortest part asked for.
        min_duration_s: f64,
    },
    /// A resampling rate outside [`RESAMPLE_RATE_RANGE_HZ`](crate::RESAMPLE_RATE_RANGE_HZ), or a gap
    /// limit that is not a number above 0 ([`Sequence::resampled`](crate::Sequence::resampled)).
    #[error(
        "cannot resample to {rate_hz} Hz across gaps of up to {} s: the rate must be from {} \
         to {} Hz (the steps a sequence may have), the gap limit a number above 0",
        short(*max_gap_s),
        crate::RESAMPLE_RATE_RANGE_HZ.0,
        crate::RESAMPLE_RATE_RANGE_HZ.1
    )]
    InvalidRate {
        /// The rate asked for.
        rate_hz: f64,
        /// The longest gap to interpolate across, seconds.
        max_gap_s: f64,
    },
    /// A rotation that is not a finite unit quaternion (a corrupt value; `Rot`'s constructors
    /// normalize, but an angle or axis that is NaN gives a NaN one).
    #[error("`{what}` at frame {index} is not a rotation (not a finite unit quaternion)")]
    NotRotation {
        /// Which rotations.
        what: &'static str,
        /// 0-based frame index.
        index: usize,
    },
    /// A resampling across gaps that would be most of the result
    /// ([`Sequence::resampled`](crate::Sequence::resampled) with a gap limit above 1 s): more
    /// than twice the frames of the recorded stretches (its steps of up to 1 s) at that rate.
    #[error(
        "resampling would make {frames} frames, more than twice the {covered} of its recorded \
         stretches at that rate: gaps over 1 s would be most of the sequence (split it at its \
         gaps first)"
    )]
    ResampledAcrossGaps {
        /// Frames the uniform timeline would have.
        frames: usize,
        /// Frames of the recorded stretches at the rate asked for (steps of up to 1 s).
        covered: usize,
    },
    /// A value beyond the hard physical bound of its channel ([`Validation::limit`](crate::Validation::limit)): a
    /// corrupt value or a wrong unit.
    #[error("`{channel}.{}` at frame {index}: {}", axis_name(*axis), beyond(*channel, *value, *limit))]
    Implausible {
        /// The channel.
        channel: Channel,
        /// 0 (x), 1 (y) or 2 (z).
        axis: usize,
        /// 0-based frame index.
        index: usize,
        /// The value.
        value: f64,
        /// The bound its magnitude exceeds.
        limit: f64,
    },
    /// The median gyro magnitude is too large for rad/s.
    #[error(
        "median |gyro| {} rad/s is above {max} rad/s: gyroscope in deg/s instead of rad/s?",
        short(*median)
    )]
    GyroUnits {
        /// Median magnitude found.
        median: f64,
        /// The limit ([`Validation::max_median_gyro`](crate::Validation::max_median_gyro)).
        max: f64,
    },
    /// The mean accelerometer magnitude is far from the mean gravity magnitude.
    #[error(
        "mean |acce| {} m/s^2 is {} times mean |gravity| {} m/s^2, outside {min}..{max}: \
         accelerometer in {}?",
        short(*acce),
        short(acce / gravity),
        short(*gravity),
        if acce < gravity { "g instead of m/s^2" } else { "another unit than m/s^2" }
    )]
    AcceScale {
        /// Mean accelerometer magnitude.
        acce: f64,
        /// Mean gravity magnitude.
        gravity: f64,
        /// Lowest accepted ratio.
        min: f64,
        /// Highest accepted ratio.
        max: f64,
    },
    /// The gyro does not turn as fast as the orientation.
    #[error(
        "the gyro turns {} times as fast as the orientation (least squares over frames), \
         outside {min}..{max}: {}?",
        short(*scale),
        if *scale > 20.0 && *scale < 200.0 {
            "gyroscope in deg/s instead of rad/s"
        } else {
            "a gyro in another unit, or of another recording or device"
        }
    )]
    GyroScale {
        /// The fitted scale.
        scale: f64,
        /// Lowest accepted scale.
        min: f64,
        /// Highest accepted scale.
        max: f64,
    },
    /// The gyro turns about other axes than the orientation (`crate::MIN_GYRO_AGREEMENT`).
    #[error(
        "the gyro turns against the orientation: their rotation rates agree in direction by {} \
         (1 when alike, -1 when opposite; at least {min} expected): a gyro with its sign \
         flipped or its axes swapped, or an orientation quaternion in another component order \
         (x, y, z, w where w, x, y, z is expected) or of another device frame?",
        short(*agreement)
    )]
    GyroDirection {
        /// Sum of the rate vectors' dot products over the sum of their magnitudes' products.
        agreement: f64,
        /// Lowest accepted agreement.
        min: f64,
    },
    /// A gyro axis reads far less than the orientation turns about it
    /// (`crate::MIN_GYRO_AXIS_SCALE`).
    #[error(
        "the gyro's {} axis reads {} times the orientation's rotation rate about it (least \
         squares over frames; at least {min} expected, where the other axes agree): {}?",
        axis_name(*axis),
        short(*scale),
        if *scale < -0.5 { "a gyro axis with its sign reversed" } else { "a dead or stuck gyro axis" }
    )]
    GyroAxis {
        /// The device axis, 0..3.
        axis: usize,
        /// The fitted scale.
        scale: f64,
        /// Lowest accepted scale.
        min: f64,
    },
    /// The linear acceleration does not match accelerometer minus gravity in size.
    #[error(
        "accelerometer minus gravity is {} times the linear acceleration (least squares), \
         outside {min}..{max}: {}?",
        short(*scale),
        linacce_cause(*scale)
    )]
    LinacceScale {
        /// The fitted scale.
        scale: f64,
        /// Lowest accepted scale.
        min: f64,
        /// Highest accepted scale.
        max: f64,
    },
    /// The ground truth moves too fast for a pedestrian: positions in another unit than metres.
    #[error(
        "the ground truth moves at a median {} m/s, above {max} m/s: positions in mm or cm \
         instead of metres?",
        short(*median)
    )]
    GroundTruthSpeed {
        /// Median speed found, m/s.
        median: f64,
        /// The limit ([`Validation::max_median_speed`](crate::Validation::max_median_speed)).
        max: f64,
    },
    /// Two consecutive ground-truth positions too far apart for the time between them
    /// ([`Validation::max_speed`](crate::Validation::max_speed)): a corrupt position.
    #[error(
        "`ground_truth.position.{}` at frame {index}: {}",
        axis_name(*axis),
        jump(*distance, *dt, *max)
    )]
    GroundTruthJump {
        /// 0-based index of the suspect frame: the later frame of the first step too fast,
        /// except frame 0 when that step is the first and every later step is fine (frame 0
        /// alone disagrees with the rest).
        index: usize,
        /// The axis that moves most: 0 (x), 1 (y) or 2 (z).
        axis: usize,
        /// Distance between the two positions, metres.
        distance: f64,
        /// Time between them, seconds.
        dt: f64,
        /// The limit, m/s.
        max: f64,
    },
    /// The median interval between timestamps is outside [`Validation::time_step_range`](crate::Validation::time_step_range).
    #[error("{}", time_step_message(*median, (*min, *max), "seconds"))]
    TimeStep {
        /// Median interval, seconds.
        median: f64,
        /// Lower limit.
        min: f64,
        /// Upper limit.
        max: f64,
    },
    /// The orientation estimate refused the sequence
    /// ([`Sequence::with_estimated_orientation`](crate::Sequence::with_estimated_orientation)).
    #[error("{what}: {error}")]
    Estimate {
        /// What was being estimated.
        what: &'static str,
        /// Why it failed.
        error: ridi_frames::EstimateError,
    },
    /// Gravity is far from the up axis the orientation gives, over most frames.
    #[error(
        "gravity is {} degrees from the up axis the orientation gives (median over frames), \
         more than {}: a quaternion's components in another order ([x, y, z, w] for \
         [w, x, y, z] or the reverse), device-from-world for world-from-device, or gravity's \
         sign flipped?",
        short(*median_deg),
        short(*max_deg)
    )]
    OrientationGravity {
        /// Median angle, degrees.
        median_deg: f64,
        /// The limit ([`Validation::max_orientation_gravity_deg`](crate::Validation::max_orientation_gravity_deg)).
        max_deg: f64,
    },
    /// The orientation stays put while the gyro turns
    /// ([`ORIENTATION_STILL_GYRO_RATE`](crate::ORIENTATION_STILL_GYRO_RATE)).
    #[error(
        "the orientation turns at {} rad/s RMS while the gyro turns at {} rad/s RMS: an \
         orientation that stays put while the phone turns (a placeholder such as the identity \
         quaternion, or an orientation of another recording){}?",
        short(*orientation_rms),
        short(*gyro_rms),
        // In deg/s the gyro of a phone that hardly turns reads this much too.
        if gyro_rms.to_radians() < crate::ORIENTATION_STILL_GYRO_RATE {
            ", or a gyroscope in deg/s on a phone that hardly turns"
        } else {
            ""
        }
    )]
    OrientationStill {
        /// RMS rotation rate of the orientation, rad/s.
        orientation_rms: f64,
        /// RMS rotation rate of the gyro, rad/s.
        gyro_rms: f64,
    },
    /// Mean gravity magnitude outside the plausible range: wrong units or a wrong column.
    #[error(
        "mean gravity magnitude {mean:.3} m/s^2 is outside {min}..{max}: wrong units or column?"
    )]
    Gravity {
        /// Mean magnitude found.
        mean: f64,
        /// Lower limit.
        min: f64,
        /// Upper limit.
        max: f64,
    },
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_in_messages_are_short() {
        assert_eq!(short(1e308), "1e308");
        assert_eq!(short(-5e-12), "-5e-12");
        assert_eq!(short(4.999_999e-12), "5e-12");
        assert_eq!(short(57.295_779_5), "57.296");
        assert_eq!(short(2000.0), "2000");
        assert_eq!(short(1e6), "1e6");
        assert_eq!(short(0.0), "0");
        assert_eq!(
            (short(f64::NAN), short(f64::NEG_INFINITY)),
            ("NaN".into(), "-inf".into())
        );
    }

    #[test]
    fn an_axis_beyond_z_is_shown_not_indexed() {
        let e = SequenceError::Implausible {
            channel: Channel::Gyro,
            axis: 3,
            index: 0,
            value: 1e9,
            limit: 100.0,
        };
        assert!(e.to_string().starts_with("`gyro.?` at frame 0"), "{e}");
    }
}
