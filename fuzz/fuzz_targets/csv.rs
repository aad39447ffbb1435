//! RIDI processed `data.csv` reader on arbitrary bytes.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use ridi_data::{ReadOptions, ridi_csv};

fuzz_target!(|data: &[u8]| {
    let _ = ridi_csv::parse(data, Path::new("fuzz/data.csv"), &ReadOptions::default());
});
