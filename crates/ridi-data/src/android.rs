//! Android sensor conventions shared by the readers of plain Android recordings (Tyrex, Indoor
//! Location Competition), which log the rotation vector but no gravity sensor.

use ridi_frames::{DeviceVec, QuatError, WorldFromDevice, gravity_in_device};

/// The world-from-device rotation of an Android rotation vector (`TYPE_ROTATION_VECTOR`,
/// `TYPE_GAME_ROTATION_VECTOR`): `x, y, z` is the vector part of a unit quaternion and `w` its
/// scalar part. When `w` is not given (old Android versions, recorders that log only
/// `values[0..3]`), it is `sqrt(1 - x² - y² - z²)`: Android's `w >= 0`.
///
/// The error is a sentence for a user, to be placed at the file, line and field.
pub(crate) fn rotation_vector(xyz: [f64; 3], w: Option<f64>) -> Result<WorldFromDevice, String> {
    let [x, y, z] = xyz;
    let w = w.unwrap_or_else(|| (1.0 - x * x - y * y - z * z).max(0.0).sqrt());
    WorldFromDevice::from_xyzw([x, y, z, w]).map_err(|e| match e {
        QuatError::NotUnit { norm } => format!("quaternion x,y,z,w has norm {norm:.4}, not 1"),
        other => other.to_string(),
    })
}

/// Gravity (pointing up, `g` long, as Android's gravity sensor reports it) in the device frame
/// of each orientation, and linear acceleration = accelerometer − gravity: how a reader derives
/// both when the recording has no gravity sensor.
pub(crate) fn gravity_and_linacce(
    orientation: &[WorldFromDevice],
    acce: &[DeviceVec],
    g: f64,
) -> (Vec<DeviceVec>, Vec<DeviceVec>) {
    let gravity: Vec<DeviceVec> = orientation
        .iter()
        .map(|&q| gravity_in_device(q, g))
        .collect();
    let linacce = acce.iter().zip(&gravity).map(|(&a, &g)| a - g).collect();
    (gravity, linacce)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_w_is_the_non_negative_completion() {
        let q = rotation_vector([0.0, 0.0, 0.6], None).unwrap();
        let [w, x, y, z] = q.to_wxyz();
        assert!((w - 0.8).abs() < 1e-12 && x == 0.0 && y == 0.0 && (z - 0.6).abs() < 1e-12);
        // Rounding just above 1 gives w = 0, not NaN.
        assert!(rotation_vector([1.000_000_1, 0.0, 0.0], None).is_ok());
        let e = rotation_vector([0.9, 0.9, 0.0], None).unwrap_err();
        assert!(e.contains("norm 1.27"), "{e}");
        assert!(rotation_vector([0.0, 0.0, 0.0], Some(1.0)).is_ok());
    }

    #[test]
    fn gravity_points_up_and_linacce_is_the_rest() {
        let q = [WorldFromDevice::identity()];
        let (g, l) = gravity_and_linacce(&q, &[DeviceVec::new(0.5, 0.0, 10.0)], 9.8);
        assert_eq!(g[0], DeviceVec::new(0.0, 0.0, 9.8));
        assert!((l[0] - DeviceVec::new(0.5, 0.0, 0.2)).norm() < 1e-12);
    }
}
