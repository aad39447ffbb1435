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

/// Why a quaternion was rejected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum QuatError {
    /// A component is NaN or infinite.
    NotFinite,
    /// The norm is too far from 1 to be a rotation (see [`Rot::NORM_TOLERANCE`]).
    NotUnit {
        /// The norm found.
        norm: f64,
    },
}

impl fmt::Display for QuatError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            QuatError::NotFinite => write!(f, "quaternion has a non-finite component"),
            QuatError::NotUnit { norm } => {
                write!(f, "quaternion norm {norm} is not close to 1")
            }
        }
    }
}

impl std::error::Error for QuatError {}

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

    /// Wraps a rotation matrix mapping `From` to `To` (columns: the `From` axes in `To`).
    pub fn from_matrix(m: &Matrix3<f64>) -> Self {
        Self::from_unit_quaternion(UnitQuaternion::from_rotation_matrix(
            &Rotation3::from_matrix_unchecked(*m),
        ))
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
        Self::checked(Quaternion::new(c[0], c[1], c[2], c[3]))
    }

    /// From Hamilton components in `[x, y, z, w]` order (Android, Tango, ROS).
    pub fn from_xyzw(c: [f64; 4]) -> Result<Self, QuatError> {
        Self::checked(Quaternion::new(c[3], c[0], c[1], c[2]))
    }

    fn checked(q: Quaternion<f64>) -> Result<Self, QuatError> {
        if !q.coords.iter().all(|c| c.is_finite()) {
            return Err(QuatError::NotFinite);
        }
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
        Self::from_unit_quaternion(self.q.try_slerp(&b, t, 1e-12).unwrap_or(self.q))
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
        Self::from_wxyz(c).map_err(serde::de::Error::custom)
    }
}
