//! RIDI raw folder reader: the input is split at NUL bytes into the contents of the raw files
//! (in `ridi_raw::FILES` order; missing parts mean missing files), written to a temp folder.
#![no_main]

use libfuzzer_sys::fuzz_target;
use ridi_data::{ReadOptions, ridi_raw};

fuzz_target!(|data: &[u8]| {
    let Ok(dir) = tempfile::tempdir() else {
        return;
    };
    for ((name, _), content) in ridi_raw::FILES.iter().zip(data.split(|&b| b == 0)) {
        if std::fs::write(dir.path().join(name), content).is_err() {
            return;
        }
    }
    // A small trim lets short inputs reach the synchronization code.
    let opts = ReadOptions {
        pose_trim: 2,
        ..ReadOptions::default()
    };
    let _ = ridi_raw::read(dir.path(), &opts);
});
