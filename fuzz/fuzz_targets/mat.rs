//! MAT v5 reader: arbitrary bytes as a `.mat` file (headers, compressed elements, structs).
#![no_main]

use libfuzzer_sys::fuzz_target;
use ridi_data::MatFile;

fuzz_target!(|data: &[u8]| {
    if let Ok(file) = MatFile::from_bytes(data, "fuzz.mat") {
        // Walk what was decoded, as the Tyrex reader does.
        for (_, value) in file.variables() {
            let _ = value.lookup("RigidBodies.Positions");
        }
    }
});
