//! A tiny Level 5 MAT-file writer: enough of the format to build the files the MAT reader must
//! accept (numeric, char, struct, cell, compressed, big-endian), the QTM exports of the Tyrex
//! ground truth, and, by editing the bytes, the files the reader must reject. The one writer of
//! ridi-data's tests and of the fuzz seeds `cargo xtask fuzz` writes.

use std::io::Write as _;

use flate2::Compression;
use flate2::write::ZlibEncoder;

/// An array to write (MAT files hold arrays only: a scalar is 1x1).
#[derive(Clone, Debug)]
pub enum MatArray {
    /// Double array: dimensions, column-major data.
    Num(Vec<usize>, Vec<f64>),
    /// Array of `class` whose data are stored as `mi_type` with the given raw bytes (their byte
    /// order is the caller's business).
    Typed {
        /// Dimensions.
        dims: Vec<usize>,
        /// Array class, a `CLASS_*` code.
        class: u8,
        /// Data type of the data element, an `MI_*` code.
        mi_type: u32,
        /// The data element's bytes.
        data: Vec<u8>,
    },
    /// Complex double array: dimensions, real and imaginary parts, column-major.
    Complex(Vec<usize>, Vec<f64>, Vec<f64>),
    /// 1xN char array.
    Char(String),
    /// 1x1 struct: its fields, in order.
    Struct(Vec<(String, MatArray)>),
    /// 1xN cell.
    Cell(Vec<MatArray>),
}

impl MatArray {
    /// Data type `miINT8`.
    pub const MI_INT8: u32 = 1;
    /// Data type `miUINT8`.
    pub const MI_UINT8: u32 = 2;
    /// Data type `miINT16`.
    pub const MI_INT16: u32 = 3;
    /// Data type `miINT32`.
    pub const MI_INT32: u32 = 5;
    /// Data type `miUINT32`.
    pub const MI_UINT32: u32 = 6;
    /// Data type `miSINGLE`.
    pub const MI_SINGLE: u32 = 7;
    /// Data type `miDOUBLE`.
    pub const MI_DOUBLE: u32 = 9;
    /// Data type `miMATRIX`: an array element.
    pub const MI_MATRIX: u32 = 14;
    /// Data type `miCOMPRESSED`: a zlib stream of elements.
    pub const MI_COMPRESSED: u32 = 15;
    /// Data type `miUTF16`.
    pub const MI_UTF16: u32 = 17;

    /// Array class `mxCELL_CLASS`.
    pub const CLASS_CELL: u8 = 1;
    /// Array class `mxSTRUCT_CLASS`.
    pub const CLASS_STRUCT: u8 = 2;
    /// Array class `mxCHAR_CLASS`.
    pub const CLASS_CHAR: u8 = 4;
    /// Array class `mxDOUBLE_CLASS`.
    pub const CLASS_DOUBLE: u8 = 6;
    /// Array class `mxSINGLE_CLASS`.
    pub const CLASS_SINGLE: u8 = 7;
    /// Array class `mxINT16_CLASS`.
    pub const CLASS_INT16: u8 = 10;
}

/// Writes MAT elements and files in one byte order.
#[derive(Clone, Copy, Debug)]
pub struct MatWriter {
    /// Big-endian (`MI` in the header) rather than little-endian (`IM`).
    pub big_endian: bool,
}

impl MatWriter {
    /// The little-endian writer (MATLAB's on x86).
    pub const LE: Self = Self { big_endian: false };
    /// The big-endian writer.
    pub const BE: Self = Self { big_endian: true };

    /// A value's bytes in the file's byte order, given both orders.
    fn ordered<const N: usize>(&self, be: [u8; N], le: [u8; N]) -> [u8; N] {
        if self.big_endian { be } else { le }
    }

    fn u32(&self, v: u32) -> [u8; 4] {
        self.ordered(v.to_be_bytes(), v.to_le_bytes())
    }

    fn f64s(&self, data: &[f64]) -> Vec<u8> {
        data.iter()
            .flat_map(|x| self.ordered(x.to_be_bytes(), x.to_le_bytes()))
            .collect()
    }

    /// One data element; up to 4 bytes use the small element form, as MATLAB does.
    pub fn elem(&self, ty: u32, data: &[u8]) -> Vec<u8> {
        let mut out = Vec::new();
        if !data.is_empty() && data.len() <= 4 {
            out.extend(self.u32(((data.len() as u32) << 16) | ty));
            out.extend(data);
            out.resize(8, 0);
        } else {
            out.extend(self.u32(ty));
            out.extend(self.u32(data.len() as u32));
            out.extend(data);
            out.resize(out.len().next_multiple_of(8), 0);
        }
        out
    }

    /// The array flags, dimensions and name elements that open an array.
    fn array_header(&self, class: u8, flags: u8, dims: &[usize], name: &str) -> Vec<u8> {
        let flags = [
            self.u32(u32::from(class) | (u32::from(flags) << 8)),
            self.u32(0),
        ]
        .concat();
        let dims: Vec<u8> = dims.iter().flat_map(|&d| self.u32(d as u32)).collect();
        let mut out = self.elem(MatArray::MI_UINT32, &flags);
        out.extend(self.elem(MatArray::MI_INT32, &dims));
        out.extend(self.elem(MatArray::MI_INT8, name.as_bytes()));
        out
    }

    /// The payload of the `miMATRIX` element of `v` named `name` (without its tag).
    pub fn matrix_body(&self, name: &str, v: &MatArray) -> Vec<u8> {
        match v {
            MatArray::Num(dims, data) => {
                let mut out = self.array_header(MatArray::CLASS_DOUBLE, 0, dims, name);
                out.extend(self.elem(MatArray::MI_DOUBLE, &self.f64s(data)));
                out
            }
            MatArray::Typed {
                dims,
                class,
                mi_type,
                data,
            } => {
                let mut out = self.array_header(*class, 0, dims, name);
                out.extend(self.elem(*mi_type, data));
                out
            }
            MatArray::Complex(dims, re, im) => {
                // Flag 0x08: complex.
                let mut out = self.array_header(MatArray::CLASS_DOUBLE, 0x08, dims, name);
                out.extend(self.elem(MatArray::MI_DOUBLE, &self.f64s(re)));
                out.extend(self.elem(MatArray::MI_DOUBLE, &self.f64s(im)));
                out
            }
            MatArray::Char(s) => {
                let units: Vec<u16> = s.encode_utf16().collect();
                let mut out = self.array_header(MatArray::CLASS_CHAR, 0, &[1, units.len()], name);
                let bytes: Vec<u8> = units
                    .iter()
                    .flat_map(|u| self.ordered(u.to_be_bytes(), u.to_le_bytes()))
                    .collect();
                out.extend(self.elem(MatArray::MI_UTF16, &bytes));
                out
            }
            MatArray::Struct(fields) => {
                // Field names in fixed 32-byte slots.
                const NAME_LEN: usize = 32;
                let mut out = self.array_header(MatArray::CLASS_STRUCT, 0, &[1, 1], name);
                out.extend(self.elem(MatArray::MI_INT32, &self.u32(NAME_LEN as u32)));
                let mut names = Vec::new();
                for (n, _) in fields {
                    let mut b = n.as_bytes().to_vec();
                    b.resize(NAME_LEN, 0);
                    names.extend(b);
                }
                out.extend(self.elem(MatArray::MI_INT8, &names));
                for (_, f) in fields {
                    out.extend(self.matrix("", f));
                }
                out
            }
            MatArray::Cell(items) => {
                let mut out = self.array_header(MatArray::CLASS_CELL, 0, &[1, items.len()], name);
                for it in items {
                    out.extend(self.matrix("", it));
                }
                out
            }
        }
    }

    /// The whole `miMATRIX` element of `v` named `name`.
    pub fn matrix(&self, name: &str, v: &MatArray) -> Vec<u8> {
        let body = self.matrix_body(name, v);
        let mut out = self.u32(MatArray::MI_MATRIX).to_vec();
        out.extend(self.u32(body.len() as u32));
        out.extend(body);
        out
    }

    /// The 128-byte file header: `text` padded to 116 bytes, no subsystem data, then version
    /// 0x0100 and the byte-order mark, both in the file's byte order.
    pub fn header(&self, text: &str) -> Vec<u8> {
        let mut h = text.as_bytes().to_vec();
        h.resize(116, b' ');
        h.extend([0u8; 8]);
        h.extend(if self.big_endian {
            *b"\x01\x00MI"
        } else {
            *b"\x00\x01IM"
        });
        h
    }

    /// A file of the variables `vars` (name, array), each in its own `miCOMPRESSED` element
    /// when `compress`.
    pub fn file<S: AsRef<str>>(&self, vars: &[(S, MatArray)], compress: bool) -> Vec<u8> {
        let mut out = self.header("MATLAB 5.0 MAT-file, written by ridi-test-support");
        for (name, v) in vars {
            let m = self.matrix(name.as_ref(), v);
            if compress {
                let mut z = ZlibEncoder::new(Vec::new(), Compression::default());
                z.write_all(&m).expect("writing to memory");
                let z = z.finish().expect("writing to memory");
                out.extend(self.u32(MatArray::MI_COMPRESSED));
                out.extend(self.u32(z.len() as u32));
                out.extend(z);
            } else {
                out.extend(m);
            }
        }
        out
    }
}

/// A QTM export of one rigid body, as the Tyrex `.mat` files: a struct named `take` with
/// `FrameRate` `rate` and a `RigidBodies` struct whose `Positions` (mm) and `Rotations`
/// (column-major 3x3) are 1x3xN and 1x9xN, N the number of each.
pub fn qtm_take(
    take: &str,
    rate: f64,
    positions_mm: &[[f64; 3]],
    rotations: &[[f64; 9]],
) -> Vec<(String, MatArray)> {
    let n = positions_mm.len();
    let pos = positions_mm.iter().flatten().copied().collect();
    let rot = rotations.iter().flatten().copied().collect();
    let rigid = MatArray::Struct(vec![
        ("Bodies".into(), MatArray::Num(vec![1, 1], vec![1.0])),
        (
            "Name".into(),
            MatArray::Cell(vec![MatArray::Char("Phone".into())]),
        ),
        ("Positions".into(), MatArray::Num(vec![1, 3, n], pos)),
        (
            "Rotations".into(),
            MatArray::Num(vec![1, 9, rotations.len()], rot),
        ),
    ]);
    vec![(
        take.to_owned(),
        MatArray::Struct(vec![
            ("File".into(), MatArray::Char("C:\\take.qtm".into())),
            ("StartFrame".into(), MatArray::Num(vec![1, 1], vec![1.0])),
            ("Frames".into(), MatArray::Num(vec![1, 1], vec![n as f64])),
            ("FrameRate".into(), MatArray::Num(vec![1, 1], vec![rate])),
            ("RigidBodies".into(), rigid),
        ]),
    )]
}
