//! MAT v5 reader: fixtures written by `ridi_test_support::MatWriter` (a tiny writer), read back,
//! and corrupted in every way that matters; no input may panic, and every error names the file
//! (and the field where there is one).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use ridi_data::DataError;
use ridi_data::{MAX_DEPTH, MatClass, MatFile, MatValue};
use ridi_test_support::{MatArray, MatWriter, assert_names_file};

fn sample() -> Vec<(&'static str, MatArray)> {
    vec![
        (
            "a",
            MatArray::Num(vec![2, 3], vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]),
        ),
        ("s", MatArray::Char("Nexus5-Handler".into())),
        (
            "take",
            MatArray::Struct(vec![
                ("FrameRate".into(), MatArray::Num(vec![1, 1], vec![60.0])),
                (
                    "Inner".into(),
                    MatArray::Struct(vec![
                        (
                            "Names".into(),
                            MatArray::Cell(vec![
                                MatArray::Char("x".into()),
                                MatArray::Char("yz".into()),
                            ]),
                        ),
                        ("Empty".into(), MatArray::Num(vec![0, 0], vec![])),
                    ]),
                ),
            ]),
        ),
    ]
}

fn check_sample(m: &MatFile) {
    let names: Vec<&str> = m.variables().map(|(n, _)| n).collect();
    assert_eq!(names, ["a", "s", "take"]);
    let a = m.get("a").unwrap().as_numeric().unwrap();
    assert_eq!(a.dims, [2, 3]);
    assert_eq!(a.class, MatClass::Double);
    // Column-major: (row 1, col 2) is the 6th value.
    assert_eq!(a.get(&[1, 2]), Some(6.0));
    assert_eq!(a.get(&[0, 1]), Some(3.0));
    assert_eq!(a.get(&[2, 0]), None);
    assert_eq!(m.get("s").unwrap().as_str(), Some("Nexus5-Handler"));
    assert_eq!(m.lookup("take.FrameRate").unwrap().scalar(), Some(60.0));
    let names = m.lookup("take.Inner.Names").unwrap().as_cell().unwrap();
    assert_eq!(names.dims, [1, 2]);
    assert_eq!(names.items[1].as_str(), Some("yz"));
    let empty = m.lookup("take.Inner.Empty").unwrap().as_numeric().unwrap();
    assert!(empty.is_empty() && empty.dims == [0, 0]);
    assert!(m.lookup("take.Missing").is_none());
}

#[test]
fn reads_plain_compressed_and_big_endian_files() {
    for (w, compress) in [
        (MatWriter::LE, false),
        (MatWriter::LE, true),
        (MatWriter::BE, false),
        (MatWriter::BE, true),
    ] {
        let bytes = w.file(&sample(), compress);
        let m = MatFile::from_bytes(&bytes, "sample.mat").unwrap();
        assert_eq!(m.is_big_endian(), w.big_endian);
        assert!(m.header_text().starts_with("MATLAB 5.0 MAT-file"));
        check_sample(&m);
    }
}

#[test]
fn reads_from_disk_and_io_errors_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.mat");
    std::fs::write(&path, MatWriter::LE.file(&sample(), true)).unwrap();
    check_sample(&MatFile::read(&path).unwrap());
    let missing = dir.path().join("missing.mat");
    let e = MatFile::read(&missing).unwrap_err();
    assert!(matches!(e, DataError::Io { .. }));
    assert!(e.to_string().contains("missing.mat"), "{e}");
}

#[test]
fn narrower_storage_types_integers_singles_and_complex_convert_to_f64() {
    let w = MatWriter::LE;
    let vars = vec![
        (
            // MATLAB stores small whole doubles as uint8 to save space.
            "u8_as_double",
            MatArray::Typed {
                dims: vec![1, 3],
                class: MatArray::CLASS_DOUBLE,
                mi_type: MatArray::MI_UINT8,
                data: vec![0, 7, 255],
            },
        ),
        (
            "i16",
            MatArray::Typed {
                dims: vec![1, 2],
                class: MatArray::CLASS_INT16,
                mi_type: MatArray::MI_INT16,
                data: [(-300i16).to_le_bytes(), 12i16.to_le_bytes()].concat(),
            },
        ),
        (
            "single",
            MatArray::Typed {
                dims: vec![1, 1],
                class: MatArray::CLASS_SINGLE,
                mi_type: MatArray::MI_SINGLE,
                data: 1.5f32.to_le_bytes().to_vec(),
            },
        ),
        (
            "z",
            MatArray::Complex(vec![1, 2], vec![1.0, 2.0], vec![-1.0, 0.5]),
        ),
    ];
    let m = MatFile::from_bytes(&w.file(&vars, false), "t.mat").unwrap();
    assert_eq!(
        m.get("u8_as_double").unwrap().as_numeric().unwrap().real,
        [0.0, 7.0, 255.0]
    );
    let i16 = m.get("i16").unwrap().as_numeric().unwrap();
    assert_eq!(
        (i16.class, i16.real.as_slice()),
        (MatClass::Int16, [-300.0, 12.0].as_slice())
    );
    assert_eq!(m.get("single").unwrap().scalar(), Some(1.5));
    let z = m.get("z").unwrap().as_numeric().unwrap();
    assert_eq!(z.imag.as_deref(), Some([-1.0, 0.5].as_slice()));
}

#[test]
fn require_names_file_path_and_what_is_there() {
    let m = MatFile::from_bytes(&MatWriter::LE.file(&sample(), false), "dir/q.mat").unwrap();
    assert_eq!(m.require("take.FrameRate").unwrap().scalar(), Some(60.0));
    let e = m.require("take.RigidBodies").unwrap_err().to_string();
    assert_eq!(
        e,
        "dir/q.mat: field `take.RigidBodies`: no field `RigidBodies` in `take` (fields: FrameRate, Inner)"
    );
    let e = m.require("nope.x").unwrap_err().to_string();
    assert!(
        e.contains("no variable `nope` (variables: a, s, take)"),
        "{e}"
    );
    let e = m.require("a.x").unwrap_err().to_string();
    assert!(
        e.contains("`a` is a double of size 2x3, not a 1x1 struct"),
        "{e}"
    );
}

/// The error of reading corrupt `bytes` as `bad.mat`, which names the file.
fn read_err(bytes: &[u8]) -> String {
    match catch_unwind(AssertUnwindSafe(|| MatFile::from_bytes(bytes, "bad.mat"))) {
        Ok(Ok(_)) => panic!("corrupt input was accepted"),
        Ok(Err(e)) => {
            assert_names_file(&e, Path::new("bad.mat"));
            e.to_string()
        }
        Err(_) => panic!("reader panicked"),
    }
}

#[test]
fn header_problems_are_reported() {
    assert_eq!(read_err(b""), "bad.mat: field `header`: the file is empty");
    assert!(read_err(&[0u8; 100]).contains("shorter than the 128-byte"));
    let mut h = MatWriter::LE.header("MATLAB 5.0 MAT-file");
    h[126..128].copy_from_slice(b"XX");
    assert!(read_err(&h).contains("not a Level 5 MAT-file"));
    let mut h = MatWriter::LE.header("MATLAB 7.3 MAT-file, HDF5");
    h[126..128].copy_from_slice(b"\0\0");
    assert!(read_err(&h).contains("7.3 (HDF5) is not supported"));
    let mut h = MatWriter::LE.header("MATLAB 5.0 MAT-file");
    h[124] = 2;
    assert!(read_err(&h).contains("version 0x0102"));
    // A header alone is a valid file without variables.
    let m = MatFile::from_bytes(&MatWriter::LE.header("MATLAB 5.0 MAT-file"), "h.mat").unwrap();
    assert_eq!(m.variables().count(), 0);
}

#[test]
fn every_truncation_is_an_error_or_the_complete_variables_before_the_cut() {
    for compress in [false, true] {
        let bytes = MatWriter::LE.file(&sample(), compress);
        let full: Vec<_> = MatFile::from_bytes(&bytes, "bad.mat")
            .unwrap()
            .variables()
            .map(|(n, v)| (n.to_owned(), v.clone()))
            .collect();
        let mut errors = 0;
        for cut in 1..bytes.len() {
            let r = catch_unwind(AssertUnwindSafe(|| {
                MatFile::from_bytes(&bytes[..cut], "bad.mat")
            }));
            match r {
                Err(_) => panic!("reader panicked at cut {cut}"),
                Ok(Err(e)) => {
                    errors += 1;
                    assert_names_file(&e, Path::new("bad.mat"));
                }
                // A cut between two variables leaves a valid, shorter file (the format has no
                // variable count), and writers may omit the last element's padding.
                Ok(Ok(m)) => {
                    let got: Vec<_> = m
                        .variables()
                        .map(|(n, v)| (n.to_owned(), v.clone()))
                        .collect();
                    assert!(got.len() < full.len() || !compress, "cut {cut} accepted");
                    assert_eq!(got[..], full[..got.len()], "cut {cut}");
                }
            }
        }
        assert!(
            errors > bytes.len() - 16,
            "{errors} errors for {} cuts",
            bytes.len()
        );
    }
}

#[test]
fn truncation_inside_a_field_names_the_field() {
    let bytes = MatWriter::LE.file(&sample(), false);
    let e = read_err(&bytes[..bytes.len() - 20]);
    assert!(e.contains("field `take.Inner"), "{e}");
    assert!(e.contains("truncated"), "{e}");
}

#[test]
fn random_corruption_never_panics_and_errors_name_the_file() {
    // Deterministic LCG: no dependency and the same bytes every run.
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        seed >> 33
    };
    for compress in [false, true] {
        let bytes = MatWriter::LE.file(&sample(), compress);
        for _ in 0..3000 {
            let mut b = bytes.clone();
            for _ in 0..1 + next() % 3 {
                let i = 128 + next() as usize % (b.len() - 128);
                b[i] = next() as u8;
            }
            let r = catch_unwind(AssertUnwindSafe(|| MatFile::from_bytes(&b, "bad.mat")));
            match r {
                Ok(Ok(_)) => {}
                Ok(Err(e)) => {
                    assert_names_file(&e, Path::new("bad.mat"));
                }
                Err(_) => panic!("reader panicked on corrupt input"),
            }
        }
    }
}

#[test]
fn huge_declared_sizes_fail_fast_without_allocating() {
    let w = MatWriter::LE;
    // 100000 x 100000 doubles declared, 8 bytes present.
    let v = MatArray::Typed {
        dims: vec![100_000, 100_000],
        class: MatArray::CLASS_DOUBLE,
        mi_type: MatArray::MI_DOUBLE,
        data: 1.0f64.to_le_bytes().to_vec(),
    };
    let e = read_err(&w.file(&[("big", v)], false));
    assert!(
        e.contains("field `big`") && e.contains("10000000000 values"),
        "{e}"
    );
    // A cell of 2^31 - 1 elements with nothing in it.
    let mut body = w.matrix_body("c", &MatArray::Cell(vec![]));
    // Flags element (16 bytes), then the dimensions' 8-byte tag.
    let dims_at = 16 + 8;
    body[dims_at + 4..dims_at + 8].copy_from_slice(&i32::MAX.to_le_bytes());
    let mut bytes = w.header("MATLAB 5.0 MAT-file");
    bytes.extend(14u32.to_le_bytes());
    bytes.extend((body.len() as u32).to_le_bytes());
    bytes.extend(body);
    let e = read_err(&bytes);
    assert!(e.contains("elements declared"), "{e}");
}

#[test]
fn an_empty_char_array_of_many_rows_is_an_empty_text_at_once() {
    // Rows of no characters cost 8 bytes to declare: `cargo xtask fuzz mat` found 738,201,856
    // of them (tests/fuzz_found/mat), and the reader spent its 10 s writing that many line
    // breaks; here the most a MAT dimension holds.
    let v = MatArray::Typed {
        dims: vec![i32::MAX as usize, 0],
        class: MatArray::CLASS_CHAR,
        mi_type: MatArray::MI_UTF16,
        data: vec![],
    };
    let m = MatFile::from_bytes(&MatWriter::LE.file(&[("c", v)], false), "c.mat").unwrap();
    let c = m.get("c").unwrap();
    assert_eq!(c.dims(), [i32::MAX as usize, 0]);
    // The length only: a failure must not print two billion line breaks.
    assert_eq!(c.as_str().map(str::len), Some(0));
    // Rows with characters are still the rows of the text.
    let v = MatArray::Typed {
        dims: vec![2, 2],
        class: MatArray::CLASS_CHAR,
        mi_type: MatArray::MI_UTF16,
        data: "acbd".encode_utf16().flat_map(u16::to_le_bytes).collect(),
    };
    let m = MatFile::from_bytes(&MatWriter::LE.file(&[("c", v)], false), "c.mat").unwrap();
    assert_eq!(m.get("c").unwrap().as_str(), Some("ab\ncd"));
}

#[test]
fn nesting_is_limited() {
    let mut v = MatArray::Num(vec![1, 1], vec![1.0]);
    for _ in 0..MAX_DEPTH + 2 {
        v = MatArray::Cell(vec![v]);
    }
    let e = read_err(&MatWriter::LE.file(&[("deep", v)], false));
    assert!(e.contains("nested deeper than"), "{e}");
    let mut ok = MatArray::Num(vec![1, 1], vec![1.0]);
    for _ in 0..MAX_DEPTH {
        ok = MatArray::Cell(vec![ok]);
    }
    let m = MatFile::from_bytes(&MatWriter::LE.file(&[("deep", ok)], true), "ok.mat").unwrap();
    let mut v = m.get("deep").unwrap();
    while let MatValue::Cell(c) = v {
        v = &c.items[0];
    }
    assert_eq!(v.scalar(), Some(1.0));
}

#[test]
fn corrupt_zlib_stream_is_an_error() {
    let mut bytes = MatWriter::LE.file(&sample(), true);
    // Past the 2-byte zlib header of the first compressed element.
    for b in &mut bytes[128 + 8 + 4..128 + 8 + 24] {
        *b ^= 0x5a;
    }
    let e = read_err(&bytes);
    assert!(e.starts_with("bad.mat"), "{e}");
}
