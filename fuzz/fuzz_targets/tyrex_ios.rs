//! Tyrex iOS reader: the input is split at its first NUL bytes into the contents of an iPhone
//! run's files (accelerometer, gyroscope, attitude, description with its `BootTime`, time
//! alignment, then the rest: the `.mat` ground truth), written into the dataset's layout in a
//! temp folder.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "common/tyrex_run.rs"]
mod tyrex_run;

fuzz_target!(|data: &[u8]| {
    tyrex_run::read_run(data, &tyrex_run::IOS);
});
