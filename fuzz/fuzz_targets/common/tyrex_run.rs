//! What the two Tyrex fuzz targets share: the input, split at NUL bytes, becomes the contents
//! of a run's `files` and then of its `.mat` ground truth, written into the dataset's layout
//! (`datasets/<layout>/<run>`, `datasets/qualisys/<run>.mat`) in a temp folder, and the run is
//! read.

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
    let mut parts = data.split(|&b| b == 0);
    for name in files {
        let content = parts.next().unwrap_or_default();
        if std::fs::write(run.join(name), content).is_err() {
            return;
        }
    }
    if let Some(mat) = parts.next() {
        let _ = std::fs::write(qualisys.join(format!("{run_name}.mat")), mat);
    }
    let _ = tyrex::read(&run, &TyrexOptions::default());
}
