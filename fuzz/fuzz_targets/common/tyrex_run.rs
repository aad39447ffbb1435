//! What the two Tyrex fuzz targets share: the input, split at its first NUL bytes, becomes the
//! contents of a run's `files` and then, everything after them (NUL bytes included: a MAT file
//! is full of them), of its `.mat` ground truth, written into the dataset's layout
//! (`datasets/<layout>/<run>`, `datasets/qualisys/<run>.mat`) in a temp folder, and the run is
//! read. Parts of half a second are kept (10 s by default), so that short inputs get through to
//! the alignment and the ground truth.
//!
//! `cargo xtask fuzz`'s tests include this very file (`#[path]`) to check that its seeds are
//! valid runs.

use ridi_data::tyrex::{self, TyrexOptions, TyrexRead};

/// A run the input is laid out as: `datasets/<layout>/<name>` with `files`, in the order the
/// input gives their contents.
pub struct Run {
    pub layout: &'static str,
    pub name: &'static str,
    pub files: &'static [&'static str],
}

/// The run of the `tyrex` target: an Android one.
#[allow(dead_code, reason = "the `tyrex_ios` target has its own")]
pub const ANDROID: Run = Run {
    layout: "android",
    name: "A_Nexus5_NoDist_Texting",
    files: &[
        "accelerometer.txt",
        "gyroscope-calibrated.txt",
        "rotation-vector.txt",
        "timeAlignment.txt",
    ],
};

/// The run of the `tyrex_ios` target: an iPhone one.
#[allow(dead_code, reason = "the `tyrex` target has its own")]
pub const IOS: Run = Run {
    layout: "ios",
    name: "A_iPhone4S_NoDist_Texting",
    files: &[
        "accelerometer.txt",
        "gyroscope.txt",
        "attitude.txt",
        "description.txt",
        "timeAlignment.txt",
    ],
};

/// The targets' entry point: [`try_read_run`], whatever it returns.
pub fn read_run(data: &[u8], run: &Run) {
    let _ = try_read_run(data, run);
}

/// Lays `data` out as `run` and reads it; an error of the temp folder is the `Err` of an I/O
/// error, as the reader's own.
pub fn try_read_run(data: &[u8], run: &Run) -> Result<TyrexRead, Box<dyn std::error::Error>> {
    let Run {
        layout,
        name: run_name,
        files,
    } = *run;
    let root = tempfile::tempdir()?;
    let run = root.path().join("datasets").join(layout).join(run_name);
    let qualisys = root.path().join("datasets/qualisys");
    std::fs::create_dir_all(&run)?;
    std::fs::create_dir_all(&qualisys)?;
    let mut parts = data.splitn(files.len() + 1, |&b| b == 0);
    for name in files {
        std::fs::write(run.join(name), parts.next().unwrap_or_default())?;
    }
    if let Some(mat) = parts.next() {
        std::fs::write(qualisys.join(format!("{run_name}.mat")), mat)?;
    }
    let opts = TyrexOptions {
        min_part_s: 0.5,
        ..TyrexOptions::default()
    };
    Ok(tyrex::read(&run, &opts)?)
}
