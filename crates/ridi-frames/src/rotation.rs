//! Frame-tagged rotations.

use std::fmt;
use std::marker::PhantomData;
use std::ops::Mul;

use nalgebra::{Matrix3, Quaternion, Rotation3, Unit, UnitQuaternion, Vector3};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::frame::{Device, Frame, Stabilized, World};
use crate::vector::Vec3;

/// A rotation taking vectors of frame `From` to frame `To`: `v_To = q v_From q*`.
///
/// Backed by a Hamilton unit quaternion. Composition type-checks frames:
/// `Rot<A, B> * Rot<B, C> = Rot<A, C>` and `Rot<A, B> * Vec3<B> = Vec3<A>`.
///
/// Quaternion order is explicit at every edge: [`Rot::from_wxyz`] / [`Rot::to_wxyz`] (RIDI
/// csv, scipy-free Hamilton order) and [`Rot::from_xyzw`] / [`Rot::to_xyzw`] (Android rotation
/// vectors, Tango poses). Serialized as `[w, x, y, z]`.
#[repr(transparent)]
pub struct Rot<To: Frame, From: Frame> {
    q: UnitQuaternion<f64>,
    frames: PhantomData<(To, From)>,
}

/// Device orientation: world-from-device, `v_W = q v_I q*`.
pub type WorldFromDevice = Rot<World, Device>;
/// Stabilizing rotation of one frame: S-from-device.
pub type StabFromDevice = Rot<Stabilized, Device>;
/// World to stabilized frame: `align(g) * q*`.
pub type StabFromWorld = Rot<Stabilized, World>;

/// Why a quaternion or a rotation matrix was rejected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum QuatError {
    /// A component of the quaternion, or an entry of the matrix ([`Rot::from_matrix`]), is NaN
    /// or infinite.
    NonFinite {
        /// What holds it: a quaternion component (in the order given) or a matrix entry.
        what: &'static str,
        /// Its index: in the components as given, or row-major in the matrix.
        index: usize,
    },
    /// The norm is too far from 1 to be a rotation (see [`Rot::NORM_TOLERANCE`]).
    NotUnit {
        /// The norm found.
        norm: f64,
    },
    /// A matrix given to [`Rot::from_matrix`] is not a rotation matrix: too far from
    /// orthonormal (see [`Rot::ORTHONORMALITY_TOLERANCE`]), or of a determinant that is not
    /// positive (a reflection, or a singular matrix).
    NotRotation {
        /// Largest entry of `|MᵀM − I|`, 0 for an orthonormal matrix.
        orthonormality_error: f64,
        /// Determinant of `M`: +1 for a rotation, −1 for a reflection.
        determinant: f64,
    },
}

impl fmt::Display for QuatError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            QuatError::NonFinite { what, index } => write!(f, "non-finite {what} {index}"),
            QuatError::NotUnit { norm } => {
                write!(f, "quaternion norm {norm} is not close to 1")
            }
            QuatError::NotRotation {
                orthonormality_error,
                determinant,
            } => write!(
                f,
                "not a rotation matrix (|R'R - I| = {orthonormality_error:.2e}, at most {:.0e} \
                 allowed; det = {determinant:.3}, must be positive)",
                ORTHONORMALITY_TOLERANCE
            ),
        }
    }
}

/// See [`Rot::ORTHONORMALITY_TOLERANCE`].
const ORTHONORMALITY_TOLERANCE: f64 = 1e-3;

impl std::error::Error for QuatError {}

/// [`QuatError::NonFinite`] naming the first non-finite of `c`.
fn finite(c: &[f64; 4], what: &'static str) -> Result<(), QuatError> {
    match c.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(QuatError::NonFinite { what, index }),
        None => Ok(()),
    }
}

impl<To: Frame, From: Frame> Rot<To, From> {
    /// Largest accepted deviation of a quaternion's norm from 1 before normalizing. Loose
    /// enough for 7-digit text files, tight enough to catch a wrong column.
    pub const NORM_TOLERANCE: f64 = 1e-2;

    /// The identity rotation.
    pub fn identity() -> Self {
        Self::from_unit_quaternion(UnitQuaternion::identity())
    }

    /// Wraps a unit quaternion known to map `From` to `To`.
    pub const fn from_unit_quaternion(q: UnitQuaternion<f64>) -> Self {
        Self {
            q,
            frames: PhantomData,
        }
    }

    /// Largest accepted entry of `|MᵀM − I|` in [`Rot::from_matrix`].
    ///
    /// Chosen from the only matrices read from files so far, the Qualisys motion-capture
    /// rotations of the Tyrex benchmark (`RigidBodies.Rotations`, single-precision values):
    /// over the 24 `Nexus5_NoDist` runs (about 171 000 tracked frames) the largest error is
    /// 9.8e-8 (median 4.5e-8), so 1e-3 leaves four orders of magnitude for other exporters
    /// while still refusing a wrong column, a scaled matrix or a mangled entry.
    pub const ORTHONORMALITY_TOLERANCE: f64 = ORTHONORMALITY_TOLERANCE;

    /// The rotation of a rotation matrix mapping `From` to `To` (columns: the `From` axes in
    /// `To`).
    ///
    /// A matrix read from a file is orthonormal only to its precision: within
    /// [`Rot::ORTHONORMALITY_TOLERANCE`] (largest entry of `|MᵀM − I|`) it is accepted and the
    /// result is the *nearest* rotation (the orthonormal polar factor `U Vᵀ` of the SVD
    /// `M = U Σ Vᵀ`, nearest in the Frobenius norm, found by Newton's iteration), as a
    /// normalized unit quaternion.
    ///
    /// # Errors
    /// [`QuatError::NonFinite`] when an entry is NaN or infinite; [`QuatError::NotRotation`]
    /// (with the orthonormality error and the determinant) when `M` is further than the
    /// tolerance from orthonormal, e.g. a scaled rotation, or when its determinant is not
    /// positive: a reflection such as `diag(−1, 1, 1)` is orthonormal but not a rotation.
    ///
    /// ```
    /// use ridi_frames::nalgebra::Matrix3;
    /// use ridi_frames::{QuatError, WorldFromDevice};
    ///
    /// // A quarter turn about z, as a 7-digit text file would give it.
    /// let m = Matrix3::new(0.0, -1.0, 0.0, 1.0, 1e-7, 0.0, 0.0, 0.0, 1.0);
    /// let q = WorldFromDevice::from_matrix(&m)?;
    /// assert!((q.quaternion().norm() - 1.0).abs() < 1e-15);
    ///
    /// let reflection = Matrix3::from_diagonal(&[-1.0, 1.0, 1.0].into());
    /// assert!(matches!(
    ///     WorldFromDevice::from_matrix(&reflection),
    ///     Err(QuatError::NotRotation { .. })
    /// ));
    /// # Ok::<(), QuatError>(())
    /// ```
    pub fn from_matrix(m: &Matrix3<f64>) -> Result<Self, QuatError> {
        if let Some(index) = (0..9).find(|&i| !m[(i / 3, i % 3)].is_finite()) {
            return Err(QuatError::NonFinite {
                what: "matrix entry (row-major)",
                index,
            });
        }
        let orthonormality_error = (m.transpose() * m - Matrix3::identity()).abs().max();
        let determinant = m.determinant();
        // Written so that a NaN (from an overflow in a huge matrix) is refused too.
        if !(determinant > 0.0 && orthonormality_error <= ORTHONORMALITY_TOLERANCE) {
            return Err(QuatError::NotRotation {
                orthonormality_error,
                determinant,
            });
        }
        // The orthonormal polar factor by Newton's iteration X <- (X + X^-T) / 2, which
        // converges quadratically (det M > 0, so to a proper rotation): from an error of 1e-3
        // three steps reach machine precision. An SVD gives the same factor but tripled the time
        // of reading a motion-capture file, where every frame is a matrix.
        let mut x = *m;
        for _ in 0..8 {
            let Some(inverse) = x.try_inverse() else {
                break;
            };
            let next = (x + inverse.transpose()) * 0.5;
            let step = (next - x).abs().max();
            x = next;
            if step < 1e-15 {
                break;
            }
        }
        let nearest = Rotation3::from_matrix_unchecked(x);
        let q = UnitQuaternion::from_rotation_matrix(&nearest).into_inner();
        Ok(Self::from_unit_quaternion(UnitQuaternion::new_normalize(q)))
    }

    /// Rotation by `angle` radians about `axis` (given in either frame: it is the same).
    pub fn from_axis_angle(axis: &Unit<Vector3<f64>>, angle: f64) -> Self {
        Self::from_unit_quaternion(UnitQuaternion::from_axis_angle(axis, angle))
    }

    /// Rotation vector (axis times angle, radians).
    pub fn from_scaled_axis(v: Vector3<f64>) -> Self {
        Self::from_unit_quaternion(UnitQuaternion::from_scaled_axis(v))
    }

    /// From Hamilton components in `[w, x, y, z]` order, normalized after checking the norm.
    pub fn from_wxyz(c: [f64; 4]) -> Result<Self, QuatError> {
        finite(&c, "quaternion component (w, x, y, z)")?;
        Self::checked(Quaternion::new(c[0], c[1], c[2], c[3]))
    }

    /// From Hamilton components in `[x, y, z, w]` order (Android, Tango, ROS).
    pub fn from_xyzw(c: [f64; 4]) -> Result<Self, QuatError> {
        finite(&c, "quaternion component (x, y, z, w)")?;
        Self::checked(Quaternion::new(c[3], c[0], c[1], c[2]))
    }

    /// From Hamilton components in `[w, x, y, z]` order as [`Self::from_wxyz`], except that
    /// components already of unit norm to round-off (a norm within 4 machine epsilons of 1) are
    /// kept bit for bit:
    /// normalizing them again would move their last bits, so that a rotation written and read
    /// back, or rebuilt from its components, would differ from the original.
    pub fn from_wxyz_as_given(c: [f64; 4]) -> Result<Self, QuatError> {
        let checked = Self::from_wxyz(c)?;
        let q = Quaternion::new(c[0], c[1], c[2], c[3]);
        if (q.norm() - 1.0).abs() <= 4.0 * f64::EPSILON {
            Ok(Self::from_unit_quaternion(UnitQuaternion::new_unchecked(q)))
        } else {
            Ok(checked)
        }
    }

    /// `q`, finite, normalized after checking the norm.
    fn checked(q: Quaternion<f64>) -> Result<Self, QuatError> {
        let norm = q.norm();
        if (norm - 1.0).abs() > Self::NORM_TOLERANCE {
            return Err(QuatError::NotUnit { norm });
        }
        Ok(Self::from_unit_quaternion(UnitQuaternion::new_normalize(q)))
    }

    /// Components in `[w, x, y, z]` order.
    pub fn to_wxyz(&self) -> [f64; 4] {
        [self.q.w, self.q.i, self.q.j, self.q.k]
    }

    /// Components in `[x, y, z, w]` order.
    pub fn to_xyzw(&self) -> [f64; 4] {
        [self.q.i, self.q.j, self.q.k, self.q.w]
    }

    /// The underlying unit quaternion (frame tags dropped).
    pub const fn quaternion(&self) -> &UnitQuaternion<f64> {
        &self.q
    }

    /// The rotation matrix; `m * v_From = v_To`.
    pub fn matrix(&self) -> Matrix3<f64> {
        self.q.to_rotation_matrix().into_inner()
    }

    /// The inverse rotation.
    pub fn inverse(&self) -> Rot<From, To> {
        Rot::from_unit_quaternion(self.q.inverse())
    }

    /// Spherical linear interpolation (shortest path) between `self` (t = 0) and `other`.
    pub fn slerp(&self, other: &Self, t: f64) -> Self {
        // Quaternions q and -q are the same rotation; nalgebra's slerp needs them on one
        // hemisphere, and it panics on exact antipodes, which this sidesteps.
        let b = if self.q.coords.dot(&other.q.coords) < 0.0 {
            UnitQuaternion::new_unchecked(-other.q.into_inner())
        } else {
            other.q
        };
        // nalgebra divides by the sine of half the angle between the two: for rotations a few
        // microradians apart, its result strays from unit norm by up to 1e-9. Normalized again,
        // it is unit to round-off, as every other rotation is.
        let q = self.q.try_slerp(&b, t, 1e-12).unwrap_or(self.q);
        Self::from_unit_quaternion(UnitQuaternion::new_normalize(q.into_inner()))
    }

    /// Angle of the relative rotation between `self` and `other`, radians in [0, pi].
    pub fn angle_to(&self, other: &Self) -> f64 {
        self.q.angle_to(&other.q)
    }

    /// Drops the frame tags in favour of others. Only for edges where the frames are known from
    /// context (e.g. a ground-truth source whose world differs from the device's).
    pub const fn cast<To2: Frame, From2: Frame>(self) -> Rot<To2, From2> {
        Rot::from_unit_quaternion(self.q)
    }
}

impl<To: Frame, From: Frame> Clone for Rot<To, From> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<To: Frame, From: Frame> Copy for Rot<To, From> {}
impl<To: Frame, From: Frame> PartialEq for Rot<To, From> {
    fn eq(&self, other: &Self) -> bool {
        self.q == other.q
    }
}
impl<To: Frame, From: Frame> Default for Rot<To, From> {
    fn default() -> Self {
        Self::identity()
    }
}

impl<To: Frame, From: Frame> fmt::Debug for Rot<To, From> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [w, x, y, z] = self.to_wxyz();
        write!(
            f,
            "{}<-{}(w={w}, x={x}, y={y}, z={z})",
            To::NAME,
            From::NAME
        )
    }
}

impl<To: Frame, Mid: Frame, From: Frame> Mul<Rot<Mid, From>> for Rot<To, Mid> {
    type Output = Rot<To, From>;
    fn mul(self, rhs: Rot<Mid, From>) -> Rot<To, From> {
        Rot::from_unit_quaternion(self.q * rhs.q)
    }
}

impl<To: Frame, From: Frame> Mul<Vec3<From>> for Rot<To, From> {
    type Output = Vec3<To>;
    fn mul(self, rhs: Vec3<From>) -> Vec3<To> {
        Vec3::from_vector(self.q.transform_vector(rhs.vector()))
    }
}

impl<To: Frame, From: Frame> Mul<Vec3<From>> for &Rot<To, From> {
    type Output = Vec3<To>;
    fn mul(self, rhs: Vec3<From>) -> Vec3<To> {
        *self * rhs
    }
}

impl<To: Frame, From: Frame> Serialize for Rot<To, From> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.to_wxyz().serialize(s)
    }
}
impl<'de, To: Frame, From: Frame> Deserialize<'de> for Rot<To, From> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let c = <[f64; 4]>::deserialize(d)?;
        // Bit for bit when unit to round-off, so that a serde round trip changes nothing.
        Self::from_wxyz_as_given(c).map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn slerp_between_close_rotations_stays_unit() {
        use nalgebra::Vector3;
        let a = crate::WorldFromDevice::from_scaled_axis(Vector3::new(0.3, -1.2, 0.7));
        for gap in [1e-9, 1e-7, 1e-6, 1e-4] {
            let b = crate::WorldFromDevice::from_scaled_axis(Vector3::new(0.3 + gap, -1.2, 0.7));
            for t in [0.1, 0.5, 0.9] {
                let norm = a.slerp(&b, t).quaternion().norm();
                assert!(
                    (norm - 1.0).abs() <= 4.0 * f64::EPSILON,
                    "{gap} {t}: {norm}"
                );
            }
        }
    }

    #[test]
    fn unit_quaternions_are_kept_bit_for_bit_as_given() {
        let c = [0.5f64.sqrt(), 0.0, 0.0, 0.5f64.sqrt()];
        let r = crate::WorldFromDevice::from_wxyz_as_given(c).unwrap();
        assert_eq!(r.to_wxyz(), c);
        assert!(crate::WorldFromDevice::from_wxyz_as_given([2.0, 0.0, 0.0, 0.0]).is_err());
        let r = crate::WorldFromDevice::from_wxyz_as_given([1.001, 0.0, 0.0, 0.0]).unwrap();
        assert_eq!(r.to_wxyz(), [1.0, 0.0, 0.0, 0.0]);
    }

    use super::*;

    fn not_rotation(m: Matrix3<f64>) -> (f64, f64) {
        match WorldFromDevice::from_matrix(&m) {
            Err(QuatError::NotRotation {
                orthonormality_error,
                determinant,
            }) => (orthonormality_error, determinant),
            other => panic!("{m} gave {other:?}"),
        }
    }

    #[test]
    fn from_matrix_refuses_a_reflection() {
        // Orthonormal, so only the determinant tells it from a rotation.
        let (err, det) = not_rotation(Matrix3::from_diagonal(&Vector3::new(-1.0, 1.0, 1.0)));
        assert_eq!((err, det), (0.0, -1.0));
        // A rotation followed by a reflection, too.
        let q = WorldFromDevice::from_scaled_axis(Vector3::new(0.3, -1.2, 2.0));
        let (err, det) = not_rotation(-q.matrix());
        assert!(err < 1e-12 && (det + 1.0).abs() < 1e-12, "{err} {det}");
        let text = WorldFromDevice::from_matrix(&-q.matrix())
            .unwrap_err()
            .to_string();
        assert!(
            text.contains("not a rotation matrix") && text.contains("det = -1.000"),
            "{text}"
        );
    }

    #[test]
    fn from_matrix_refuses_scaled_and_singular_matrices() {
        // 2 I: MᵀM − I = 3 I (the unchecked conversion gave w = 1.32 here).
        let (err, det) = not_rotation(Matrix3::identity() * 2.0);
        assert_eq!((err, det), (3.0, 8.0));
        // Just outside the tolerance on the diagonal: (1 + d)² − 1 ≈ 2d.
        let d = 0.6 * Rot::<World, Device>::ORTHONORMALITY_TOLERANCE;
        let (err, _) = not_rotation(Matrix3::identity() * (1.0 + d));
        assert!(err > Rot::<World, Device>::ORTHONORMALITY_TOLERANCE);
        let (_, det) = not_rotation(Matrix3::zeros());
        assert_eq!(det, 0.0);
        // Overflow in MᵀM must not slip through as NaN.
        not_rotation(Matrix3::identity() * 1e200);
        let text = WorldFromDevice::from_matrix(&(Matrix3::identity() * 2.0))
            .unwrap_err()
            .to_string();
        assert!(
            text.contains("|R'R - I| = 3.00e0") && text.contains("at most 1e-3"),
            "{text}"
        );
    }

    #[test]
    fn from_matrix_refuses_non_finite_entries() {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut m = Matrix3::identity();
            m[(1, 2)] = bad;
            assert_eq!(
                WorldFromDevice::from_matrix(&m),
                Err(QuatError::NonFinite {
                    what: "matrix entry (row-major)",
                    index: 5
                }),
                "{bad}"
            );
        }
    }

    #[test]
    fn from_matrix_accepts_a_slightly_perturbed_rotation_as_a_unit_quaternion() {
        let q = WorldFromDevice::from_scaled_axis(Vector3::new(-0.4, 0.9, 2.5));
        let mut m = q.matrix();
        let noise = [1.0, -0.5, 0.25, 0.8, -1.0, 0.3, -0.7, 0.6, 0.9];
        for (v, n) in m.iter_mut().zip(noise) {
            *v += 1e-6 * n;
        }
        let r = WorldFromDevice::from_matrix(&m).unwrap();
        assert!((r.quaternion().norm() - 1.0).abs() < 1e-15);
        assert!(r.angle_to(&q) < 3e-6, "{}", r.angle_to(&q));
        // The nearest rotation: no farther from M than the rotation it was perturbed from.
        assert!((r.matrix() - m).norm() <= (q.matrix() - m).norm() + 1e-15);
        let back = r.matrix();
        assert!((back.transpose() * back - Matrix3::identity()).abs().max() < 1e-15);
        // An exact rotation comes back unchanged.
        let exact = WorldFromDevice::from_matrix(&q.matrix()).unwrap();
        assert!(exact.angle_to(&q) < 1e-12);
        assert_eq!(
            WorldFromDevice::from_matrix(&Matrix3::identity()).unwrap(),
            WorldFromDevice::identity()
        );
    }
}
