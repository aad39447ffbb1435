//! Tyrex reader: the input is split at its first NUL bytes into the contents of a run's files
//! (accelerometer, calibrated gyroscope, rotation vector, time alignment, then the rest: the
//! `.mat` ground truth), written into the benchmark's layout in a temp folder.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "common/tyrex_run.rs"]
mod tyrex_run;

fuzz_target!(|data: &[u8]| {
    tyrex_run::read_run(data, &tyrex_run::ANDROID);
});
