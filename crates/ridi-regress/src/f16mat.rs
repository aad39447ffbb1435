//! Half-precision sample storage for prediction.
//!
//! Evaluating a query streams every stored sample it needs from memory once; with tens of
//! thousands of 1200-value samples that is tens of MB, far beyond the caches, so the time per
//! query is set by bytes, not by arithmetic. Storing the samples as IEEE binary16 halves those
//! bytes (and the model file); values are widened to `f32` as they are read and all arithmetic
//! stays `f32` with `f64` sums. The squared norms are computed from the rounded values, so
//! `|a|² + |b|² - 2 a·b` is the distance to the rounded sample and cannot go inconsistent.

use half::f16;
use half::slice::HalfFloatSliceExt;
use rayon::prelude::*;
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::ser::{SerializeStruct, Serializer};
use serde::{Deserialize, Serialize};

use crate::error::RegressError;
use crate::kernel;
use ridi_features::FeatureMatrixRef;

/// Largest finite binary16 value: larger feature values cannot be stored.
pub(crate) const F16_MAX: f32 = 65504.0;

/// Row-major binary16 matrix (one sample per row).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct F16Matrix {
    data: Vec<f16>,
    dim: usize,
}

impl F16Matrix {
    /// Rounds the rows of `x` listed in `idx` (to nearest, ties to even).
    pub(crate) fn from_rows(x: FeatureMatrixRef<'_>, idx: &[usize]) -> Self {
        let dim = x.cols();
        let mut data = vec![f16::ZERO; idx.len() * dim];
        for (dst, &i) in data.chunks_exact_mut(dim).zip(idx) {
            dst.convert_from_f32_slice(x.row(i));
        }
        Self { data, dim }
    }

    pub(crate) fn rows(&self) -> usize {
        self.data.len().checked_div(self.dim).unwrap_or(0)
    }

    pub(crate) fn dim(&self) -> usize {
        self.dim
    }

    /// Raw bits of row `i` (to match stored rows against training rows).
    pub(crate) fn row_bits(&self, i: usize) -> &[u16] {
        self.data[i * self.dim..(i + 1) * self.dim].reinterpret_cast()
    }

    /// Widens rows `r0..r1` into `out` (resized to fit).
    pub(crate) fn rows_f32(&self, r0: usize, r1: usize, out: &mut Vec<f32>) {
        out.resize((r1 - r0) * self.dim, 0.0);
        self.data[r0 * self.dim..r1 * self.dim].convert_to_f32_slice(out);
    }

    /// Squared norm of every (rounded) row, summed in the same order as [`kernel::dot`] so
    /// that a row's norm and its dot product with itself agree.
    pub(crate) fn sq_norms(&self) -> Vec<f32> {
        (0..self.rows())
            .into_par_iter()
            .with_min_len(64)
            .map_init(Vec::new, |buf, i| {
                self.rows_f32(i, i + 1, buf);
                kernel::dot(buf, buf)
            })
            .collect()
    }

    /// Rejects values that are not finite (the checksum does not catch a well-formed but
    /// wrong payload).
    pub(crate) fn check(&self) -> Result<(), RegressError> {
        match self.data.iter().position(|v| !v.is_finite()) {
            Some(pos) => Err(RegressError::Decode(format!(
                "non-finite stored sample value at row {}, column {}",
                pos / self.dim,
                pos % self.dim
            ))),
            None => Ok(()),
        }
    }

    /// `out[j] = q · row(r0 + j)` for `j < out.len()`: one pass over the rows (the
    /// single-query path, where a GEMM's blocking buys nothing and costs set-up).
    pub(crate) fn dots(&self, q: &[f32], r0: usize, out: &mut [f32]) {
        assert_eq!(q.len(), self.dim, "query length");
        let rows = &self.data[r0 * self.dim..(r0 + out.len()) * self.dim];
        #[cfg(target_arch = "x86_64")]
        if crate::simd::avx2_f16c() {
            // SAFETY: the CPU supports AVX2, FMA and F16C (checked at run time); `rows`
            // holds `out.len()` rows of `q.len()` values.
            unsafe { crate::simd::f16_dots_avx2(q, rows.reinterpret_cast(), out) };
            return;
        }
        dots_generic(q, rows, out);
    }
}

/// Portable [`F16Matrix::dots`]: widen a row, then [`kernel::dot`].
fn dots_generic(q: &[f32], rows: &[f16], out: &mut [f32]) {
    let mut buf = vec![0.0f32; q.len()];
    for (o, r) in out.iter_mut().zip(rows.chunks_exact(q.len())) {
        r.convert_to_f32_slice(&mut buf);
        *o = kernel::dot(q, &buf);
    }
}

/// Byte payload of the samples: little-endian binary16, written as one byte string (a
/// sequence of `u16` would cost bincode's variable-length integers, 3 bytes each).
impl Serialize for F16Matrix {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let bytes: Vec<u8> = self
            .data
            .iter()
            .flat_map(|v| v.to_bits().to_le_bytes())
            .collect();
        let mut st = s.serialize_struct("F16Matrix", 2)?;
        st.serialize_field("dim", &self.dim)?;
        st.serialize_field("data", &Bytes(bytes))?;
        st.end()
    }
}

impl<'de> Deserialize<'de> for F16Matrix {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        struct Repr {
            dim: usize,
            data: Bytes,
        }
        let r = Repr::deserialize(d)?;
        let b = r.data.0;
        if r.dim == 0 || b.len() % 2 != 0 || !(b.len() / 2).is_multiple_of(r.dim) {
            return Err(de::Error::custom(format!(
                "{} sample bytes do not form rows of {} half floats",
                b.len(),
                r.dim
            )));
        }
        let data = b
            .chunks_exact(2)
            .map(|c| f16::from_bits(u16::from_le_bytes([c[0], c[1]])))
            .collect();
        Ok(Self { data, dim: r.dim })
    }
}

struct Bytes(Vec<u8>);

impl Serialize for Bytes {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_bytes(&self.0)
    }
}

impl<'de> Deserialize<'de> for Bytes {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Bytes;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a byte string")
            }
            fn visit_bytes<E: de::Error>(self, v: &[u8]) -> Result<Bytes, E> {
                Ok(Bytes(v.to_vec()))
            }
            fn visit_byte_buf<E: de::Error>(self, v: Vec<u8>) -> Result<Bytes, E> {
                Ok(Bytes(v))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Bytes, A::Error> {
                let mut v = Vec::with_capacity(seq.size_hint().unwrap_or(0).min(1 << 24));
                while let Some(b) = seq.next_element()? {
                    v.push(b);
                }
                Ok(Bytes(v))
            }
        }
        d.deserialize_byte_buf(V)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::tests::data;
    use crate::matrix::View as _;

    #[test]
    fn dots_match_widened_rows_for_any_shape() {
        // Dimensions with and without a tail after the 16-value blocks; row counts with and
        // without a remainder after the 4-row blocks.
        for (n, d) in [(11, 1200), (6, 37), (4, 16), (3, 5)] {
            let x = data(n, d);
            let idx: Vec<usize> = (0..n).rev().collect();
            let m = F16Matrix::from_rows(x.view(), &idx);
            let q: Vec<f32> = (0..d).map(|k| (k as f32 * 0.11).cos()).collect();
            let mut fast = vec![0.0; n - 1];
            m.dots(&q, 1, &mut fast);
            let mut portable = vec![0.0; n - 1];
            dots_generic(&q, &m.data[d..], &mut portable);
            let kernels = [&fast, &portable];
            let mut row = Vec::new();
            for j in 0..n - 1 {
                m.rows_f32(j + 1, j + 2, &mut row);
                let exact: f64 = q.iter().zip(&row).map(|(a, b)| *a as f64 * *b as f64).sum();
                let scale: f64 = q.iter().zip(&row).map(|(a, b)| (a * b).abs() as f64).sum();
                for v in kernels.iter().map(|k| k[j]) {
                    assert!(
                        (v as f64 - exact).abs() <= 1e-6 * scale,
                        "n={n} d={d} row {j}: {v} vs {exact}"
                    );
                }
            }
            // A row's dot product does not depend on the block it falls in.
            let mut single = [0.0];
            m.dots(&q, 2, &mut single);
            assert_eq!(single[0], fast[1]);
        }
    }

    #[test]
    fn rounding_error_and_norms() {
        let x = data(20, 64);
        let m = F16Matrix::from_rows(x.view(), &(0..20).collect::<Vec<_>>());
        let mut w = Vec::new();
        m.rows_f32(0, 20, &mut w);
        for (a, b) in x.as_slice().iter().zip(&w) {
            // Round to nearest: half a unit in the last of 11 significant bits, or half the
            // subnormal spacing 2^-24 near zero.
            let bound = (a.abs() * 0.5f32.powi(11)).max(0.5f32.powi(25));
            assert!((a - b).abs() <= bound, "{a} -> {b}");
        }
        let norms = m.sq_norms();
        for (i, n) in norms.iter().enumerate() {
            let r = &w[i * 64..(i + 1) * 64];
            assert_eq!(*n, kernel::dot(r, r));
        }
    }

    #[test]
    fn serializes_two_bytes_per_value_and_round_trips() {
        let x = data(9, 50);
        let m = F16Matrix::from_rows(x.view(), &[8, 0, 3]);
        let cfg = bincode::config::standard();
        let bytes = bincode::serde::encode_to_vec(&m, cfg).unwrap();
        assert!(bytes.len() <= 3 * 50 * 2 + 8, "{} bytes", bytes.len());
        let (back, _): (F16Matrix, usize) = bincode::serde::decode_from_slice(&bytes, cfg).unwrap();
        assert_eq!(back, m);
        assert_eq!(back.row_bits(1), m.row_bits(1));
        // A byte count that is not whole rows is rejected.
        let odd = F16Matrix {
            data: m.data[..49].to_vec(),
            dim: 50,
        };
        let bytes = bincode::serde::encode_to_vec(&odd, cfg).unwrap();
        assert!(bincode::serde::decode_from_slice::<F16Matrix, _>(&bytes, cfg).is_err());
    }
}
