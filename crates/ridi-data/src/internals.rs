//! What the fuzz targets, this crate's tests and its benches reach beyond the public API,
//! behind the feature `internals` (off by default; the crate's dev-dependency on itself turns
//! it on for its own tests and benches, `fuzz/Cargo.toml` for the fuzz targets). Not a
//! supported API: it follows the internals it wraps.

use std::path::Path;

use ridi_frames::{Frame, Vec3};

use crate::ListEntry;
use crate::error::Result;

pub use crate::hdf5::{Hdf5Array, Hdf5File};
pub use crate::mat::{
    CellArray, CharArray, MAX_DEPTH, MatClass, MatFile, MatValue, Numeric, StructArray,
};

/// The entries of the list file content `bytes`, as [`ListEntry::read`] parses a file; `path`
/// is the list file (errors name it, relative entries are resolved against its folder).
pub fn parse_list(bytes: &[u8], path: &Path) -> Result<Vec<ListEntry>> {
    crate::list::parse_list(bytes, path)
}

/// Linear interpolation of `src`, sampled at `src_t`, at the times `dst_t`, as the readers
/// resample vectors.
pub fn interpolate_vec3<F: Frame>(src_t: &[f64], src: &[Vec3<F>], dst_t: &[f64]) -> Vec<Vec3<F>> {
    crate::resample::interpolate_vec3(src_t, src, dst_t)
}
