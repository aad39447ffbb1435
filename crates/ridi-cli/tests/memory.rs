//! Memory that does not grow with the input: `ridi track --online` (with and without a plot)
//! and `ridi inspect` of a long recording, a RIDI `data.csv` or raw folder generated here, run
//! as a child whose peak resident memory (`wait4`) must stay far below what reading the whole
//! recording takes. Before streaming, 1 M rows took 493 MB to inspect and 499 MB to track
//! (500 k rows about half), a raw folder of 500 k records a file 289 MB to inspect and one of
//! 250 k 146 MB to track with a plot; streamed, 6-16 MB, and with a plot what its points take,
//! at most 2^18 frames' (`docs/benchmarks.md`, "Memory of long recordings"). A child's peak counts its parent's
//! (see [`count_lines`]): this process holds no long output.

#![cfg(target_os = "linux")]

use std::io::Write as _;
use std::path::Path;
use std::process::{Command, Stdio};

use ridi_test_support::sample_dataset;

/// The bound every streamed command must stay under, bytes: a fifth of what reading the
/// whole of the shorter recording took.
const BOUND: u64 = 64 << 20;

/// One period of the long recordings' phone, lying still and shaking a little (valid for
/// every check of the readers): gyro, accelerometer, linear acceleration and gravity of 1000
/// frames (`benchmarks/long_recording.py` writes the same).
fn phone() -> Vec<[[f64; 3]; 4]> {
    (0..1000)
        .map(|i| {
            let (s, c) = ((i as f64 * 0.0628).sin(), (i as f64 * 0.0377).cos());
            let gyro = [0.02 * s, 0.03 * c, 0.01 * s * c];
            let lin = [0.3 * s, 0.2 * c, 0.1 * s];
            let grav = [0.0, 9.8, 0.0];
            let acce = [grav[0] + lin[0], grav[1] + lin[1], grav[2] + lin[2]];
            [gyro, acce, lin, grav]
        })
        .collect()
}

/// The quaternion components of the upright phone's orientation (a turn by 90 degrees about
/// x, taking its y axis, along gravity, up).
const UPRIGHT: f64 = std::f64::consts::FRAC_1_SQRT_2;

/// The time of the long recordings' frame `i` at 200 Hz, nanoseconds.
fn ns(i: usize) -> u64 {
    1_000_000_000 + 5_000_000 * i as u64
}

/// `values` as the long recordings write them, joined by `sep`.
fn cells(values: &[f64], sep: &str) -> String {
    let cells: Vec<String> = values.iter().map(|v| format!("{v:.4}")).collect();
    cells.join(sep)
}

/// A file `path` of large buffered writes.
fn create(path: &Path) -> std::io::BufWriter<std::fs::File> {
    std::io::BufWriter::with_capacity(1 << 20, std::fs::File::create(path).unwrap())
}

/// Writes a RIDI `data.csv` of `rows` rows at 200 Hz: the [`phone`].
fn long_recording(path: &Path, rows: usize) {
    let bodies: Vec<String> = phone()
        .iter()
        // Upright (y up, along gravity): rv_w rv_x rv_y rv_z of a turn by 90 degrees about x.
        .map(|f| format!("{},{UPRIGHT},{UPRIGHT},0,0\n", cells(&f.concat(), ",")))
        .collect();
    let mut w = create(path);
    w.write_all(
        b",time,gyro_x,gyro_y,gyro_z,acce_x,acce_y,acce_z,linacce_x,linacce_y,linacce_z,\
          grav_x,grav_y,grav_z,rv_w,rv_x,rv_y,rv_z\n",
    )
    .unwrap();
    for i in 0..rows {
        write!(w, "{i},{},{}", ns(i), bodies[i % 1000]).unwrap();
    }
    w.flush().unwrap();
}

/// Writes a RIDI raw folder of `rows` records per file at 200 Hz: the [`phone`], its rotation
/// vector still, and a still pose as the clock (the pose's trim leaves `rows - 1600` frames).
fn long_raw_folder(folder: &Path, rows: usize) {
    std::fs::create_dir_all(folder).unwrap();
    let frames = phone();
    let files = ["gyro.txt", "acce.txt", "linacce.txt", "gravity.txt"];
    for (k, name) in files.into_iter().enumerate() {
        let bodies: Vec<String> = frames.iter().map(|f| cells(&f[k], " ")).collect();
        let mut w = create(&folder.join(name));
        w.write_all(b"# t x y z\n").unwrap();
        for i in 0..rows {
            writeln!(w, "{} {}", ns(i), bodies[i % 1000]).unwrap();
        }
        w.flush().unwrap();
    }
    let upright_xyzw = format!("{UPRIGHT} 0 0 {UPRIGHT}");
    for (name, header, values) in [
        ("orientation.txt", "# t x y z w", upright_xyzw),
        (
            "pose.txt",
            "# t tx ty tz qx qy qz qw",
            "1.5 -2 1.2 0 0 0 1".into(),
        ),
    ] {
        let mut w = create(&folder.join(name));
        writeln!(w, "{header}").unwrap();
        for i in 0..rows {
            writeln!(w, "{} {values}", ns(i)).unwrap();
        }
        w.flush().unwrap();
    }
}

/// The lines of the file at `path`, counted without holding it: this process's own peak
/// memory counts in its children's (a spawned child's `ru_maxrss` starts from the peak of the
/// address space it was spawned from), so no test here reads a long output whole.
fn count_lines(path: &Path) -> usize {
    use std::io::BufRead as _;
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    file.split(b'\n').count()
}

/// Whether the file at `path` holds `needle`, read in blocks (see [`count_lines`]).
fn holds(path: &Path, needle: &[u8]) -> bool {
    use std::io::Read as _;
    let mut file = std::fs::File::open(path).unwrap();
    let mut window = Vec::new();
    let mut block = vec![0; 1 << 16];
    loop {
        let n = file.read(&mut block).unwrap();
        if n == 0 {
            return false;
        }
        window.extend_from_slice(&block[..n]);
        if window.windows(needle.len()).any(|w| w == needle) {
            return true;
        }
        window.drain(..window.len().saturating_sub(needle.len()));
    }
}

/// Runs `ridi args` to its end; its exit success, stderr and peak resident memory, bytes.
// `wait4` reaps the child (and gives its own peak memory, which `getrusage(RUSAGE_CHILDREN)`
// would mix with the other tests' children); `Child::wait` after it could reap another child.
#[allow(clippy::zombie_processes)]
fn peak_memory(args: &[&str], dir: &Path) -> (bool, String, u64) {
    let err = dir.join("stderr.txt");
    let child = Command::new(env!("CARGO_BIN_EXE_ridi"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&err).unwrap())
        .spawn()
        .expect("run ridi");
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    // SAFETY: a plain system call on our own child, with valid pointers to locals.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let waited = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    assert_eq!(waited, pid, "wait4");
    let success = libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0;
    // Linux counts ru_maxrss in KiB.
    let peak = usage.ru_maxrss as u64 * 1024;
    (success, std::fs::read_to_string(err).unwrap(), peak)
}

/// Runs `ridi args` in `dir` to its end, which must be a success peaking under [`BOUND`].
fn assert_bounded(args: &[&str], dir: &Path) {
    let (ok, err, peak) = peak_memory(args, dir);
    assert!(ok, "{err}");
    assert!(
        peak < BOUND,
        "ridi {} peaked at {} MiB (bound {} MiB)",
        args.join(" "),
        peak >> 20,
        BOUND >> 20
    );
}

#[test]
fn inspect_of_a_million_rows_runs_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("long.csv");
    long_recording(&csv, 1_000_000);
    assert_bounded(&["inspect", csv.to_str().unwrap()], dir.path());
}

#[test]
fn inspect_of_a_raw_folder_of_half_a_million_rows_runs_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("long");
    long_raw_folder(&raw, 500_000);
    assert_bounded(&["inspect", raw.to_str().unwrap()], dir.path());
}

/// Trains a small model in `dir`: two runs of the sample, no grid search.
fn small_model(dir: &Path) -> std::path::PathBuf {
    let list = dir.join("list.txt");
    let runs = [
        "Jakob_Nexus5_NoDist_Swinging",
        "Jakob_Nexus5_NoDist_Texting",
    ];
    let lines: Vec<String> = runs
        .iter()
        .map(|r| format!("{},{}\n", sample_dataset().join(r).display(), &r[20..]))
        .collect();
    std::fs::write(&list, lines.concat()).unwrap();
    let model = dir.join("m.ridi");
    let out = Command::new(env!("CARGO_BIN_EXE_ridi"))
        .args(["train", "--list", list.to_str().unwrap()])
        .args(["--out", model.to_str().unwrap(), "--grid", "none"])
        .output()
        .expect("run ridi");
    assert!(out.status.success(), "{}", ridi_test_support::stderr(&out));
    model
}

/// Tracks `source` in `dir` online with a model and an SVG plot, within [`BOUND`]; the
/// trajectory CSV's line count and the plot.
fn track_online_with_plot(source: &Path, dir: &Path) -> (usize, std::path::PathBuf) {
    let model = small_model(dir);
    let traj = dir.join("traj.csv");
    let plot = dir.join("traj.svg");
    let args = [
        "track",
        source.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
        "--online",
        "--out",
        traj.to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
    ];
    assert_bounded(&args, dir);
    (count_lines(&traj), plot)
}

#[test]
fn online_track_of_half_a_million_rows_runs_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    // 500 k rows: 3 s in the dev profile; whole, the recording took about 250 MB. Nearly twice
    // the frames a plot keeps (ridi's PLOT_FRAMES): its points are thinned, not grown.
    let csv = dir.path().join("long.csv");
    long_recording(&csv, 500_000);
    let (lines, plot) = track_online_with_plot(&csv, dir.path());
    // Every frame has its row, after the header.
    assert_eq!(lines, 500_001);
    assert!(holds(&plot, b"<svg"), "no plot");
}

#[test]
fn online_track_of_a_raw_folder_with_a_plot_runs_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    // 250 k records a file: 3 s in the dev profile; whole, the folder took about 145 MB. The
    // plot keeps 40 bytes a frame, every frame of these (10 MB).
    let raw = dir.path().join("long");
    long_raw_folder(&raw, 250_000);
    let (lines, plot) = track_online_with_plot(&raw, dir.path());
    assert_eq!(lines, 250_000 - 1600 + 1);
    assert!(
        holds(&plot, b"ground truth"),
        "the plot has no ground truth"
    );
}
