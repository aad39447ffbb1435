//! RoNIN reader: the first two bytes are the length of an `info.json` (little-endian), which
//! follows them; the rest is the `data.hdf5` (`ronin::parse`, and the HDF5 reader,
//! `Hdf5File`, on the datasets RoNIN's files hold). A seed: the two bytes, then
//! `crates/ridi-data/tests/ronin/a000_1/info.json` and `data.hdf5`.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use ridi_data::Hdf5File;
use ridi_data::ronin::{self, RoninOptions};

fuzz_target!(|data: &[u8]| {
    let Some((len, rest)) = data.split_first_chunk::<2>() else {
        return;
    };
    let n = usize::from(u16::from_le_bytes(*len)).min(rest.len());
    let (info, h5) = rest.split_at(n);
    if let Ok(file) = Hdf5File::from_bytes(h5.to_vec(), "data.hdf5") {
        for name in [
            "synced/time",
            "synced/acce",
            "pose/tango_ori",
            "raw/imu/wifi_address",
            "/",
        ] {
            let _ = file.read_f64(name);
        }
    }
    let _ = ronin::parse(
        h5.to_vec(),
        info,
        Path::new("a000_1"),
        &RoninOptions::default(),
    );
});
