//! Tyrex iOS reader: the input is split at NUL bytes into the contents of an iPhone run's files
//! (accelerometer, gyroscope, attitude, description with its `BootTime`, time alignment, then
//! the `.mat` ground truth), written into the dataset's layout in a temp folder.
#![no_main]

use libfuzzer_sys::fuzz_target;
use ridi_data::tyrex::{self, TyrexOptions};

const FILES: [&str; 5] = [
    "accelerometer.txt",
    "gyroscope.txt",
    "attitude.txt",
    "description.txt",
    "timeAlignment.txt",
];

fuzz_target!(|data: &[u8]| {
    let Ok(root) = tempfile::tempdir() else {
        return;
    };
    let run = root.path().join("datasets/ios/A_iPhone4S_NoDist_Texting");
    let qualisys = root.path().join("datasets/qualisys");
    if std::fs::create_dir_all(&run).is_err() || std::fs::create_dir_all(&qualisys).is_err() {
        return;
    }
    let mut parts = data.split(|&b| b == 0);
    for name in FILES {
        let content = parts.next().unwrap_or_default();
        if std::fs::write(run.join(name), content).is_err() {
            return;
        }
    }
    if let Some(mat) = parts.next() {
        let _ = std::fs::write(qualisys.join("A_iPhone4S_NoDist_Texting.mat"), mat);
    }
    let _ = tyrex::read(&run, &TyrexOptions::default());
});
