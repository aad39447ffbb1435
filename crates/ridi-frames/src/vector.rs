//! Frame-tagged 3-vectors.

use std::fmt;
use std::marker::PhantomData;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub, SubAssign};

use nalgebra::Vector3;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::frame::{Device, Frame, Stabilized, World};

/// A 3-vector expressed in frame `F`.
///
/// The frame is a type parameter: rotate it with a [`Rot`](crate::Rot) to change frames.
/// Serialized as a plain `[x, y, z]` array.
#[repr(transparent)]
pub struct Vec3<F: Frame> {
    v: Vector3<f64>,
    frame: PhantomData<F>,
}

/// A vector in the world frame W.
pub type WorldVec = Vec3<World>;
/// A vector in the device frame I.
pub type DeviceVec = Vec3<Device>;
/// A vector in the stabilized-IMU frame S.
pub type StabVec = Vec3<Stabilized>;

impl<F: Frame> Vec3<F> {
    /// The zero vector.
    pub const ZERO: Self = Self::new(0.0, 0.0, 0.0);

    /// A vector from its components in frame `F`.
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Self {
            v: Vector3::new(x, y, z),
            frame: PhantomData,
        }
    }

    /// Wraps an nalgebra vector whose components are known to be in frame `F`.
    pub const fn from_vector(v: Vector3<f64>) -> Self {
        Self {
            v,
            frame: PhantomData,
        }
    }

    /// A vector from `[x, y, z]`.
    pub const fn from_array(a: [f64; 3]) -> Self {
        Self::new(a[0], a[1], a[2])
    }

    /// The components as `[x, y, z]`.
    pub fn to_array(self) -> [f64; 3] {
        [self.v.x, self.v.y, self.v.z]
    }

    /// The underlying nalgebra vector (frame tag dropped).
    pub const fn vector(&self) -> &Vector3<f64> {
        &self.v
    }

    /// x component.
    pub fn x(self) -> f64 {
        self.v.x
    }
    /// y component.
    pub fn y(self) -> f64 {
        self.v.y
    }
    /// z component.
    pub fn z(self) -> f64 {
        self.v.z
    }

    /// Euclidean norm.
    pub fn norm(self) -> f64 {
        self.v.norm()
    }

    /// Dot product with a vector of the same frame.
    pub fn dot(self, other: Self) -> f64 {
        self.v.dot(&other.v)
    }

    /// Cross product with a vector of the same frame.
    pub fn cross(self, other: Self) -> Self {
        Self::from_vector(self.v.cross(&other.v))
    }

    /// `true` when every component is finite.
    pub fn is_finite(self) -> bool {
        self.v.iter().all(|c| c.is_finite())
    }

    /// Linear interpolation `self + t (other - self)`.
    pub fn lerp(self, other: Self, t: f64) -> Self {
        Self::from_vector(self.v.lerp(&other.v, t))
    }
}

impl<F: Frame> Clone for Vec3<F> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<F: Frame> Copy for Vec3<F> {}
impl<F: Frame> Default for Vec3<F> {
    fn default() -> Self {
        Self::ZERO
    }
}
impl<F: Frame> PartialEq for Vec3<F> {
    fn eq(&self, other: &Self) -> bool {
        self.v == other.v
    }
}

impl<F: Frame> fmt::Debug for Vec3<F> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}[{}, {}, {}]", F::NAME, self.v.x, self.v.y, self.v.z)
    }
}

impl<F: Frame> Add for Vec3<F> {
    type Output = Self;
    fn add(self, rhs: Self) -> Self {
        Self::from_vector(self.v + rhs.v)
    }
}
impl<F: Frame> AddAssign for Vec3<F> {
    fn add_assign(&mut self, rhs: Self) {
        self.v += rhs.v;
    }
}
impl<F: Frame> Sub for Vec3<F> {
    type Output = Self;
    fn sub(self, rhs: Self) -> Self {
        Self::from_vector(self.v - rhs.v)
    }
}
impl<F: Frame> SubAssign for Vec3<F> {
    fn sub_assign(&mut self, rhs: Self) {
        self.v -= rhs.v;
    }
}
impl<F: Frame> Neg for Vec3<F> {
    type Output = Self;
    fn neg(self) -> Self {
        Self::from_vector(-self.v)
    }
}
impl<F: Frame> Mul<f64> for Vec3<F> {
    type Output = Self;
    fn mul(self, rhs: f64) -> Self {
        Self::from_vector(self.v * rhs)
    }
}
impl<F: Frame> Mul<Vec3<F>> for f64 {
    type Output = Vec3<F>;
    fn mul(self, rhs: Vec3<F>) -> Vec3<F> {
        rhs * self
    }
}
impl<F: Frame> Div<f64> for Vec3<F> {
    type Output = Self;
    fn div(self, rhs: f64) -> Self {
        Self::from_vector(self.v / rhs)
    }
}

impl<F: Frame> Serialize for Vec3<F> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.to_array().serialize(s)
    }
}
impl<'de, F: Frame> Deserialize<'de> for Vec3<F> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        <[f64; 3]>::deserialize(d).map(Self::from_array)
    }
}
