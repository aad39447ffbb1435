//! What the two Tyrex fuzz targets share: the input, split at its first NUL bytes, becomes the
//! contents of a run's `files` and then, everything after them (NUL bytes included: a MAT file
//! is full of them), of its `.mat` ground truth, written into the dataset's layout
//! (`datasets/<layout>/<run>`, `datasets/qualisys/<run>.mat`) in a temp folder, and the run is
//! read. Parts of half a second are kept (10 s by default), so that short inputs get through to
//! the alignment and the ground truth.

use ridi_data::tyrex::{self, TyrexOptions};

pub fn read_run(data: &[u8], layout: &str, run_name: &str, files: &[&str]) {
    let Ok(root) = tempfile::tempdir() else {
        return;
    };
    let run = root.path().join("datasets").join(layout).join(run_name);
    let qualisys = root.path().join("datasets/qualisys");
    if std::fs::create_dir_all(&run).is_err() || std::fs::create_dir_all(&qualisys).is_err() {
        return;
    }
    let mut parts = data.splitn(files.len() + 1, |&b| b == 0);
    for name in files {
        let content = parts.next().unwrap_or_default();
        if std::fs::write(run.join(name), content).is_err() {
            return;
        }
    }
    if let Some(mat) = parts.next() {
        let _ = std::fs::write(qualisys.join(format!("{run_name}.mat")), mat);
    }
    let opts = TyrexOptions {
        min_part_s: 0.5,
        ..TyrexOptions::default()
    };
    let _ = tyrex::read(&run, &opts);
}
