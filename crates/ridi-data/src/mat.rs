//! A reader for Level 5 MAT-files (MATLAB 5 to 7.x, not the HDF5-based 7.3), as written by
//! MATLAB, scipy and Qualisys Track Manager ("QTM ... Level 5 MAT-file").
//!
//! # Why a reader of our own
//! The `matrw` crate (0.1.4) was tried first: it rejects any header whose text does not start
//! with `MATLAB 5.0 MAT-file`, which QTM files do not, and with that patched it panics
//! (`unimplemented!`) on the QTM variable instead of returning an error. This reader covers the
//! subset that data sets use and never panics on bad input.
//!
//! # Layout
//! A 128-byte header (116 bytes of text, a subsystem offset, version `0x0100` and the endian
//! indicator `IM`/`MI`), then data elements: an 8-byte tag (type, byte count) and the data
//! padded to 8 bytes, or the 4-byte "small element" form for up to 4 bytes of data. Variables
//! are `miMATRIX` elements, optionally wrapped in `miCOMPRESSED` (one zlib stream each). A
//! `miMATRIX` holds array flags (class, complex, logical), dimensions, a name, then per class:
//! real (and imaginary) data for numeric classes, characters for `char`, one `miMATRIX` per
//! element for cells, and field names plus one `miMATRIX` per element and field for structs.
//! Arrays are column-major: element `(i, j, k)` of an `[a, b, c]` array is at
//! `i + a * (j + b * k)`.
//!
//! # What is supported
//! Numeric classes (double, single, 8- to 64-bit integers; the stored type may be narrower than
//! the class, as MATLAB does when saving) converted to `f64` (64-bit integers above 2^53 lose
//! precision), complex parts, logical arrays (as numeric 0/1), char arrays (UTF-8, UTF-16,
//! UTF-32, 8-bit), cells, structs and objects (read as structs with a class name). Sparse
//! arrays, function handles and opaque classes are skipped and show up as
//! [`MatValue::Unsupported`].
//!
//! # Robustness
//! Every size read from the file is checked against the bytes that actually remain before
//! anything is allocated, nesting is limited to [`MAX_DEPTH`] levels, and decompressed data
//! are bounded by the size the compressed element declares. Truncated or corrupt input gives a
//! [`DataError`] that names the file, the variable path (e.g. `Take1.RigidBodies.Positions`) and
//! the byte offset.
//!
//! Internal to the crate (the Tyrex reader's): its items are `pub` only so that the
//! `internals` feature can hand them to the fuzz targets, tests and benches; not a supported API.

// Without `internals` nothing re-exports the `pub` items (crate-private in effect), and the
// Tyrex reader uses part of the value API that the tests check whole.
#![cfg_attr(not(feature = "internals"), allow(unreachable_pub, dead_code))]

use std::fmt;
use std::io::Read;
use std::path::{Path, PathBuf};

use flate2::read::ZlibDecoder;

use crate::error::{DataError, Location, Result};

/// Deepest nesting of cells and structs accepted; a corrupt file could otherwise nest deep
/// enough to overflow the stack.
pub const MAX_DEPTH: usize = 32;

const HEADER_LEN: usize = 128;

const MI_INT8: u32 = 1;
const MI_UINT8: u32 = 2;
const MI_INT16: u32 = 3;
const MI_UINT16: u32 = 4;
const MI_INT32: u32 = 5;
const MI_UINT32: u32 = 6;
const MI_SINGLE: u32 = 7;
const MI_DOUBLE: u32 = 9;
const MI_INT64: u32 = 12;
const MI_UINT64: u32 = 13;
const MI_MATRIX: u32 = 14;
const MI_COMPRESSED: u32 = 15;
const MI_UTF8: u32 = 16;
const MI_UTF16: u32 = 17;
const MI_UTF32: u32 = 18;

/// MATLAB array class, from the array flags of a `miMATRIX` element.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MatClass {
    /// Cell array.
    Cell,
    /// Struct array.
    Struct,
    /// Object (struct with a class name).
    Object,
    /// Character array.
    Char,
    /// Sparse array (not decoded).
    Sparse,
    /// 64-bit float.
    Double,
    /// 32-bit float.
    Single,
    /// Signed 8-bit integer.
    Int8,
    /// Unsigned 8-bit integer.
    UInt8,
    /// Signed 16-bit integer.
    Int16,
    /// Unsigned 16-bit integer.
    UInt16,
    /// Signed 32-bit integer.
    Int32,
    /// Unsigned 32-bit integer.
    UInt32,
    /// Signed 64-bit integer.
    Int64,
    /// Unsigned 64-bit integer.
    UInt64,
    /// Function handle (not decoded).
    Function,
    /// Opaque class, e.g. MATLAB `string` or `table` (not decoded).
    Opaque,
    /// A class code this reader does not know.
    Unknown(u8),
}

impl MatClass {
    fn from_code(code: u8) -> Self {
        match code {
            1 => MatClass::Cell,
            2 => MatClass::Struct,
            3 => MatClass::Object,
            4 => MatClass::Char,
            5 => MatClass::Sparse,
            6 => MatClass::Double,
            7 => MatClass::Single,
            8 => MatClass::Int8,
            9 => MatClass::UInt8,
            10 => MatClass::Int16,
            11 => MatClass::UInt16,
            12 => MatClass::Int32,
            13 => MatClass::UInt32,
            14 => MatClass::Int64,
            15 => MatClass::UInt64,
            16 => MatClass::Function,
            17 => MatClass::Opaque,
            c => MatClass::Unknown(c),
        }
    }

    fn is_numeric(self) -> bool {
        matches!(
            self,
            MatClass::Double
                | MatClass::Single
                | MatClass::Int8
                | MatClass::UInt8
                | MatClass::Int16
                | MatClass::UInt16
                | MatClass::Int32
                | MatClass::UInt32
                | MatClass::Int64
                | MatClass::UInt64
        )
    }
}

impl fmt::Display for MatClass {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MatClass::Unknown(c) => write!(f, "unknown class {c}"),
            other => write!(f, "{}", format!("{other:?}").to_lowercase()),
        }
    }
}

/// A numeric (or logical) array, converted to `f64`, column-major.
#[derive(Debug, Clone, PartialEq)]
pub struct Numeric {
    /// Dimensions (at least two in files written by MATLAB).
    pub dims: Vec<usize>,
    /// Class the array had in MATLAB.
    pub class: MatClass,
    /// Whether MATLAB flagged the array as logical.
    pub logical: bool,
    /// Real parts, column-major, `dims.iter().product()` values.
    pub real: Vec<f64>,
    /// Imaginary parts of a complex array.
    pub imag: Option<Vec<f64>>,
}

impl Numeric {
    /// Number of elements.
    pub fn len(&self) -> usize {
        self.real.len()
    }

    /// Whether the array has no elements.
    pub fn is_empty(&self) -> bool {
        self.real.is_empty()
    }

    /// Column-major linear index of `index` (missing trailing subscripts count as 0), or `None`
    /// when out of bounds.
    pub fn linear_index(&self, index: &[usize]) -> Option<usize> {
        column_major(&self.dims, index)
    }

    /// The real part at `index` (see [`Numeric::linear_index`]).
    pub fn get(&self, index: &[usize]) -> Option<f64> {
        self.linear_index(index)
            .and_then(|i| self.real.get(i).copied())
    }

    /// The value of a one-element array.
    pub fn scalar(&self) -> Option<f64> {
        match self.real.as_slice() {
            [v] => Some(*v),
            _ => None,
        }
    }
}

/// A character array. Multi-row arrays are joined row by row with `\n`.
#[derive(Debug, Clone, PartialEq)]
pub struct CharArray {
    /// Dimensions.
    pub dims: Vec<usize>,
    /// The text, rows separated by `\n`.
    pub text: String,
}

/// A struct (or object) array: for each element, one value per field.
#[derive(Debug, Clone, PartialEq)]
pub struct StructArray {
    /// Dimensions.
    pub dims: Vec<usize>,
    /// Class name of an object; `None` for a plain struct.
    pub class_name: Option<String>,
    /// Field names in file order.
    pub fields: Vec<String>,
    /// Values, element after element (column-major), each with one value per field.
    pub values: Vec<MatValue>,
}

impl StructArray {
    /// Number of elements.
    pub fn len(&self) -> usize {
        if self.fields.is_empty() {
            // Without fields there are no values to count; saturate rather than overflow on
            // dimensions built by hand.
            self.dims.iter().fold(1usize, |a, &d| a.saturating_mul(d))
        } else {
            self.values.len() / self.fields.len()
        }
    }

    /// Whether the array has no elements.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Field `name` of element `element` (column-major linear index).
    pub fn field(&self, element: usize, name: &str) -> Option<&MatValue> {
        let f = self.fields.iter().position(|n| n == name)?;
        self.values.get(element.checked_mul(self.fields.len())? + f)
    }
}

/// A cell array.
#[derive(Debug, Clone, PartialEq)]
pub struct CellArray {
    /// Dimensions.
    pub dims: Vec<usize>,
    /// Cells, column-major.
    pub items: Vec<MatValue>,
}

/// A variable, struct field or cell of a MAT-file.
#[derive(Debug, Clone, PartialEq)]
pub enum MatValue {
    /// Numeric or logical array.
    Numeric(Numeric),
    /// Character array.
    Char(CharArray),
    /// Struct or object array.
    Struct(StructArray),
    /// Cell array.
    Cell(CellArray),
    /// A class this reader skips (sparse, function handle, opaque, unknown).
    Unsupported {
        /// The class.
        class: MatClass,
        /// Dimensions.
        dims: Vec<usize>,
    },
}

impl MatValue {
    /// Dimensions.
    pub fn dims(&self) -> &[usize] {
        match self {
            MatValue::Numeric(n) => &n.dims,
            MatValue::Char(c) => &c.dims,
            MatValue::Struct(s) => &s.dims,
            MatValue::Cell(c) => &c.dims,
            MatValue::Unsupported { dims, .. } => dims,
        }
    }

    /// What kind of value this is, for messages.
    pub fn kind(&self) -> String {
        match self {
            MatValue::Numeric(n) => n.class.to_string(),
            MatValue::Char(_) => "char".into(),
            MatValue::Struct(s) => match &s.class_name {
                Some(c) => format!("object of class {c}"),
                None => "struct".into(),
            },
            MatValue::Cell(_) => "cell".into(),
            MatValue::Unsupported { class, .. } => format!("{class} (not decoded)"),
        }
    }

    /// The numeric array, if this is one.
    pub fn as_numeric(&self) -> Option<&Numeric> {
        match self {
            MatValue::Numeric(n) => Some(n),
            _ => None,
        }
    }

    /// The struct array, if this is one.
    pub fn as_struct(&self) -> Option<&StructArray> {
        match self {
            MatValue::Struct(s) => Some(s),
            _ => None,
        }
    }

    /// The cell array, if this is one.
    pub fn as_cell(&self) -> Option<&CellArray> {
        match self {
            MatValue::Cell(c) => Some(c),
            _ => None,
        }
    }

    /// The text of a char array.
    pub fn as_str(&self) -> Option<&str> {
        match self {
            MatValue::Char(c) => Some(&c.text),
            _ => None,
        }
    }

    /// The value of a one-element numeric array.
    pub fn scalar(&self) -> Option<f64> {
        self.as_numeric().and_then(Numeric::scalar)
    }

    /// Field `name` of a one-element struct.
    pub fn field(&self, name: &str) -> Option<&MatValue> {
        match self {
            MatValue::Struct(s) if s.len() == 1 => s.field(0, name),
            _ => None,
        }
    }

    /// The value at a dot-separated path of fields of one-element structs, e.g.
    /// `"RigidBodies.Positions"`; the empty path is `self`.
    pub fn lookup(&self, path: &str) -> Option<&MatValue> {
        if path.is_empty() {
            return Some(self);
        }
        path.split('.').try_fold(self, |v, name| v.field(name))
    }
}

/// A parsed MAT-file: its header text and variables in file order.
#[derive(Debug, Clone, PartialEq)]
pub struct MatFile {
    path: PathBuf,
    header: String,
    big_endian: bool,
    variables: Vec<(String, MatValue)>,
}

impl MatFile {
    /// Reads and parses the file at `path`.
    pub fn read(path: impl AsRef<Path>) -> Result<MatFile> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|e| DataError::io(path, e))?;
        Self::from_bytes(&bytes, path)
    }

    /// Parses MAT-file bytes; `path` is only used to name the file in errors.
    pub fn from_bytes(bytes: &[u8], path: impl AsRef<Path>) -> Result<MatFile> {
        let path = path.as_ref();
        let header_err =
            |msg: String| DataError::format(Location::file(path).with_field("header"), msg);
        if bytes.is_empty() {
            return Err(header_err("the file is empty".into()));
        }
        if bytes.len() < HEADER_LEN {
            return Err(header_err(format!(
                "{} bytes, shorter than the 128-byte MAT-file header: truncated or not a MAT-file",
                bytes.len()
            )));
        }
        let text_end = bytes[..116].iter().position(|&b| b == 0).unwrap_or(116);
        let header = String::from_utf8_lossy(&bytes[..text_end])
            .trim_end()
            .to_owned();
        let big_endian = match &bytes[126..128] {
            b"IM" => false,
            b"MI" => true,
            _ => {
                let hdf5 = bytes.get(512..520) == Some(b"\x89HDF\r\n\x1a\n".as_slice());
                return Err(header_err(if header.starts_with("MATLAB 7.3") || hdf5 {
                    "MAT-file version 7.3 (HDF5) is not supported: save with -v7".into()
                } else {
                    "no endian indicator `IM`/`MI` at byte 126: not a Level 5 MAT-file".into()
                }));
            }
        };
        let ctx = Ctx { path, big_endian };
        let version = ctx.u16(&bytes[124..126]);
        if version != 0x0100 {
            return Err(header_err(format!(
                "version 0x{version:04x} at byte 124, expected 0x0100 (Level 5)"
            )));
        }
        let mut variables = Vec::new();
        let body = Slice {
            data: &bytes[HEADER_LEN..],
            origin: Origin::File(HEADER_LEN),
        };
        let mut pos = 0;
        while pos < body.data.len() {
            let tag = checked_tag(&ctx, &body, pos, "", 0)?;
            match tag.ty {
                MI_MATRIX => {
                    variables.push(parse_matrix(&ctx, body.sub(&tag), "", 0)?);
                    pos = tag.next_padded;
                }
                MI_COMPRESSED => {
                    let inflated = inflate(&ctx, &body, &tag)?;
                    let inner = Slice {
                        data: &inflated,
                        origin: Origin::Compressed(body.file_offset(tag.start)),
                    };
                    let mut ipos = 0;
                    while ipos < inner.data.len() {
                        let itag = checked_tag(&ctx, &inner, ipos, "", 0)?;
                        if itag.ty == MI_MATRIX {
                            variables.push(parse_matrix(&ctx, inner.sub(&itag), "", 0)?);
                        }
                        ipos = itag.next_padded;
                    }
                    // Compressed elements are not padded: the next tag follows directly.
                    pos = tag.next_unpadded;
                }
                // Only the two types above may appear at the top level; anything else is
                // skipped by its declared size, which `tag` has checked.
                _ => pos = tag.next_padded,
            }
        }
        Ok(MatFile {
            path: path.to_path_buf(),
            header,
            big_endian,
            variables,
        })
    }

    /// The file this was read from (as given to [`MatFile::read`] or
    /// [`MatFile::from_bytes`]).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The descriptive text of the header (e.g. `MATLAB 5.0 MAT-file, Platform: ...`).
    pub fn header_text(&self) -> &str {
        &self.header
    }

    /// Whether the file is big-endian.
    pub fn is_big_endian(&self) -> bool {
        self.big_endian
    }

    /// Variables with their names, in file order.
    pub fn variables(&self) -> impl Iterator<Item = (&str, &MatValue)> {
        self.variables.iter().map(|(n, v)| (n.as_str(), v))
    }

    /// The variable called `name`.
    pub fn get(&self, name: &str) -> Option<&MatValue> {
        self.variables
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v)
    }

    /// The value at a dot-separated path starting with a variable name, e.g.
    /// `"Take1.RigidBodies.Positions"`.
    pub fn lookup(&self, path: &str) -> Option<&MatValue> {
        let (var, rest) = path.split_once('.').unwrap_or((path, ""));
        self.get(var)?.lookup(rest)
    }

    /// Like [`MatFile::lookup`], but a missing variable or field is an error that names the
    /// file, the path and what is there instead.
    pub fn require(&self, path: &str) -> Result<&MatValue> {
        let (var, rest) = path.split_once('.').unwrap_or((path, ""));
        let at = || Location::file(&self.path).with_field(path);
        let mut value = self.get(var).ok_or_else(|| {
            let names: Vec<&str> = self.variables().map(|(n, _)| n).collect();
            DataError::format(
                at(),
                format!("no variable `{var}` (variables: {})", names.join(", ")),
            )
        })?;
        let mut walked = var.to_owned();
        for name in rest.split('.').filter(|s| !s.is_empty()) {
            value = match value {
                MatValue::Struct(s) if s.len() == 1 => s.field(0, name).ok_or_else(|| {
                    DataError::format(
                        at(),
                        format!(
                            "no field `{name}` in `{walked}` (fields: {})",
                            s.fields.join(", ")
                        ),
                    )
                })?,
                other => {
                    return Err(DataError::format(
                        at(),
                        format!(
                            "`{walked}` is a {} of size {}, not a 1x1 struct with field `{name}`",
                            other.kind(),
                            dims_text(other.dims())
                        ),
                    ));
                }
            };
            walked.push('.');
            walked.push_str(name);
        }
        Ok(value)
    }
}

/// Dimensions as MATLAB prints them, e.g. `1x3x7200`.
pub(crate) fn dims_text(dims: &[usize]) -> String {
    dims.iter()
        .map(|d| d.to_string())
        .collect::<Vec<_>>()
        .join("x")
}

fn column_major(dims: &[usize], index: &[usize]) -> Option<usize> {
    if index.len() > dims.len() && index[dims.len()..].iter().any(|&i| i != 0) {
        return None;
    }
    let mut linear = 0usize;
    let mut stride = 1usize;
    for (k, &d) in dims.iter().enumerate() {
        let i = index.get(k).copied().unwrap_or(0);
        if i >= d {
            return None;
        }
        linear = linear.checked_add(i.checked_mul(stride)?)?;
        stride = stride.checked_mul(d)?;
    }
    Some(linear)
}

struct Ctx<'a> {
    path: &'a Path,
    big_endian: bool,
}

impl Ctx<'_> {
    fn u16(&self, b: &[u8]) -> u16 {
        let a = [b[0], b[1]];
        if self.big_endian {
            u16::from_be_bytes(a)
        } else {
            u16::from_le_bytes(a)
        }
    }

    fn u32(&self, b: &[u8]) -> u32 {
        let a = [b[0], b[1], b[2], b[3]];
        if self.big_endian {
            u32::from_be_bytes(a)
        } else {
            u32::from_le_bytes(a)
        }
    }

    fn err(&self, field: &str, message: String) -> DataError {
        let field = if field.is_empty() { "variable" } else { field };
        DataError::format(Location::file(self.path).with_field(field), message)
    }
}

/// Where a buffer's bytes come from, so that errors can give an offset a user can find.
#[derive(Debug, Clone, Copy)]
enum Origin {
    /// A range of the file starting at this offset.
    File(usize),
    /// The inflated content of the compressed element whose tag is at this file offset.
    Compressed(usize),
}

#[derive(Clone, Copy)]
struct Slice<'a> {
    data: &'a [u8],
    origin: Origin,
}

/// A data element's tag, with positions relative to its buffer.
struct Tag {
    ty: u32,
    start: usize,
    data_start: usize,
    size: usize,
    /// Position after the data and the padding to 8 bytes (clamped to the buffer end: some
    /// writers omit the last element's padding).
    next_padded: usize,
    next_unpadded: usize,
}

impl<'a> Slice<'a> {
    fn file_offset(&self, pos: usize) -> usize {
        match self.origin {
            Origin::File(o) => o + pos,
            Origin::Compressed(o) => o,
        }
    }

    fn at(&self, pos: usize) -> String {
        match self.origin {
            Origin::File(o) => format!("at byte {}", o + pos),
            Origin::Compressed(o) => {
                format!("at byte {pos} of the compressed element at byte {o}")
            }
        }
    }

    fn tag(&self, ctx: &Ctx, pos: usize, field: &str) -> Result<Tag> {
        let rest = self.data.len().saturating_sub(pos);
        if rest < 8 {
            return Err(ctx.err(
                field,
                format!(
                    "truncated: {rest} bytes left {} where an 8-byte element tag is expected",
                    self.at(pos)
                ),
            ));
        }
        let first = ctx.u32(&self.data[pos..]);
        if first >> 16 != 0 {
            // Small element: byte count in the upper, type in the lower half, data in the
            // following 4 bytes.
            let size = (first >> 16) as usize;
            if size > 4 {
                return Err(ctx.err(
                    field,
                    format!(
                        "small data element {} declares {size} bytes, at most 4 fit",
                        self.at(pos)
                    ),
                ));
            }
            return Ok(Tag {
                ty: first & 0xffff,
                start: pos,
                data_start: pos + 4,
                size,
                next_padded: pos + 8,
                next_unpadded: pos + 8,
            });
        }
        let size = ctx.u32(&self.data[pos + 4..]) as usize;
        let data_start = pos + 8;
        let left = self.data.len() - data_start;
        if size > left {
            return Err(ctx.err(
                field,
                format!(
                    "truncated: {} element {} declares {size} bytes, only {left} remain",
                    type_name(first),
                    self.at(pos)
                ),
            ));
        }
        let end = data_start + size;
        Ok(Tag {
            ty: first,
            start: pos,
            data_start,
            size,
            next_padded: end.next_multiple_of(8).min(self.data.len()),
            next_unpadded: end,
        })
    }

    fn sub(&self, tag: &Tag) -> Slice<'a> {
        Slice {
            data: &self.data[tag.data_start..tag.data_start + tag.size],
            origin: match self.origin {
                Origin::File(o) => Origin::File(o + tag.data_start),
                c @ Origin::Compressed(_) => c,
            },
        }
    }

    fn bytes(&self, tag: &Tag) -> &'a [u8] {
        &self.data[tag.data_start..tag.data_start + tag.size]
    }
}

/// The tag of a variable or of a struct field or cell (`parent` is its path, empty for a
/// variable). When the element is cut short, its partial content is parsed anyway so that the
/// error names the innermost field where the data end, which tells a user much more than
/// "variable truncated".
fn checked_tag(ctx: &Ctx, s: &Slice, pos: usize, parent: &str, depth: usize) -> Result<Tag> {
    let err = match s.tag(ctx, pos, parent) {
        Ok(tag) => return Ok(tag),
        Err(e) => e,
    };
    let partial = match s.data.get(pos + 8..) {
        Some(p) if !p.is_empty() => p,
        _ => return Err(err),
    };
    let first = ctx.u32(&s.data[pos..]);
    if first == MI_MATRIX {
        let cut = Slice {
            data: partial,
            origin: match s.origin {
                Origin::File(o) => Origin::File(o + pos + 8),
                c @ Origin::Compressed(_) => c,
            },
        };
        parse_matrix(ctx, cut, parent, depth)?;
    } else if first == MI_COMPRESSED && parent.is_empty() && matches!(s.origin, Origin::File(_)) {
        // Only a top-level compressed element is looked into: compressed data nested in
        // compressed data is not MAT v5, and following it could recurse without bound.
        let inflated = inflate_partial(partial);
        let cut = Slice {
            data: &inflated,
            origin: Origin::Compressed(s.file_offset(pos)),
        };
        if inflated.len() >= 8 {
            checked_tag(ctx, &cut, 0, parent, depth)?;
        }
    }
    Err(err)
}

/// What a cut-short zlib stream still yields, for error messages only; capped because it is
/// only needed to find where the data end.
fn inflate_partial(bytes: &[u8]) -> Vec<u8> {
    const CAP: u64 = 256 << 20;
    let mut out = Vec::new();
    let mut decoder = ZlibDecoder::new(bytes).take(CAP);
    let mut buf = [0u8; 64 << 10];
    while let Ok(n) = decoder.read(&mut buf) {
        if n == 0 {
            break;
        }
        out.extend_from_slice(&buf[..n]);
    }
    out
}

fn type_name(ty: u32) -> String {
    match ty {
        MI_INT8 => "miINT8".into(),
        MI_UINT8 => "miUINT8".into(),
        MI_INT16 => "miINT16".into(),
        MI_UINT16 => "miUINT16".into(),
        MI_INT32 => "miINT32".into(),
        MI_UINT32 => "miUINT32".into(),
        MI_SINGLE => "miSINGLE".into(),
        MI_DOUBLE => "miDOUBLE".into(),
        MI_INT64 => "miINT64".into(),
        MI_UINT64 => "miUINT64".into(),
        MI_MATRIX => "miMATRIX".into(),
        MI_COMPRESSED => "miCOMPRESSED".into(),
        MI_UTF8 => "miUTF8".into(),
        MI_UTF16 => "miUTF16".into(),
        MI_UTF32 => "miUTF32".into(),
        other => format!("type-{other}"),
    }
}

fn inflate(ctx: &Ctx, body: &Slice, tag: &Tag) -> Result<Vec<u8>> {
    let field = format!("compressed element at byte {}", body.file_offset(tag.start));
    let bad = |e: std::io::Error| ctx.err(&field, format!("corrupt zlib data: {e}"));
    let mut decoder = ZlibDecoder::new(body.bytes(tag));
    let mut head = [0u8; 8];
    decoder.read_exact(&mut head).map_err(bad)?;
    let first = ctx.u32(&head);
    let declared = if first >> 16 != 0 {
        4
    } else {
        ctx.u32(&head[4..]) as u64
    };
    // The inner tag's size bounds what is read, so a lying size can make the buffer grow only as
    // far as real data decompresses, never by the size alone.
    let mut out = head.to_vec();
    decoder
        .take(declared.next_multiple_of(8))
        .read_to_end(&mut out)
        .map_err(bad)?;
    Ok(out)
}

fn parse_matrix(ctx: &Ctx, m: Slice, parent: &str, depth: usize) -> Result<(String, MatValue)> {
    let here = |name: &str| -> String {
        match (parent.is_empty(), name.is_empty()) {
            (true, _) => name.to_owned(),
            (false, true) => parent.to_owned(),
            (false, false) => format!("{parent}.{name}"),
        }
    };
    if depth > MAX_DEPTH {
        return Err(ctx.err(
            parent,
            format!("nested deeper than {MAX_DEPTH} levels {}", m.at(0)),
        ));
    }
    // MATLAB writes an empty array inside cells and structs as a bare zero-size miMATRIX.
    if m.data.is_empty() {
        return Ok((
            String::new(),
            MatValue::Numeric(Numeric {
                dims: vec![0, 0],
                class: MatClass::Double,
                logical: false,
                real: Vec::new(),
                imag: None,
            }),
        ));
    }
    let flags = m.tag(ctx, 0, parent)?;
    if flags.ty != MI_UINT32 || flags.size != 8 {
        return Err(ctx.err(
            parent,
            format!(
                "array flags {} should be 8 bytes of type miUINT32, found {} bytes of type {}",
                m.at(0),
                flags.size,
                flags.ty
            ),
        ));
    }
    let f0 = ctx.u32(m.bytes(&flags));
    let class = MatClass::from_code((f0 & 0xff) as u8);
    let complex = f0 & 0x800 != 0;
    let logical = f0 & 0x200 != 0;

    let dims_tag = m.tag(ctx, flags.next_padded, parent)?;
    if dims_tag.ty != MI_INT32 || dims_tag.size % 4 != 0 || dims_tag.size == 0 {
        return Err(ctx.err(
            parent,
            format!(
                "dimensions {} should be miINT32 values, found {} bytes of type {}",
                m.at(dims_tag.start),
                dims_tag.size,
                dims_tag.ty
            ),
        ));
    }
    let mut dims = Vec::with_capacity(dims_tag.size / 4);
    for c in m.bytes(&dims_tag).chunks_exact(4) {
        let d = ctx.u32(c) as i32;
        if d < 0 {
            return Err(ctx.err(
                parent,
                format!("negative dimension {d} {}", m.at(dims_tag.start)),
            ));
        }
        dims.push(d as usize);
    }
    let numel = dims
        .iter()
        .try_fold(1usize, |a, &d| a.checked_mul(d))
        .ok_or_else(|| ctx.err(parent, format!("dimensions {} overflow", dims_text(&dims))))?;

    let name_tag = m.tag(ctx, dims_tag.next_padded, parent)?;
    if !matches!(name_tag.ty, MI_INT8 | MI_UINT8) {
        return Err(ctx.err(
            parent,
            format!(
                "array name {} should be miINT8, found type {}",
                m.at(name_tag.start),
                name_tag.ty
            ),
        ));
    }
    let name = String::from_utf8_lossy(m.bytes(&name_tag))
        .trim_end_matches('\0')
        .to_owned();
    let path = here(&name);
    let mut pos = name_tag.next_padded;

    let value = match class {
        c if c.is_numeric() => {
            let real_tag = m.tag(ctx, pos, &path)?;
            let real = numbers(ctx, &m, &real_tag, numel, &path, "real part")?;
            let imag = if complex {
                let imag_tag = m.tag(ctx, real_tag.next_padded, &path)?;
                Some(numbers(ctx, &m, &imag_tag, numel, &path, "imaginary part")?)
            } else {
                None
            };
            MatValue::Numeric(Numeric {
                dims,
                class,
                logical,
                real,
                imag,
            })
        }
        MatClass::Char => {
            let tag = m.tag(ctx, pos, &path)?;
            MatValue::Char(CharArray {
                text: chars(ctx, &m, &tag, &dims, numel, &path)?,
                dims,
            })
        }
        MatClass::Cell => {
            let items = children(ctx, &m, &mut pos, numel, &path, depth, |i| {
                format!("{{{}}}", i + 1)
            })?;
            MatValue::Cell(CellArray { dims, items })
        }
        MatClass::Struct | MatClass::Object => {
            let class_name = if class == MatClass::Object {
                let tag = m.tag(ctx, pos, &path)?;
                pos = tag.next_padded;
                Some(
                    String::from_utf8_lossy(m.bytes(&tag))
                        .trim_end_matches('\0')
                        .to_owned(),
                )
            } else {
                None
            };
            let len_tag = m.tag(ctx, pos, &path)?;
            if len_tag.ty != MI_INT32 || len_tag.size != 4 {
                return Err(ctx.err(
                    &path,
                    format!(
                        "field name length {} should be one miINT32, found {} bytes of type {}",
                        m.at(len_tag.start),
                        len_tag.size,
                        len_tag.ty
                    ),
                ));
            }
            let name_len = ctx.u32(m.bytes(&len_tag)) as usize;
            let names_tag = m.tag(ctx, len_tag.next_padded, &path)?;
            if name_len == 0 || names_tag.size % name_len != 0 {
                return Err(ctx.err(
                    &path,
                    format!(
                        "field names {} take {} bytes, not a multiple of the name length {name_len}",
                        m.at(names_tag.start),
                        names_tag.size
                    ),
                ));
            }
            let fields: Vec<String> = m
                .bytes(&names_tag)
                .chunks_exact(name_len)
                .map(|c| {
                    let end = c.iter().position(|&b| b == 0).unwrap_or(c.len());
                    String::from_utf8_lossy(&c[..end]).into_owned()
                })
                .collect();
            pos = names_tag.next_padded;
            let count = numel
                .checked_mul(fields.len())
                .ok_or_else(|| ctx.err(&path, "struct size overflows".into()))?;
            let nf = fields.len();
            let values = children(ctx, &m, &mut pos, count, &path, depth, |i| {
                let field = &fields[i % nf];
                if numel == 1 {
                    field.clone()
                } else {
                    format!("({}).{field}", i / nf + 1)
                }
            })?;
            MatValue::Struct(StructArray {
                dims,
                class_name,
                fields,
                values,
            })
        }
        other => MatValue::Unsupported { class: other, dims },
    };
    Ok((name, value))
}

/// Parses `count` consecutive `miMATRIX` children (cells, struct fields) starting at `pos`.
fn children(
    ctx: &Ctx,
    m: &Slice,
    pos: &mut usize,
    count: usize,
    path: &str,
    depth: usize,
    label: impl Fn(usize) -> String,
) -> Result<Vec<MatValue>> {
    // Every child takes at least an 8-byte tag, so the remaining bytes bound a sane count
    // before anything is allocated.
    let room = m.data.len().saturating_sub(*pos) / 8;
    if count > room {
        return Err(ctx.err(
            path,
            format!(
                "truncated: {count} elements declared {}, room for at most {room}",
                m.at(*pos)
            ),
        ));
    }
    let mut out = Vec::with_capacity(count);
    for i in 0..count {
        let child_path = {
            let l = label(i);
            if l.starts_with('{') || l.starts_with('(') {
                format!("{path}{l}")
            } else {
                format!("{path}.{l}")
            }
        };
        let tag = checked_tag(ctx, m, *pos, &child_path, depth + 1)?;
        if tag.ty != MI_MATRIX {
            return Err(ctx.err(
                &child_path,
                format!(
                    "expected a miMATRIX element {}, found type {}",
                    m.at(tag.start),
                    tag.ty
                ),
            ));
        }
        let (_, v) = parse_matrix(ctx, m.sub(&tag), &child_path, depth + 1)?;
        out.push(v);
        *pos = tag.next_padded;
    }
    Ok(out)
}

fn numbers(
    ctx: &Ctx,
    m: &Slice,
    tag: &Tag,
    numel: usize,
    path: &str,
    what: &str,
) -> Result<Vec<f64>> {
    let width = match tag.ty {
        MI_INT8 | MI_UINT8 => 1,
        MI_INT16 | MI_UINT16 => 2,
        MI_INT32 | MI_UINT32 | MI_SINGLE => 4,
        MI_DOUBLE | MI_INT64 | MI_UINT64 => 8,
        t => {
            return Err(ctx.err(
                path,
                format!("{what} {} has non-numeric data type {t}", m.at(tag.start)),
            ));
        }
    };
    let b = m.bytes(tag);
    if b.len() != numel.saturating_mul(width) {
        return Err(ctx.err(
            path,
            format!(
                "{what} {} holds {} bytes, {numel} values of {width} bytes expected",
                m.at(tag.start),
                b.len()
            ),
        ));
    }
    let be = ctx.big_endian;
    macro_rules! conv {
        ($t:ty, $n:literal) => {
            b.chunks_exact($n)
                .map(|c| {
                    let a: [u8; $n] = c.try_into().unwrap_or([0; $n]);
                    (if be {
                        <$t>::from_be_bytes(a)
                    } else {
                        <$t>::from_le_bytes(a)
                    }) as f64
                })
                .collect()
        };
    }
    Ok(match tag.ty {
        MI_INT8 => b.iter().map(|&x| x as i8 as f64).collect(),
        MI_UINT8 => b.iter().map(|&x| x as f64).collect(),
        MI_INT16 => conv!(i16, 2),
        MI_UINT16 => conv!(u16, 2),
        MI_INT32 => conv!(i32, 4),
        MI_UINT32 => conv!(u32, 4),
        MI_SINGLE => conv!(f32, 4),
        MI_INT64 => conv!(i64, 8),
        MI_UINT64 => conv!(u64, 8),
        _ => conv!(f64, 8),
    })
}

fn chars(
    ctx: &Ctx,
    m: &Slice,
    tag: &Tag,
    dims: &[usize],
    numel: usize,
    path: &str,
) -> Result<String> {
    let b = m.bytes(tag);
    let be = ctx.big_endian;
    let decoded: Vec<char> = match tag.ty {
        MI_UTF8 => String::from_utf8_lossy(b).chars().collect(),
        // 8-bit characters other than UTF-8 are Latin-1, the first 256 code points.
        MI_INT8 | MI_UINT8 => b.iter().map(|&c| c as char).collect(),
        MI_UINT16 | MI_UTF16 | MI_INT16 => {
            let units = b.chunks_exact(2).map(|c| {
                if be {
                    u16::from_be_bytes([c[0], c[1]])
                } else {
                    u16::from_le_bytes([c[0], c[1]])
                }
            });
            char::decode_utf16(units)
                .map(|r| r.unwrap_or(char::REPLACEMENT_CHARACTER))
                .collect()
        }
        MI_UTF32 | MI_UINT32 | MI_INT32 => b
            .chunks_exact(4)
            .map(|c| {
                let a = [c[0], c[1], c[2], c[3]];
                let u = if be {
                    u32::from_be_bytes(a)
                } else {
                    u32::from_le_bytes(a)
                };
                char::from_u32(u).unwrap_or(char::REPLACEMENT_CHARACTER)
            })
            .collect(),
        t => {
            return Err(ctx.err(
                path,
                format!("characters {} have data type {t}", m.at(tag.start)),
            ));
        }
    };
    let rows = dims.first().copied().unwrap_or(1);
    // Multi-row char arrays are column-major; reorder when the count allows it, and keep the
    // raw order otherwise (multi-byte UTF-8 can make the count differ from the dimensions).
    // An empty array is an empty text: its row count, which costs nothing to declare (e.g.
    // 2^31 - 1 by 0), must not become that many line breaks.
    if rows > 1 && numel > 0 && decoded.len() == numel {
        let cols = numel / rows;
        let mut text = String::with_capacity(numel + rows);
        for r in 0..rows {
            if r > 0 {
                text.push('\n');
            }
            text.extend((0..cols).map(|c| decoded[r + rows * c]));
        }
        Ok(text)
    } else {
        Ok(decoded.into_iter().collect())
    }
}
