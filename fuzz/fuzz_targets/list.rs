//! Dataset list parser on arbitrary bytes.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = ridi_data::parse_list(data, Path::new("/fuzz/list.txt"));
});
