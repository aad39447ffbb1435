//! RIDI `data_plain.txt` reader on arbitrary bytes.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use ridi_data::{ReadOptions, ridi_plain};

fuzz_target!(|data: &[u8]| {
    let _ = ridi_plain::parse(
        data,
        Path::new("fuzz/data_plain.txt"),
        &ReadOptions::default(),
    );
});
