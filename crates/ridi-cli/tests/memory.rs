//! Memory that does not grow with the input: `ridi track --online` and `ridi inspect` of a long
//! recording, generated here, run as a child whose peak resident memory (`wait4`) must stay
//! far below what reading the whole recording takes. Before streaming, 1 M rows took 493 MB to
//! inspect and 499 MB to track (500 k rows about half); streamed, 6-16 MB
//! (`docs/benchmarks.md`, "Memory of long recordings").

#![cfg(target_os = "linux")]

use std::io::Write as _;
use std::path::Path;
use std::process::{Command, Stdio};

use ridi_test_support::sample_dataset;

/// The bound every streamed command must stay under, bytes: a fifth of what reading the
/// whole of the shorter recording took.
const BOUND: u64 = 64 << 20;

/// Writes a RIDI `data.csv` of `rows` rows at 200 Hz: a phone lying still, shaking a little,
/// valid for every check of the reader (`benchmarks/long_recording.py` writes the same).
fn long_recording(path: &Path, rows: usize) {
    let bodies: Vec<String> = (0..1000)
        .map(|i| {
            let (s, c) = ((i as f64 * 0.0628).sin(), (i as f64 * 0.0377).cos());
            let gyro = [0.02 * s, 0.03 * c, 0.01 * s * c];
            let lin = [0.3 * s, 0.2 * c, 0.1 * s];
            let grav = [0.0, 9.8, 0.0];
            let acce = [grav[0] + lin[0], grav[1] + lin[1], grav[2] + lin[2]];
            let values: Vec<String> = [gyro, acce, lin, grav]
                .concat()
                .iter()
                .map(|v| format!("{v:.4}"))
                .collect();
            format!("{},1,0,0,0\n", values.join(","))
        })
        .collect();
    let file = std::fs::File::create(path).unwrap();
    let mut w = std::io::BufWriter::with_capacity(1 << 20, file);
    w.write_all(
        b",time,gyro_x,gyro_y,gyro_z,acce_x,acce_y,acce_z,linacce_x,linacce_y,linacce_z,\
          grav_x,grav_y,grav_z,rv_w,rv_x,rv_y,rv_z\n",
    )
    .unwrap();
    for i in 0..rows {
        let t = 1_000_000_000u64 + 5_000_000 * i as u64;
        write!(w, "{i},{t},{}", bodies[i % 1000]).unwrap();
    }
    w.flush().unwrap();
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

#[test]
fn inspect_of_a_million_rows_runs_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("long.csv");
    long_recording(&csv, 1_000_000);
    let (ok, err, peak) = peak_memory(&["inspect", csv.to_str().unwrap()], dir.path());
    assert!(ok, "{err}");
    assert!(
        peak < BOUND,
        "ridi inspect of 1 M rows peaked at {} MiB (bound {} MiB)",
        peak >> 20,
        BOUND >> 20
    );
}

#[test]
fn online_track_of_half_a_million_rows_runs_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    // A small model: two runs of the sample, no grid search.
    let list = dir.path().join("list.txt");
    let runs = [
        "Jakob_Nexus5_NoDist_Swinging",
        "Jakob_Nexus5_NoDist_Texting",
    ];
    let lines: Vec<String> = runs
        .iter()
        .map(|r| format!("{},{}\n", sample_dataset().join(r).display(), &r[20..]))
        .collect();
    std::fs::write(&list, lines.concat()).unwrap();
    let model = dir.path().join("m.ridi");
    let out = Command::new(env!("CARGO_BIN_EXE_ridi"))
        .args(["train", "--list", list.to_str().unwrap()])
        .args(["--out", model.to_str().unwrap(), "--grid", "none"])
        .output()
        .expect("run ridi");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    // 500 k rows: 16 s in the dev profile; whole, the recording took about 250 MB.
    let csv = dir.path().join("long.csv");
    long_recording(&csv, 500_000);
    let traj = dir.path().join("traj.csv");
    let args = [
        "track",
        csv.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
        "--online",
        "--out",
        traj.to_str().unwrap(),
    ];
    let (ok, err, peak) = peak_memory(&args, dir.path());
    assert!(ok, "{err}");
    assert!(
        peak < BOUND,
        "ridi track --online of 500 k rows peaked at {} MiB (bound {} MiB)",
        peak >> 20,
        BOUND >> 20
    );
    // Every frame has its row, after the header.
    let text = std::fs::read_to_string(&traj).unwrap();
    assert_eq!(text.lines().count(), 500_001);
}
