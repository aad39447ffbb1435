//! Frame-tagged horizontal 2-vectors: what RIDI regresses (velocity in S) and plots (positions
//! in W) without the vertical.

use std::fmt;
use std::marker::PhantomData;
use std::ops::{Add, AddAssign, Div, Index, Mul, Neg, Sub, SubAssign};

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::frame::{Frame, Stabilized, World};
use crate::vector::{StabVec, WorldVec};

/// The two components of a vector in frame `F` perpendicular to the frame's up axis: `[x, z]`
/// in S, whose up axis is +y, and `[x, y]` in W, whose up axis is +z.
///
/// The frame is a type parameter, so that a world velocity cannot be passed where a velocity
/// in S is expected. Serialized as a plain `[a, b]` array.
///
/// ```
/// use ridi_frames::{StabHorizontal, StabVec};
///
/// let v = StabVec::new(1.0, 0.2, -0.5);
/// let h: StabHorizontal = v.horizontal();
/// assert_eq!(h.to_array(), [1.0, -0.5]);
/// assert_eq!(h.with_up(0.2), v);
/// ```
#[repr(transparent)]
pub struct Horizontal<F: Frame> {
    h: [f64; 2],
    frame: PhantomData<F>,
}

/// A horizontal vector in S: `[S-x, S-z]` (a velocity target of RIDI).
pub type StabHorizontal = Horizontal<Stabilized>;
/// A horizontal vector in W: `[W-x, W-y]` (a position or velocity on the floor plan).
pub type WorldHorizontal = Horizontal<World>;

impl<F: Frame> Horizontal<F> {
    /// The zero vector.
    pub const ZERO: Self = Self::new(0.0, 0.0);

    /// A horizontal vector from its two components in frame `F` (S: x, z; W: x, y).
    pub const fn new(a: f64, b: f64) -> Self {
        Self {
            h: [a, b],
            frame: PhantomData,
        }
    }

    /// A horizontal vector from its two components in frame `F`.
    pub const fn from_array(h: [f64; 2]) -> Self {
        Self::new(h[0], h[1])
    }

    /// The two components (S: x, z; W: x, y).
    pub const fn to_array(self) -> [f64; 2] {
        self.h
    }

    /// Euclidean norm (the horizontal speed of a velocity).
    pub fn norm(self) -> f64 {
        self.h[0].hypot(self.h[1])
    }

    /// `true` when both components are finite.
    pub fn is_finite(self) -> bool {
        self.h.iter().all(|c| c.is_finite())
    }
}

impl StabVec {
    /// The horizontal part `[x, z]` (S's up axis is +y).
    pub fn horizontal(self) -> StabHorizontal {
        StabHorizontal::new(self.x(), self.z())
    }
}

impl StabHorizontal {
    /// The 3-vector with this horizontal part and `up` along S-up (+y).
    pub const fn with_up(self, up: f64) -> StabVec {
        StabVec::new(self.h[0], up, self.h[1])
    }
}

impl WorldVec {
    /// The horizontal part `[x, y]` (W's up axis is +z).
    pub fn horizontal(self) -> WorldHorizontal {
        WorldHorizontal::new(self.x(), self.y())
    }
}

impl WorldHorizontal {
    /// The 3-vector with this horizontal part and `up` along W-up (+z).
    pub const fn with_up(self, up: f64) -> WorldVec {
        WorldVec::new(self.h[0], self.h[1], up)
    }
}

impl<F: Frame> Clone for Horizontal<F> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<F: Frame> Copy for Horizontal<F> {}
impl<F: Frame> Default for Horizontal<F> {
    fn default() -> Self {
        Self::ZERO
    }
}
impl<F: Frame> PartialEq for Horizontal<F> {
    fn eq(&self, other: &Self) -> bool {
        self.h == other.h
    }
}

impl<F: Frame> fmt::Debug for Horizontal<F> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}h[{}, {}]", F::NAME, self.h[0], self.h[1])
    }
}

/// Component `i` of [`Horizontal::to_array`] (S: 0 is x, 1 is z; W: 0 is x, 1 is y).
///
/// # Panics
/// If `i > 1`, as an array would.
impl<F: Frame> Index<usize> for Horizontal<F> {
    type Output = f64;
    fn index(&self, i: usize) -> &f64 {
        &self.h[i]
    }
}

impl<F: Frame> Add for Horizontal<F> {
    type Output = Self;
    fn add(self, rhs: Self) -> Self {
        Self::new(self.h[0] + rhs.h[0], self.h[1] + rhs.h[1])
    }
}
impl<F: Frame> AddAssign for Horizontal<F> {
    fn add_assign(&mut self, rhs: Self) {
        *self = *self + rhs;
    }
}
impl<F: Frame> Sub for Horizontal<F> {
    type Output = Self;
    fn sub(self, rhs: Self) -> Self {
        Self::new(self.h[0] - rhs.h[0], self.h[1] - rhs.h[1])
    }
}
impl<F: Frame> SubAssign for Horizontal<F> {
    fn sub_assign(&mut self, rhs: Self) {
        *self = *self - rhs;
    }
}
impl<F: Frame> Neg for Horizontal<F> {
    type Output = Self;
    fn neg(self) -> Self {
        Self::new(-self.h[0], -self.h[1])
    }
}
impl<F: Frame> Mul<f64> for Horizontal<F> {
    type Output = Self;
    fn mul(self, rhs: f64) -> Self {
        Self::new(self.h[0] * rhs, self.h[1] * rhs)
    }
}
impl<F: Frame> Mul<Horizontal<F>> for f64 {
    type Output = Horizontal<F>;
    fn mul(self, rhs: Horizontal<F>) -> Horizontal<F> {
        rhs * self
    }
}
impl<F: Frame> Div<f64> for Horizontal<F> {
    type Output = Self;
    fn div(self, rhs: f64) -> Self {
        Self::new(self.h[0] / rhs, self.h[1] / rhs)
    }
}

impl<F: Frame> Serialize for Horizontal<F> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.h.serialize(s)
    }
}
impl<'de, F: Frame> Deserialize<'de> for Horizontal<F> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        <[f64; 2]>::deserialize(d).map(Self::from_array)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn horizontal_parts_drop_each_frames_up_axis() {
        let s = StabVec::new(1.0, 2.0, 3.0);
        assert_eq!(s.horizontal(), StabHorizontal::new(1.0, 3.0));
        assert_eq!(s.horizontal().with_up(2.0), s);
        let w = WorldVec::new(1.0, 2.0, 3.0);
        assert_eq!(w.horizontal(), WorldHorizontal::new(1.0, 2.0));
        assert_eq!(w.horizontal().with_up(3.0), w);
    }

    #[test]
    fn arithmetic_and_norm() {
        let a = StabHorizontal::new(3.0, 4.0);
        assert_eq!(a.norm(), 5.0);
        assert_eq!((a[0], a[1]), (3.0, 4.0));
        assert_eq!((a + a - a * 0.5).to_array(), [4.5, 6.0]);
        assert_eq!((-a / 2.0).to_array(), [-1.5, -2.0]);
        assert_eq!(2.0 * a, a + a);
        assert!(!StabHorizontal::new(f64::NAN, 0.0).is_finite());
        assert_eq!(format!("{a:?}"), format!("{}h[3, 4]", Stabilized::NAME));
    }
}
