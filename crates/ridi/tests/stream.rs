//! Recordings read as streams against the same recordings read whole: a RIDI raw folder's
//! online track (trajectory CSV and plot) and inspection are those of its sequence read
//! whole, byte for byte; so is the plot of a streamed processed file. (Plots need the `plot`
//! feature, a default one.)
#![cfg(feature = "plot")]

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use ridi::data::{Format, ReadOptions, RoundTrip, RowReader, Sequence, write_ridi_csv};
use ridi::regress::{Cascade, NoProgress};
use ridi::{GridChoice, ReadFiles, TrackOptions, TrackOutput, TrainOptions};
use ridi_test_support::sample_dataset;

/// Two runs of the sample read whole.
fn sample(runs: &[&str]) -> Vec<Sequence> {
    runs.iter()
        .map(|r| ridi::data::read_sequence(sample_dataset().join(r), &ReadOptions::default()))
        .collect::<Result<_, _>>()
        .unwrap()
}

/// A small model: two runs of the sample, no grid search.
fn small_model() -> Cascade {
    let mut seqs = sample(&[
        "Jakob_Nexus5_NoDist_Swinging",
        "Jakob_Nexus5_NoDist_Texting",
    ]);
    seqs[0].set_placement(Some("swing".into()));
    seqs[1].set_placement(Some("hand".into()));
    let mut opts = TrainOptions::default();
    opts.cascade.regressors = GridChoice::None.regressors();
    ridi::train(&seqs, &opts, &mut NoProgress).unwrap()
}

/// Writes `seq` as a RIDI raw folder: every stream at its own frames' nanoseconds, the ground
/// truth as `pose.txt`, a step every second.
fn write_raw(seq: &Sequence, folder: &Path) {
    std::fs::create_dir_all(folder).unwrap();
    let r = RoundTrip;
    let ns: Vec<i64> = seq
        .time()
        .iter()
        .map(|t| (t * 1e9).round() as i64)
        .collect();
    let vectors = [
        ("gyro.txt", seq.gyro()),
        ("acce.txt", seq.acce()),
        ("linacce.txt", seq.linacce()),
        ("gravity.txt", seq.gravity()),
    ];
    for (name, values) in vectors {
        let mut text = String::from("# t x y z\n");
        for (t, v) in ns.iter().zip(values) {
            let _ = writeln!(text, "{t} {} {} {}", r(v.x()), r(v.y()), r(v.z()));
        }
        std::fs::write(folder.join(name), text).unwrap();
    }
    let mut rv = String::from("# t x y z w\n");
    for (t, q) in ns.iter().zip(seq.orientation()) {
        let [w, x, y, z] = q.to_wxyz();
        let _ = writeln!(rv, "{t} {} {} {} {}", r(x), r(y), r(z), r(w));
    }
    std::fs::write(folder.join("orientation.txt"), rv).unwrap();
    let gt = seq.ground_truth().unwrap();
    let mut pose = String::from("# t tx ty tz qx qy qz qw\n");
    for (i, t) in ns.iter().enumerate() {
        let (p, [w, x, y, z]) = (gt.position[i], gt.orientation[i].to_wxyz());
        let (px, py, pz) = (r(p.x()), r(p.y()), r(p.z()));
        let _ = writeln!(
            pose,
            "{t} {px} {py} {pz} {} {} {} {}",
            r(x),
            r(y),
            r(z),
            r(w)
        );
    }
    std::fs::write(folder.join("pose.txt"), pose).unwrap();
    let mut steps = String::from("# t count\n");
    for (k, t) in ns.iter().step_by(200).enumerate() {
        let _ = writeln!(steps, "{t} {k}");
    }
    std::fs::write(folder.join("step.txt"), steps).unwrap();
}

/// The online track of `source` written by `ridi track --online`'s two ways, streamed and
/// read whole (the model's orientation applied, as the command does), with an SVG plot: the
/// files of each, CSV then plot.
fn streamed_and_whole(source: &Path, model: &Cascade, dir: &Path) -> [(Vec<u8>, Vec<u8>); 2] {
    let opts = TrackOptions {
        online: true,
        ..TrackOptions::default()
    };
    let inputs = ReadFiles::of([&source.to_path_buf()]);
    let files = |name: &str| {
        (
            dir.join(format!("{name}.csv")),
            dir.join(format!("{name}.svg")),
        )
    };
    let output = |(csv, svg): &(PathBuf, PathBuf)| {
        TrackOutput::new(csv, &inputs)
            .unwrap()
            .with_plot(svg, &inputs)
            .unwrap()
    };
    let streamed = files("streamed");
    let rows = RowReader::open(source, &ReadOptions::default()).unwrap();
    output(&streamed).write_stream(rows, model, &opts).unwrap();

    let whole = files("whole");
    let mut loaded = ridi::read_any(source, None, &ReadOptions::default()).unwrap();
    ridi::apply_orientation(
        model.feature_config().orientation,
        opts.recorded_heading.as_ref(),
        &mut loaded.sequences,
    )
    .unwrap();
    let seq = &loaded.sequences[0];
    let track = ridi::track(seq, model, &opts).unwrap();
    output(&whole).write(seq, &track).unwrap();
    let read =
        |(csv, svg): (PathBuf, PathBuf)| (std::fs::read(csv).unwrap(), std::fs::read(svg).unwrap());
    [read(streamed), read(whole)]
}

#[test]
fn streamed_recordings_track_plot_and_inspect_as_read_whole() {
    let dir = tempfile::tempdir().unwrap();
    let model = small_model();
    let seq = &sample(&["Thibaud_Nexus5_NoDist_Swinging"])[0];

    // A raw folder: its track, plot and inspection.
    let raw = dir.path().join("Thibaud_raw");
    write_raw(seq, &raw);
    let [streamed, whole] = streamed_and_whole(&raw, &model, dir.path());
    let (csv, svg) = &streamed;
    // The pose trimmed by 800 records at each end: every kept frame has its row.
    assert_eq!(
        String::from_utf8_lossy(csv).lines().count(),
        seq.len() - 1600 + 1
    );
    assert!(String::from_utf8_lossy(svg).contains("ground truth"));
    assert!(streamed == whole, "the streamed track or plot differs");
    let read = ridi::data::ridi_raw::read(&raw, &ReadOptions::default()).unwrap();
    let rows = RowReader::open(&raw, &ReadOptions::default()).unwrap();
    let inspected = ridi::inspect_stream(rows).unwrap();
    assert_eq!(inspected, ridi::inspect(&read, Format::RidiRaw));
    assert!(inspected.has_steps && inspected.path_length_m.is_some());

    // A processed file's plot.
    let csv = dir.path().join("Thibaud.csv");
    write_ridi_csv(seq, &csv).unwrap();
    let [streamed, whole] = streamed_and_whole(&csv, &model, dir.path());
    let lines = String::from_utf8_lossy(&streamed.0).lines().count();
    assert_eq!(lines, seq.len() + 1);
    assert!(streamed == whole, "the streamed track or plot differs");
}

/// A streamed recording at another rate gets `track`'s error for it (with `ridi convert
/// --rate`), not the live tracker's check of its first second.
#[test]
fn a_streamed_recording_at_another_rate_gets_tracks_error() {
    let dir = tempfile::tempdir().unwrap();
    let model = small_model();
    let seq = &sample(&["Thibaud_Nexus5_NoDist_Swinging"])[0];
    let half = seq.resampled(100.0, 0.1).unwrap();
    let path = dir.path().join("half.csv");
    write_ridi_csv(&half, &path).unwrap();
    let opts = TrackOptions {
        online: true,
        ..TrackOptions::default()
    };
    let whole = ridi::track(&half, &model, &opts).unwrap_err().to_string();
    let inputs = ReadFiles::of([&path]);
    let rows = RowReader::open(&path, &ReadOptions::default()).unwrap();
    let out = dir.path().join("t.csv");
    let streamed = TrackOutput::new(&out, &inputs)
        .unwrap()
        .write_stream(rows, &model, &opts)
        .unwrap_err()
        .to_string();
    assert!(
        streamed.contains("has a rate of 100.0 Hz") && streamed.contains("ridi convert"),
        "{streamed}"
    );
    assert!(whole.contains("has a rate of 100.0 Hz"), "{whole}");
    assert!(!out.exists());
}
