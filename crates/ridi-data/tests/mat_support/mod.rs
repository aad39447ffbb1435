//! A tiny Level 5 MAT-file writer for test fixtures: enough of the format to build the files
//! the reader must accept (numeric, char, struct, cell, compressed, big-endian) and, by editing
//! the bytes, the ones it must reject.

#![allow(dead_code)]

use std::io::Write;

use flate2::Compression;
use flate2::write::ZlibEncoder;

pub(crate) const MI_INT8: u32 = 1;
pub(crate) const MI_UINT8: u32 = 2;
pub(crate) const MI_INT16: u32 = 3;
pub(crate) const MI_INT32: u32 = 5;
pub(crate) const MI_UINT32: u32 = 6;
pub(crate) const MI_SINGLE: u32 = 7;
pub(crate) const MI_DOUBLE: u32 = 9;
pub(crate) const MI_MATRIX: u32 = 14;
pub(crate) const MI_COMPRESSED: u32 = 15;
pub(crate) const MI_UTF16: u32 = 17;

pub(crate) const CLASS_CELL: u8 = 1;
pub(crate) const CLASS_STRUCT: u8 = 2;
pub(crate) const CLASS_CHAR: u8 = 4;
pub(crate) const CLASS_DOUBLE: u8 = 6;
pub(crate) const CLASS_SINGLE: u8 = 7;
pub(crate) const CLASS_INT16: u8 = 10;

/// A value to write.
#[derive(Clone, Debug)]
pub(crate) enum V {
    /// Double array, column-major.
    Num(Vec<usize>, Vec<f64>),
    /// Array of `class` whose data are stored as `mi_type` with the given raw bytes (file
    /// endianness is the caller's business).
    Typed {
        dims: Vec<usize>,
        class: u8,
        mi_type: u32,
        data: Vec<u8>,
    },
    /// Complex double array.
    Complex(Vec<usize>, Vec<f64>, Vec<f64>),
    /// 1xN char array.
    Char(String),
    /// 1x1 struct.
    Struct(Vec<(String, V)>),
    /// 1xN cell.
    Cell(Vec<V>),
}

pub(crate) struct W {
    pub big_endian: bool,
}

impl W {
    fn u32(&self, v: u32) -> [u8; 4] {
        if self.big_endian {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }
    }

    fn f64(&self, v: f64) -> [u8; 8] {
        if self.big_endian {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }
    }

    /// One data element; up to 4 bytes use the small element form, as MATLAB does.
    pub(crate) fn elem(&self, ty: u32, data: &[u8]) -> Vec<u8> {
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

    fn header_parts(&self, class: u8, flags: u8, dims: &[usize], name: &str) -> Vec<u8> {
        let mut flag_bytes = Vec::new();
        flag_bytes.extend(self.u32(class as u32 | ((flags as u32) << 8)));
        flag_bytes.extend(self.u32(0));
        let mut dim_bytes = Vec::new();
        for &d in dims {
            dim_bytes.extend(self.u32(d as u32));
        }
        let mut out = self.elem(MI_UINT32, &flag_bytes);
        out.extend(self.elem(MI_INT32, &dim_bytes));
        out.extend(self.elem(MI_INT8, name.as_bytes()));
        out
    }

    /// The payload of a miMATRIX element (without its tag).
    pub(crate) fn matrix_body(&self, name: &str, v: &V) -> Vec<u8> {
        match v {
            V::Num(dims, data) => {
                let mut out = self.header_parts(CLASS_DOUBLE, 0, dims, name);
                let bytes: Vec<u8> = data.iter().flat_map(|&x| self.f64(x)).collect();
                out.extend(self.elem(MI_DOUBLE, &bytes));
                out
            }
            V::Typed {
                dims,
                class,
                mi_type,
                data,
            } => {
                let mut out = self.header_parts(*class, 0, dims, name);
                out.extend(self.elem(*mi_type, data));
                out
            }
            V::Complex(dims, re, im) => {
                let mut out = self.header_parts(CLASS_DOUBLE, 0x08, dims, name);
                let r: Vec<u8> = re.iter().flat_map(|&x| self.f64(x)).collect();
                let i: Vec<u8> = im.iter().flat_map(|&x| self.f64(x)).collect();
                out.extend(self.elem(MI_DOUBLE, &r));
                out.extend(self.elem(MI_DOUBLE, &i));
                out
            }
            V::Char(s) => {
                let units: Vec<u16> = s.encode_utf16().collect();
                let mut out = self.header_parts(CLASS_CHAR, 0, &[1, units.len()], name);
                let bytes: Vec<u8> = units
                    .iter()
                    .flat_map(|&u| {
                        if self.big_endian {
                            u.to_be_bytes()
                        } else {
                            u.to_le_bytes()
                        }
                    })
                    .collect();
                out.extend(self.elem(MI_UTF16, &bytes));
                out
            }
            V::Struct(fields) => {
                let mut out = self.header_parts(CLASS_STRUCT, 0, &[1, 1], name);
                let len = 32;
                out.extend(self.elem(MI_INT32, &self.u32(len)));
                let mut names = Vec::new();
                for (n, _) in fields {
                    let mut b = n.as_bytes().to_vec();
                    b.resize(len as usize, 0);
                    names.extend(b);
                }
                out.extend(self.elem(MI_INT8, &names));
                for (_, f) in fields {
                    out.extend(self.matrix("", f));
                }
                out
            }
            V::Cell(items) => {
                let mut out = self.header_parts(CLASS_CELL, 0, &[1, items.len()], name);
                for it in items {
                    out.extend(self.matrix("", it));
                }
                out
            }
        }
    }

    /// A whole miMATRIX element.
    pub(crate) fn matrix(&self, name: &str, v: &V) -> Vec<u8> {
        let body = self.matrix_body(name, v);
        let mut out = Vec::new();
        out.extend(self.u32(MI_MATRIX));
        out.extend(self.u32(body.len() as u32));
        out.extend(body);
        out
    }

    pub(crate) fn header(&self, text: &str) -> Vec<u8> {
        let mut h = text.as_bytes().to_vec();
        h.resize(116, b' ');
        h.extend([0u8; 8]);
        if self.big_endian {
            h.extend([0x01, 0x00]);
            h.extend(b"MI");
        } else {
            h.extend([0x00, 0x01]);
            h.extend(b"IM");
        }
        h
    }

    /// A file with `vars`, each in its own miCOMPRESSED element when `compress`.
    pub(crate) fn file(&self, vars: &[(&str, V)], compress: bool) -> Vec<u8> {
        let mut out = self.header("MATLAB 5.0 MAT-file, written by the ridi-data tests");
        for (name, v) in vars {
            let m = self.matrix(name, v);
            if compress {
                let mut z = ZlibEncoder::new(Vec::new(), Compression::default());
                z.write_all(&m).unwrap();
                let z = z.finish().unwrap();
                out.extend(self.u32(MI_COMPRESSED));
                out.extend(self.u32(z.len() as u32));
                out.extend(z);
            } else {
                out.extend(m);
            }
        }
        out
    }
}

pub(crate) fn le() -> W {
    W { big_endian: false }
}

/// A QTM-like export: a struct named `take` with `FrameRate` and a `RigidBodies` struct whose
/// `Positions` (mm) and `Rotations` (column-major 3x3) are 1x3xN and 1x9xN.
pub(crate) fn qtm_like(
    take: &str,
    rate: f64,
    positions_mm: &[[f64; 3]],
    rotations: &[[f64; 9]],
) -> Vec<(String, V)> {
    let n = positions_mm.len();
    let pos: Vec<f64> = positions_mm.iter().flatten().copied().collect();
    let rot: Vec<f64> = rotations.iter().flatten().copied().collect();
    let rigid = V::Struct(vec![
        ("Bodies".into(), V::Num(vec![1, 1], vec![1.0])),
        ("Name".into(), V::Cell(vec![V::Char("Phone".into())])),
        ("Positions".into(), V::Num(vec![1, 3, n], pos)),
        ("Rotations".into(), V::Num(vec![1, 9, rotations.len()], rot)),
    ]);
    vec![(
        take.to_owned(),
        V::Struct(vec![
            ("File".into(), V::Char("C:\\take.qtm".into())),
            ("StartFrame".into(), V::Num(vec![1, 1], vec![1.0])),
            ("Frames".into(), V::Num(vec![1, 1], vec![n as f64])),
            ("FrameRate".into(), V::Num(vec![1, 1], vec![rate])),
            ("RigidBodies".into(), rigid),
        ]),
    )]
}
