//! Turning features and targets about S's up axis: training windows as they would have been
//! measured with the phone carried turned by some angle about the vertical.
//!
//! Every channel of a feature is a 3-vector in S and the Gaussian smoothing is linear, so a
//! window of a phone turned by `angle` about S-up (+y) is the same window with each x-z pair
//! rotated; its target turns the same way. A regressor trained only on the headings the
//! training people happened to carry the phone at fails on a person who carries it otherwise
//! (a back-pocket phone turned 100 degrees, a swinging hand turned around); turned copies teach
//! it that the velocity turns with the signal.

use ridi_frames::StabHorizontal;

use crate::FeatureError;
use crate::matrix::FeatureMatrix;

/// Rotation about S-up by `angle` radians, as the `(cos, sin)` of an x-z rotation:
/// `x' = c x + s z`, `z' = -s x + c z` (right-handed about +y).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct YawTurn {
    cos: f64,
    sin: f64,
}

impl YawTurn {
    /// The turn by `angle` radians about S-up.
    pub fn new(angle: f64) -> Self {
        Self {
            cos: angle.cos(),
            sin: angle.sin(),
        }
    }

    /// Turns a horizontal vector in S (a velocity target).
    pub fn horizontal(&self, v: StabHorizontal) -> StabHorizontal {
        let [x, z] = v.to_array();
        StabHorizontal::new(self.cos * x + self.sin * z, -self.sin * x + self.cos * z)
    }

    /// Turns every 3-vector `x y z` of a feature row in place (any number of channels: all
    /// are vectors in S). Fails when the row is not made of whole 3-vectors.
    pub fn row(&self, row: &mut [f32]) -> Result<(), FeatureError> {
        if !row.len().is_multiple_of(3) {
            return Err(FeatureError::LengthMismatch {
                what: "feature row (whole 3-vectors)",
                expected: row.len() / 3 * 3,
                found: row.len(),
            });
        }
        let (c, s) = (self.cos as f32, self.sin as f32);
        for v in row.chunks_exact_mut(3) {
            [v[0], v[2]] = [c * v[0] + s * v[2], -s * v[0] + c * v[2]];
        }
        Ok(())
    }
}

/// Rows with their turned copies ([`turned_copies`]).
#[derive(Debug, Clone, PartialEq)]
pub struct TurnedRows {
    /// The input rows, then copy 0 of every row, copy 1, ...
    pub features: FeatureMatrix,
    /// Their targets, turned with them.
    pub targets: Vec<StabHorizontal>,
    /// For each row, the input row it comes from (to repeat labels and groups).
    pub source: Vec<usize>,
}

/// Training rows plus `copies` turned copies of each: copy `j` of row `i` is turned by
/// `2 pi frac(i phi + j / copies)` (phi the golden ratio), so each row's copies are evenly
/// spaced around the circle and neighbouring rows, which overlap in time, start at well spread
/// angles. Deterministic. Fails when `targets` and `features` differ in length.
///
/// The rows must not be standardized yet: a per-column standardization scales S-x and S-z
/// differently, so turning a standardized row is not standardizing a turned one. Turn first,
/// then fit the standardization on all rows (as `ridi`'s training does).
pub fn turned_copies(
    features: &FeatureMatrix,
    targets: &[StabHorizontal],
    copies: usize,
) -> Result<TurnedRows, FeatureError> {
    if targets.len() != features.rows() {
        return Err(FeatureError::LengthMismatch {
            what: "targets (one per feature row)",
            expected: features.rows(),
            found: targets.len(),
        });
    }
    let n = features.rows();
    let total = copies
        .checked_add(1)
        .and_then(|c| n.checked_mul(c))
        .ok_or_else(|| {
            FeatureError::InvalidConfig(format!("{copies} turned copies of {n} rows overflow"))
        })?;
    // Checked once here, so that the rows below cannot fail half-way.
    YawTurn::new(0.0).row(&mut vec![0.0; features.cols()])?;
    // Appended rather than zero-filled and overwritten: the matrix is the whole training set.
    // Reserved fallibly: a count of copies no memory holds is an error, not an abort.
    let too_many = || {
        FeatureError::InvalidConfig(format!(
            "{copies} turned copies of {n} rows of {} features do not fit in memory",
            features.cols()
        ))
    };
    let values = total.checked_mul(features.cols()).ok_or_else(too_many)?;
    let mut data = Vec::new();
    data.try_reserve_exact(values).map_err(|_| too_many())?;
    data.extend_from_slice(features.as_slice());
    let mut targets_out = Vec::new();
    targets_out
        .try_reserve_exact(total)
        .map_err(|_| too_many())?;
    targets_out.extend_from_slice(targets);
    let mut source = Vec::new();
    source.try_reserve_exact(total).map_err(|_| too_many())?;
    source.extend(0..n);
    const PHI: f64 = 0.618_033_988_749_894_9;
    for j in 0..copies {
        for (i, target) in targets.iter().enumerate() {
            let turn = (i as f64 * PHI + j as f64 / copies as f64).fract();
            let t = YawTurn::new(std::f64::consts::TAU * turn);
            let start = data.len();
            data.extend_from_slice(features.row(i));
            t.row(&mut data[start..])?;
            targets_out.push(t.horizontal(*target));
            source.push(i);
        }
    }
    Ok(TurnedRows {
        features: FeatureMatrix::from_vec(total, features.cols(), data)?,
        targets: targets_out,
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{FeatureConfig, FeatureExtractor, GroundTruthView, compute_targets};
    use ridi_frames::nalgebra::Vector3;
    use ridi_frames::{DeviceVec, ImuFrames, WorldFromDevice, WorldVec};

    /// A flat phone with heading `yaw` (about world up) walking along world +y at 1 m/s, its
    /// gyro and linear acceleration given in the world and measured in the device frame.
    fn walk(yaw: f64) -> (FeatureMatrix, Vec<StabHorizontal>) {
        let n = 1000;
        let time: Vec<f64> = (0..n).map(|i| i as f64 / 200.0).collect();
        let q = WorldFromDevice::from_axis_angle(&Vector3::z_axis(), yaw);
        let gyro: Vec<DeviceVec> = (0..n)
            .map(|i| q.inverse() * WorldVec::new(0.3 * (i as f64 * 0.05).sin(), 0.1, 0.2))
            .collect();
        let linacce: Vec<DeviceVec> = (0..n)
            .map(|i| q.inverse() * WorldVec::new(0.5, -0.7 * (i as f64 * 0.07).cos(), 0.1))
            .collect();
        let gravity = vec![DeviceVec::new(0.0, 0.0, 9.81); n];
        let position: Vec<WorldVec> = time.iter().map(|&t| WorldVec::new(0.0, t, 0.0)).collect();
        let orientation = vec![q; n];
        let config = FeatureConfig::default();
        let frames: Vec<usize> = vec![300, 600, 900];
        let fx = FeatureExtractor::new(config.clone()).unwrap();
        let stab = fx
            .stabilize(&ImuFrames::new(&time, &gyro, &linacce, &gravity, &orientation).unwrap())
            .unwrap();
        let x = fx.features(&stab, &frames).unwrap();
        let gt = GroundTruthView {
            time: &time,
            position: &position,
            orientation: &orientation,
            gravity: &gravity,
        };
        let y = compute_targets(&gt, &config, &frames).unwrap();
        (x, y.values)
    }

    #[test]
    fn turning_keeps_up_and_lengths() {
        let t = YawTurn::new(1.0);
        let mut row = [1.0f32, 2.0, 3.0, -4.0, 5.0, 6.0];
        t.row(&mut row).unwrap();
        assert_eq!((row[1], row[4]), (2.0, 5.0));
        assert!(((row[0].powi(2) + row[2].powi(2)) - 10.0).abs() < 1e-5);
        assert!(((row[3].powi(2) + row[5].powi(2)) - 52.0).abs() < 1e-4);
        let back = YawTurn::new(-1.0);
        back.row(&mut row).unwrap();
        for (a, b) in row.iter().zip([1.0f32, 2.0, 3.0, -4.0, 5.0, 6.0]) {
            assert!((a - b).abs() < 1e-5);
        }
        assert!(t.row(&mut [0.0; 4]).is_err());
    }

    /// A phone carried turned by `a` about the vertical measures the window and target of
    /// the unturned phone turned by `-a` about S-up.
    #[test]
    fn turned_window_is_the_window_of_a_turned_phone() {
        let (x, y) = walk(0.3);
        let (x_turned, y_turned) = walk(0.3 + 0.7);
        let t = YawTurn::new(-0.7);
        for i in 0..x.rows() {
            let mut row = x.row(i).to_vec();
            t.row(&mut row).unwrap();
            for (a, b) in row.iter().zip(x_turned.row(i)) {
                assert!((a - b).abs() < 1e-5, "{a} {b}");
            }
            let v = t.horizontal(y[i]);
            assert!((v - y_turned[i]).norm() < 1e-5, "{v:?} {:?}", y_turned[i]);
        }
    }

    #[test]
    fn copies_are_spread_and_keep_speed_and_up() {
        let (x, y) = walk(0.3);
        let TurnedRows {
            features: turned,
            targets: ty,
            source,
        } = turned_copies(&x, &y, 2).unwrap();
        assert_eq!(turned.rows(), 9);
        assert_eq!(source, vec![0, 1, 2, 0, 1, 2, 0, 1, 2]);
        for r in 0..turned.rows() {
            let i = source[r];
            // Speed and the vertical channels are kept.
            assert!((ty[r].norm() - y[i].norm()).abs() < 1e-12);
            for k in (1..1200).step_by(3) {
                assert_eq!(turned.row(r)[k], x.row(i)[k]);
            }
        }
        // The two copies of one row are half a turn apart.
        assert!((ty[3] + ty[6]).norm() < 1e-5);
        assert!(turned_copies(&x, &y[..2], 1).is_err());
        // More copies than memory holds: an error, not an abort or an overflow.
        for copies in [1 << 40, usize::MAX] {
            let e = turned_copies(&x, &y, copies).unwrap_err().to_string();
            assert!(e.contains("turned copies of 3 rows"), "{e}");
        }
    }
}
