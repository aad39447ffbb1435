//! Indoor Location Competition path file reader on arbitrary bytes.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use ridi_data::ilc::{self, IlcOptions};

fuzz_target!(|data: &[u8]| {
    let _ = ilc::parse(data, Path::new("fuzz/path.txt"), &IlcOptions::default());
    let _ = ilc::looks_like_path_file(data);
});
