//! `ridi convert` on bad input: a failed conversion leaves nothing behind, and a source of
//! another format than the one given says what it is and what was expected.

use std::path::{Path, PathBuf};

use ridi::data::{
    Format, GroundTruth, ReadOptions, Sequence, SequenceError, SequenceParts, read_sequence,
    write_ridi_csv, write_ridi_plain,
};
use ridi::{ConvertOptions, convert};
use ridi_test_support::{file_names, sample_dataset};

fn seq(name: &str) -> PathBuf {
    sample_dataset().join(name)
}

/// `dir/src` with one RIDI capture (a copy of a sample run) per name.
fn sources_named(dir: &Path, names: &[&str]) -> PathBuf {
    let src = dir.join("src");
    let s = read_sequence(
        seq("Thibaud_Nexus5_NoDist_Texting"),
        &ReadOptions::default(),
    )
    .unwrap();
    for name in names {
        let folder = src.join(name).join("processed");
        std::fs::create_dir_all(&folder).unwrap();
        write_ridi_csv(&s, folder.join("data.csv")).unwrap();
    }
    src
}

/// A folder of three RIDI captures, the second with a NaN on line 301 of its data.csv.
fn three_sources(dir: &Path) -> PathBuf {
    let src = sources_named(dir, &["a_seq", "b_seq", "c_seq"]);
    let bad = src.join("b_seq/processed/data.csv");
    let text = std::fs::read_to_string(&bad).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut cells: Vec<&str> = lines[300].split(',').collect();
    cells[3] = "NaN";
    lines[300] = cells.join(",");
    std::fs::write(&bad, lines.join("\n") + "\n").unwrap();
    src
}

fn files_under(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    if dir.is_dir() {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            out.push(p.display().to_string());
            out.extend(files_under(&p));
        }
    }
    out.sort();
    out
}

#[test]
fn a_bad_source_leaves_no_conversion_behind() {
    let dir = tempfile::tempdir().unwrap();
    let src = three_sources(dir.path());
    let opts = ReadOptions::default();
    // A new output folder (and its parent) is not left behind.
    let out = dir.path().join("new/conv");
    let e = convert(&src, &out, &ConvertOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("b_seq/processed/data.csv:301: field `gyro_y`"),
        "{e}"
    );
    assert!(!dir.path().join("new").exists());
    // An existing one keeps what it had, and only that.
    let out = dir.path().join("conv");
    std::fs::create_dir_all(out.join("a_seq/processed")).unwrap();
    std::fs::write(out.join("a_seq/processed/data.csv"), "old").unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let before = files_under(&out);
    assert!(convert(&src, &out, &ConvertOptions::default()).is_err());
    assert_eq!(files_under(&out), before);
    assert_eq!(
        std::fs::read_to_string(out.join("a_seq/processed/data.csv")).unwrap(),
        "old"
    );
    // Without the bad source, everything is written, replacing the old file.
    std::fs::remove_dir_all(src.join("b_seq")).unwrap();
    let summary = convert(&src, &out, &ConvertOptions::default()).unwrap();
    assert_eq!(summary.sequences.len(), 2);
    // The sample's runs name their phone, so the device's list comes too.
    assert_eq!(
        summary.lists,
        [out.join("list_all.txt"), out.join("list_nexus5.txt")]
    );
    let names: Vec<String> = files_under(&out)
        .iter()
        .map(|p| p.strip_prefix(&*out.to_string_lossy()).unwrap().to_string())
        .collect();
    assert_eq!(
        names,
        [
            "/a_seq",
            "/a_seq/processed",
            "/a_seq/processed/data.csv",
            "/a_seq/processed/data.csv.meta",
            "/c_seq",
            "/c_seq/processed",
            "/c_seq/processed/data.csv",
            "/c_seq/processed/data.csv.meta",
            "/list_all.txt",
            "/list_nexus5.txt",
            "/notes.txt"
        ]
    );
    assert!(read_sequence(out.join("a_seq"), &opts).is_ok());
}

#[test]
fn a_source_of_another_format_than_given_says_what_it_is_and_what_was_expected() {
    let dir = tempfile::tempdir().unwrap();
    let opts = ReadOptions::default();
    let csv = dir.path().join("texting.csv");
    let s = read_sequence(seq("Thibaud_Nexus5_NoDist_Texting"), &opts).unwrap();
    write_ridi_csv(&s, &csv).unwrap();
    let out = dir.path().join("c");
    // The error of converting `source` as `from`, which must contain `want`.
    let fails = |source: &Path, from: Format, want: &str| {
        let e = convert(
            source,
            &out,
            &ConvertOptions {
                from: Some(from),
                ..ConvertOptions::default()
            },
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains(want), "{e}");
        e
    };
    let e = fails(
        &csv,
        Format::Tyrex,
        "texting.csv: not a Tyrex folder (it is a RIDI processed csv): a Tyrex run is a folder",
    );
    assert!(
        e.contains("accelerometer.txt") && e.contains("datasets/android/"),
        "{e}"
    );
    fails(
        &csv,
        Format::RidiRaw,
        "not a RIDI raw folder (it is a RIDI processed csv): a RIDI raw folder holds gyro.txt",
    );
    fails(
        &csv,
        Format::Ilc,
        "not an Indoor Location Competition path file (it is a RIDI processed csv)",
    );
    // A sample capture folder is a RIDI csv, not a raw folder: nothing raw in it.
    fails(
        &seq("Thibaud_Nexus5_NoDist_Texting"),
        Format::RidiRaw,
        "not a RIDI raw folder (it is a RIDI processed csv)",
    );
    fails(
        &dir.path().join("nowhere"),
        Format::Tyrex,
        "nowhere: not a Tyrex folder (no such file or folder): a Tyrex run is",
    );
    // An empty folder given as raw names every raw file it lacks.
    let empty = dir.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let e = ridi::read_any(&empty, Some(Format::RidiRaw), &opts)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(
            "RIDI raw folder without gyro.txt, acce.txt, linacce.txt, gravity.txt, orientation.txt"
        ),
        "{e}"
    );
    // The failures left nothing; the right format converts, and `ridi-csv` takes a
    // data_plain.txt too.
    assert!(!out.exists());
    let plain = dir.path().join("plain/data_plain.txt");
    std::fs::create_dir_all(plain.parent().unwrap()).unwrap();
    write_ridi_plain(&s, &plain).unwrap();
    for source in [&csv, &plain] {
        let summary = convert(
            source,
            &out,
            &ConvertOptions {
                from: Some(Format::RidiCsv),
                ..ConvertOptions::default()
            },
        )
        .unwrap();
        assert_eq!(summary.sequences[0].frames, s.len());
    }
    // Two lists, and per sequence its folder, `processed`, the data and its sidecar.
    let files = files_under(&out);
    assert_eq!(files.len(), 10, "{files:?}");
    assert!(!files.iter().any(|f| f.contains("staging")), "{files:?}");
    // A folder with both processed files reads its data.csv unless data_plain.txt is asked for.
    let both = dir.path().join("both");
    std::fs::create_dir_all(both.join("processed")).unwrap();
    write_ridi_csv(&s, both.join("processed/data.csv")).unwrap();
    write_ridi_plain(&s.slice(0..1000), both.join("processed/data_plain.txt")).unwrap();
    let frames = |from| {
        let loaded = ridi::read_any(&both, from, &opts).unwrap();
        (loaded.format, loaded.sequences[0].len())
    };
    assert_eq!(frames(None), (Format::RidiCsv, s.len()));
    assert_eq!(frames(Some(Format::RidiCsv)), (Format::RidiCsv, s.len()));
    assert_eq!(frames(Some(Format::RidiPlain)), (Format::RidiPlain, 1000));
    // Read to be split at its gaps too.
    let split = ridi::read_split(&both, Some(Format::RidiPlain), &opts, 0.1).unwrap();
    assert_eq!(split.format, Format::RidiPlain);
    assert_eq!(split.sequences[0].len(), 1000);
}

#[test]
fn list_labels_in_the_source_carry_over_and_a_folder_of_another_format_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let src = sources_named(dir.path(), &["walk_a", "walk_b", "walk_c"]);
    // The RIDI layout keeps labels in list files beside the sequences; a licence is no list,
    // and a second list that disagrees keeps the first label with a warning.
    std::fs::write(src.join("LICENCE.txt"), "Permission is granted...\n").unwrap();
    std::fs::write(src.join("list_a.txt"), "walk_a,Texting\nwalk_b,Pocket\n").unwrap();
    std::fs::write(src.join("list_b.txt"), "# other\nwalk_b,Swinging\n").unwrap();

    let out = dir.path().join("out");
    let summary = convert(&src, &out, &ConvertOptions::default()).unwrap();
    let labels: Vec<(&str, Option<&str>)> = summary
        .sequences
        .iter()
        .map(|c| (c.name.as_str(), c.placement.as_deref()))
        .collect();
    assert_eq!(
        labels,
        [
            ("walk_a", Some("Texting")),
            ("walk_b", Some("Pocket")),
            ("walk_c", None)
        ]
    );
    assert!(
        summary.warnings.iter().any(
            |w| w.contains("list_b.txt:2: placement `Swinging`") && w.contains("kept `Pocket`")
        ),
        "{:?}",
        summary.warnings
    );
    let list = std::fs::read_to_string(out.join("list_all.txt")).unwrap();
    assert!(
        list.contains("\nwalk_a,Texting\nwalk_b,Pocket\nwalk_c,\n"),
        "{list}"
    );

    // Converting into the source folder would replace the lists it read: refused, and the
    // folder stays as it was.
    let before = std::fs::read_to_string(src.join("list_a.txt")).unwrap();
    let e = convert(&src, &src, &ConvertOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(": cannot write it: the command reads it; choose an --out outside the source"),
        "{e}"
    );
    assert_eq!(
        std::fs::read_to_string(src.join("list_a.txt")).unwrap(),
        before
    );
    assert!(!src.join("list_all.txt").exists());
    let left: Vec<_> = file_names(&src)
        .into_iter()
        .filter(|n| n.starts_with(".ridi-staging"))
        .collect();
    assert!(left.is_empty(), "{left:?}");

    // Asked for another format, the folder says what it holds.
    for from in [Format::Tyrex, Format::Ilc, Format::RidiRaw] {
        let e = convert(
            &src,
            &dir.path().join("x"),
            &ConvertOptions {
                from: Some(from),
                ..ConvertOptions::default()
            },
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("but 3 sources of another format")
                && e.contains(
                    "is a RIDI processed csv): convert without --from, or with --from ridi-csv"
                ),
            "{e}"
        );
    }
}

#[test]
fn rate_resamples_every_sequence_and_refuses_to_fill_gaps() {
    let dir = tempfile::tempdir().unwrap();
    let opts = ReadOptions::default();
    let full = read_sequence(seq("Thibaud_Nexus5_NoDist_Texting"), &opts).unwrap();
    // The same walk logged at 100 Hz: every other frame.
    let keep: Vec<usize> = (0..full.len()).step_by(2).collect();
    let at_100 = |keep: &[usize]| {
        let p = full.parts();
        let pick = |v: &[ridi::frames::DeviceVec]| keep.iter().map(|&i| v[i]).collect();
        let gt = p.ground_truth.as_ref().unwrap();
        Sequence::new(SequenceParts {
            time: keep.iter().map(|&i| p.time[i]).collect(),
            gyro: pick(&p.gyro),
            acce: pick(&p.acce),
            linacce: pick(&p.linacce),
            gravity: pick(&p.gravity),
            orientation: keep.iter().map(|&i| p.orientation[i]).collect(),
            ground_truth: Some(GroundTruth {
                position: keep.iter().map(|&i| gt.position[i]).collect(),
                orientation: keep.iter().map(|&i| gt.orientation[i]).collect(),
            }),
            ..p.clone()
        })
        .unwrap()
    };
    let slow = at_100(&keep);
    let src = dir.path().join("src/walk/processed");
    std::fs::create_dir_all(&src).unwrap();
    write_ridi_csv(&slow, src.join("data.csv")).unwrap();

    let out = dir.path().join("out");
    let to_200 = ConvertOptions {
        rate_hz: Some(200.0),
        ..ConvertOptions::default()
    };
    convert(&dir.path().join("src"), &out, &to_200).unwrap();
    let back = read_sequence(out.join("walk"), &opts).unwrap();
    assert!(
        (back.median_rate_hz() - 200.0).abs() < 0.01,
        "{}",
        back.median_rate_hz()
    );
    assert!(
        back.len() >= 2 * slow.len() - 2,
        "{} from {}",
        back.len(),
        slow.len()
    );
    // Interpolation reproduces the 200 Hz original closely between the 100 Hz samples.
    let n = back.len().min(full.len());
    let worst = (0..n)
        .map(|i| (back.acce()[i] - full.acce()[i]).norm())
        .fold(0.0, f64::max);
    assert!(worst < 3.0, "{worst}");
    // At the 100 Hz samples themselves, the values are the recorded ones.
    for i in (0..n).step_by(2) {
        let d = (back.acce()[i] - full.acce()[i]).norm();
        assert!(d < 1e-4, "frame {i}: {d}");
    }
    assert!((back.time()[0] - full.time()[0]).abs() < 1e-6);

    // A 0.1 s gap (10 frame intervals at 100 Hz) would be filled with invented frames.
    let gappy: Vec<usize> = keep
        .iter()
        .copied()
        .filter(|i| !(1000..1020).contains(i))
        .collect();
    write_ridi_csv(&at_100(&gappy), src.join("data.csv")).unwrap();
    let e = convert(&dir.path().join("src"), &dir.path().join("out2"), &to_200)
        .unwrap_err()
        .to_string();
    assert!(e.contains("gap of 0.110 s") && e.contains("walk"), "{e}");

    // Split there first, it converts: two parts, each resampled, tracked as they are, the
    // frames on either side of the gap where they were.
    let split = ConvertOptions {
        split_at_gaps_s: Some(0.1),
        ..to_200.clone()
    };
    let out3 = dir.path().join("out3");
    let summary = convert(&dir.path().join("src"), &out3, &split).unwrap();
    let names: Vec<&str> = summary.sequences.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["walk_part1", "walk_part2"]);
    assert!(
        summary
            .warnings
            .iter()
            .any(|w| w.ends_with("sequence `walk`: split at 1 gap longer than 0.1 s; 2 parts kept")),
        "{:?}",
        summary.warnings
    );
    let (a, b) = (
        read_sequence(out3.join("walk_part1"), &opts).unwrap(),
        read_sequence(out3.join("walk_part2"), &opts).unwrap(),
    );
    let gap_from = (full.time()[998], full.time()[1020]);
    assert!(
        (a.time()[a.len() - 1] - gap_from.0).abs() < 0.005,
        "{}",
        a.time()[a.len() - 1]
    );
    assert!((b.time()[0] - gap_from.1).abs() < 1e-6, "{}", b.time()[0]);
    for s in [&a, &b] {
        assert!((s.median_rate_hz() - 200.0).abs() < 0.01);
        assert!(s.time().windows(2).all(|w| w[1] - w[0] < 0.006));
        #[cfg(feature = "bundled-model")]
        ridi::track(
            s,
            &ridi::bundled_model().unwrap(),
            &ridi::TrackOptions::default(),
        )
        .unwrap();
    }
    // A part shorter than a second is dropped, saying so; nothing left is an error.
    let short: Vec<usize> = gappy.iter().copied().filter(|&i| i >= 900).collect();
    write_ridi_csv(&at_100(&short), src.join("data.csv")).unwrap();
    let summary = convert(&dir.path().join("src"), &dir.path().join("out4"), &split).unwrap();
    let names: Vec<&str> = summary.sequences.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["walk"]);
    assert!(
        summary.warnings.iter().any(|w| w.contains(
            "sequence `walk`: split at 1 gap longer than 0.1 s; 1 part shorter than 1 s dropped ("
        ) && w.ends_with("; 1 part kept, named `walk`")),
        "{:?}",
        summary.warnings
    );
    // The list names what was written.
    let listed = std::fs::read_to_string(dir.path().join("out4/list_all.txt")).unwrap();
    assert!(listed.ends_with("\nwalk,\n"), "{listed}");
    // A source left without any part is a warning while another converts.
    let tiny: Vec<usize> = keep
        .iter()
        .copied()
        .filter(|&i| i < 60 || (100..150).contains(&i))
        .collect();
    let tiny_dir = dir.path().join("src/tiny/processed");
    std::fs::create_dir_all(&tiny_dir).unwrap();
    write_ridi_csv(&at_100(&tiny), tiny_dir.join("data.csv")).unwrap();
    let summary = convert(&dir.path().join("src"), &dir.path().join("out6"), &split).unwrap();
    let names: Vec<&str> = summary.sequences.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["walk"]);
    assert!(
        summary.warnings.iter().any(|w| w.contains("sequence `tiny`: split at 1 gap")
            && w.ends_with("; nothing left")),
        "{:?}",
        summary.warnings
    );
    // The warnings stay beside the output, one per line after a header.
    let file = dir.path().join("out6").join(ridi::WARNINGS_FILE);
    assert_eq!(summary.warnings_file.as_deref(), Some(file.as_path()));
    let kept = std::fs::read_to_string(&file).unwrap();
    assert_eq!(
        kept.lines().skip(1).collect::<Vec<_>>(),
        summary
            .warnings
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>()
    );
    assert!(kept.starts_with("# warnings of `ridi convert "), "{kept}");

    let split_hard = ConvertOptions {
        split_at_gaps_s: Some(0.001),
        ..split.clone()
    };
    let e = convert(
        &dir.path().join("src"),
        &dir.path().join("out5"),
        &split_hard,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("no part of at least 1 s between gaps longer than 0.001 s"),
        "{e}"
    );
    assert!(matches!(
        slow.resampled(0.0, 1.0),
        Err(SequenceError::InvalidRate { .. })
    ));
}

/// The device of a sequence survives `ridi convert` in the sidecar beside its `data.csv`, each
/// device gets its list, and a sequence converted again without one loses the old sidecar.
#[test]
fn devices_are_kept_with_one_list_per_device() {
    use ridi::data::{DeviceInfo, sidecar_path};
    let dir = tempfile::tempdir().unwrap();
    let opts = ReadOptions::default();
    let walk = read_sequence(seq("Thibaud_Nexus5_NoDist_Texting"), &opts).unwrap();
    let src = dir.path().join("src");
    let device =
        |model: &str, rate: f64| Some(DeviceInfo::new(model).unwrap().with_imu_rate(rate).unwrap());
    let write = |name: &str, d: Option<DeviceInfo>| {
        // Without a device, also the layout's own orientation source: no sidecar at all.
        let mut s = if d.is_none() {
            let mut parts = walk.clone().into_parts();
            parts.orientation_source = None;
            ridi::data::Sequence::new(parts).unwrap()
        } else {
            walk.clone()
        };
        s.set_device(d);
        let folder = src.join(name).join("processed");
        std::fs::create_dir_all(&folder).unwrap();
        write_ridi_csv(&s, folder.join("data.csv")).unwrap();
    };
    write("Ann_Nexus5_NoDist_Texting", device("Nexus 5", 198.6));
    write("Ann_iPhone4S_NoDist_AR", device("iPhone 4S", 90.2));
    write("Bo_iPhone4S_NoDist_Texting", device("iPhone 4S", 90.2));
    write("plain", None);
    let out = dir.path().join("out");
    // An earlier conversion's warnings, which this one, without any, removes.
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(
        out.join(ridi::WARNINGS_FILE),
        "# warnings of an earlier run\nold\n",
    )
    .unwrap();
    let summary = convert(&src, &out, &ConvertOptions::default()).unwrap();
    assert!(summary.warnings.is_empty(), "{:?}", summary.warnings);
    assert!(summary.warnings_file.is_none() && !out.join(ridi::WARNINGS_FILE).exists());
    let lists: Vec<String> = summary
        .lists
        .iter()
        .map(|l| l.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        lists,
        [
            "list_Ann.txt",
            "list_Bo.txt",
            "list_all.txt",
            "list_iphone4s.txt",
            "list_nexus5.txt"
        ]
    );
    let names = |list: &str| -> Vec<String> {
        ridi::data::ListEntry::read(&[out.join(list)])
            .unwrap()
            .iter()
            .map(|e| e.path.file_name().unwrap().to_string_lossy().into_owned())
            .collect()
    };
    assert_eq!(
        names("list_iphone4s.txt"),
        ["Ann_iPhone4S_NoDist_AR", "Bo_iPhone4S_NoDist_Texting"]
    );
    assert_eq!(names("list_nexus5.txt"), ["Ann_Nexus5_NoDist_Texting"]);
    assert_eq!(names("list_all.txt").len(), 4);
    // Read back from the converted layout, with the device; `plain` has no sidecar.
    let back = read_sequence(out.join("Ann_iPhone4S_NoDist_AR"), &opts).unwrap();
    assert_eq!(back.device(), device("iPhone 4S", 90.2).as_ref());
    assert!(!sidecar_path(&out.join("plain/processed/data.csv")).exists());
    let c = summary
        .sequences
        .iter()
        .find(|c| c.name == "Ann_Nexus5_NoDist_Texting")
        .unwrap();
    assert_eq!(c.device.as_ref().unwrap().model(), "Nexus 5");

    // `ridi inspect` names the device and its rate.
    let report = ridi::inspect(&back, Format::RidiCsv);
    assert_eq!(report.device.as_deref(), Some("iPhone 4S"));
    assert_eq!(report.device_imu_rate_hz, Some(90.2));
    let text = report.to_string();
    assert!(
        text.contains("device:       iPhone 4S, IMU at 90.2 Hz (this sequence: 200 Hz)\n"),
        "{text}"
    );
    let unknown = read_sequence(out.join("plain"), &opts).unwrap();
    let text = ridi::inspect(&unknown, Format::RidiCsv).to_string();
    assert!(text.contains("device:       (unknown)\n"), "{text}");

    // Converted again without its device, a sequence loses the old sidecar with its old data.
    write("Ann_Nexus5_NoDist_Texting", None);
    let sidecar = sidecar_path(&out.join("Ann_Nexus5_NoDist_Texting/processed/data.csv"));
    assert!(sidecar.is_file());
    let summary = convert(&src, &out, &ConvertOptions::default()).unwrap();
    assert!(!sidecar.exists());
    let back = read_sequence(out.join("Ann_Nexus5_NoDist_Texting"), &opts).unwrap();
    assert_eq!(back.device(), None);
    assert!(!summary.lists.contains(&out.join("list_nexus5.txt")));

    // A device whose list would be another list's gets none, with a warning.
    write("Ann_Nexus5_NoDist_Texting", device("ANN", 100.0));
    let summary = convert(&src, &dir.path().join("out2"), &ConvertOptions::default()).unwrap();
    assert_eq!(
        summary.warnings,
        ["1 sequence of the device `ANN`: no list_ann.txt, as list_Ann.txt is another list"]
    );
}

/// A Tyrex-layout run of `seconds` at 200 Hz (a flat phone turning slowly), without ground truth.
fn tyrex_run(dir: &Path, seconds: f64) {
    std::fs::create_dir_all(dir).unwrap();
    let rows = |f: &dyn Fn(f64) -> String| -> String {
        (0..(seconds * 200.0) as usize)
            .map(|k| f(0.003 + k as f64 * 0.005) + "\n")
            .collect()
    };
    let w = 0.3;
    std::fs::write(
        dir.join("accelerometer.txt"),
        rows(&|t| format!("{t:.9} {} 0.0 9.80665", 0.1 * t.sin())),
    )
    .unwrap();
    std::fs::write(
        dir.join("gyroscope-calibrated.txt"),
        rows(&|t| format!("{t:.9} 0.0 0.0 {w}")),
    )
    .unwrap();
    std::fs::write(
        dir.join("rotation-vector.txt"),
        rows(&|t| {
            let h = w * t / 2.0;
            format!("{t:.9} 0 0 {} {} 0.17", h.sin(), h.cos())
        }),
    )
    .unwrap();
    std::fs::write(dir.join("timeAlignment.txt"), "-2.0\n").unwrap();
}

/// Runs without motion capture: skipped beside runs that have it, converted without ground
/// truth when no run has it, the same with and without `--from tyrex`.
#[test]
fn tyrex_runs_without_motion_capture_are_skipped_or_converted_with_a_warning() {
    let tmp = tempfile::tempdir().unwrap();
    let android = tmp.path().join("tyrex/datasets/android");
    tyrex_run(&android.join("Ann_Nexus5_NoDist_Texting"), 12.0);
    tyrex_run(&android.join("Ann_Nexus5_NoDist_AR"), 12.0);
    for from in [None, Some(ridi::data::Format::Tyrex)] {
        let out = tmp.path().join(format!("out-{}", from.is_some()));
        let opts = ridi::ConvertOptions {
            from,
            ..Default::default()
        };
        let summary = ridi::convert(&tmp.path().join("tyrex"), &out, &opts).unwrap();
        assert_eq!(summary.sequences.len(), 2, "{from:?}");
        assert!(
            summary
                .warnings
                .iter()
                .any(|w| w.contains("no run has a Qualisys file")
                    && w.contains("the 2 runs converted")),
            "{from:?}: {:?}",
            summary.warnings
        );
        // Lists are for training and evaluation, which need ground truth.
        assert!(summary.lists.is_empty(), "{:?}", summary.lists);
        assert!(
            summary.warnings.iter().any(|w| w.contains(
                ": 2 sequences without ground truth (Ann_Nexus5_NoDist_AR, \
                 Ann_Nexus5_NoDist_Texting): no list file written, as training and evaluation \
                 need ground truth; `ridi track` takes each one's data.csv"
            )),
            "{from:?}: {:?}",
            summary.warnings
        );
        assert!(!file_names(&out).iter().any(|f| f.starts_with("list_")));
    }
}

/// A sequence without ground truth (the competition's test paths) is converted for tracking
/// and left out of the lists, which training and evaluation read; one warning names it.
#[test]
fn sequences_without_ground_truth_are_in_no_list() {
    let dir = tempfile::tempdir().unwrap();
    let src = sources_named(dir.path(), &["walk"]);
    let mut parts = read_sequence(src.join("walk"), &ReadOptions::default())
        .unwrap()
        .into_parts();
    parts.ground_truth = None;
    parts.name = "test_path".into();
    let folder = src.join("test_path").join("processed");
    std::fs::create_dir_all(&folder).unwrap();
    write_ridi_csv(&Sequence::new(parts).unwrap(), folder.join("data.csv")).unwrap();
    let out = dir.path().join("out");
    let summary = convert(&src, &out, &ConvertOptions::default()).unwrap();
    assert_eq!(summary.sequences.len(), 2);
    assert!(out.join("test_path/processed/data.csv").is_file());
    let list = std::fs::read_to_string(out.join("list_all.txt")).unwrap();
    let listed: Vec<&str> = list.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(listed, ["walk,"], "{list}");
    let warning = format!(
        "{}: 1 sequence without ground truth (test_path): left out of the list files, as \
         training and evaluation need ground truth; `ridi track` takes its data.csv",
        out.display()
    );
    assert!(
        summary.warnings.contains(&warning),
        "{:?}",
        summary.warnings
    );

    // A sequence an earlier conversion listed, converted again without ground truth, is left
    // out of that conversion's lists (a list left empty goes); a list of one's own stays.
    let earlier = dir.path().join("earlier");
    convert(
        &sources_named(&earlier, &["walk", "test_path"]),
        &out,
        &ConvertOptions::default(),
    )
    .unwrap();
    assert_eq!(
        std::fs::read_to_string(out.join("list_all.txt"))
            .unwrap()
            .lines()
            .count(),
        3
    );
    std::fs::write(out.join("list_mine.txt"), "test_path,\n").unwrap();
    let alone = dir.path().join("alone");
    std::fs::create_dir_all(&alone).unwrap();
    std::fs::rename(src.join("test_path"), alone.join("test_path")).unwrap();
    let summary = convert(&alone, &out, &ConvertOptions::default()).unwrap();
    assert!(summary.lists.is_empty());
    for list in ["list_all.txt", "list_nexus5.txt"] {
        let text = std::fs::read_to_string(out.join(list)).unwrap();
        let listed: Vec<&str> = text.lines().filter(|l| !l.starts_with('#')).collect();
        assert_eq!(listed, ["walk,"], "{list}: {text}");
    }
    assert!(
        out.join("list_mine.txt").is_file(),
        "not written by convert"
    );
    assert!(
        summary.warnings.iter().any(|w| w.contains(
            "1 sequence without ground truth (test_path): no list file written, as training \
             and evaluation need ground truth (left out of the earlier list_all.txt, \
             list_nexus5.txt, which named it)"
        )),
        "{:?}",
        summary.warnings
    );
    let only = dir.path().join("only");
    convert(
        &sources_named(&dir.path().join("e2"), &["test_path"]),
        &only,
        &ConvertOptions::default(),
    )
    .unwrap();
    let summary = convert(&alone, &only, &ConvertOptions::default()).unwrap();
    assert!(!only.join("list_all.txt").exists() && !only.join("list_nexus5.txt").exists());
    assert!(
        summary
            .warnings
            .iter()
            .any(|w| w
                .contains("(removed the earlier list_all.txt, list_nexus5.txt, which named it)")),
        "{:?}",
        summary.warnings
    );
}

/// A sequence whose name a list file cannot hold (read back as a comment, as two fields or two
/// lines, or trimmed) is refused, naming its folder, before anything is written.
#[test]
fn names_a_list_file_cannot_hold_are_refused_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    for (name, why) in [
        ("#hash", "comment"),
        ("a,b", "comma"),
        ("two\nlines", "control character"),
        (" padded", "trimmed"),
    ] {
        let src = sources_named(
            &dir.path().join(format!("case{}", name.len())),
            &["fine", name],
        );
        let out = dir.path().join("out");
        let e = convert(&src, &out, &ConvertOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("{name:?}")) && e.contains(why) && e.contains("rename the folder"),
            "{name:?}: {e}"
        );
        assert!(!e.contains('\n'), "the name is escaped: {e:?}");
        assert!(!out.exists(), "{name:?}");
    }
}

/// Two sources that give one sequence name (here a split part and a folder of that name) would
/// be written to one folder: refused, naming both, before anything is written.
#[test]
fn two_sequences_of_one_name_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let src = sources_named(dir.path(), &["walk_part1"]);
    let opts = ReadOptions::default();
    let full = read_sequence(seq("Thibaud_Nexus5_NoDist_Texting"), &opts).unwrap();
    let mut parts = full.clone().into_parts();
    for (i, t) in parts.time.iter_mut().enumerate() {
        *t += if i >= 2000 { 0.3 } else { 0.0 };
    }
    parts.name = "walk".into();
    let folder = src.join("walk").join("processed");
    std::fs::create_dir_all(&folder).unwrap();
    write_ridi_csv(&Sequence::new(parts).unwrap(), folder.join("data.csv")).unwrap();
    let out = dir.path().join("out");
    let split = ConvertOptions {
        split_at_gaps_s: Some(0.1),
        ..ConvertOptions::default()
    };
    let e = convert(&src, &out, &split).unwrap_err().to_string();
    let (at_walk, at_part) = (src.join("walk"), src.join("walk_part1"));
    assert!(
        e.contains("gives a sequence named `walk_part1`, as ")
            && e.contains("an output folder holds one sequence per name")
            && [&at_walk, &at_part]
                .iter()
                .all(|p| e.contains(p.to_str().unwrap())),
        "{e}"
    );
    assert!(!out.exists());
    // Without the split, both convert.
    assert_eq!(
        convert(&src, &out, &ConvertOptions::default())
            .unwrap()
            .sequences
            .len(),
        2
    );
    // Names that differ in case alone are one folder on some file systems: refused too.
    let src2 = sources_named(&dir.path().join("two"), &["Walk", "walk"]);
    let e = convert(&src2, &dir.path().join("out2"), &ConvertOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("whatever its case"), "{e}");
}

/// A recording paused for longer than the readers accept (3 s) is refused whole, inspected,
/// and converted in two parts when split at its gaps.
#[test]
fn a_recording_paused_for_seconds_converts_split_at_its_gaps() {
    use ridi::data::Validation;
    let dir = tempfile::tempdir().unwrap();
    let opts = ReadOptions::default();
    let walk = read_sequence(seq("Thibaud_Nexus5_NoDist_Texting"), &opts).unwrap();
    let mut parts = walk.into_parts();
    for t in &mut parts.time[2000..] {
        *t += 3.0;
    }
    let pausing = Validation {
        max_gap_s: f64::INFINITY,
        ..Validation::default()
    };
    let paused = Sequence::with_validation(parts, &pausing).unwrap();
    let folder = dir.path().join("src/walk/processed");
    std::fs::create_dir_all(&folder).unwrap();
    write_ridi_csv(&paused, folder.join("data.csv")).unwrap();
    let src = dir.path().join("src");

    let e = convert(&src, &dir.path().join("out1"), &ConvertOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("data.csv:2002: field `time`: gap of 3.005 s since line 2001")
            && e.contains("`ridi convert --split-at-gaps 0.1` does"),
        "{e}"
    );
    let inspected = ridi::inspect(
        &ridi::read_any(
            &folder.join("data.csv"),
            ridi::source_format(&src.join("walk"), None).ok(),
            &ReadOptions {
                validation: pausing,
                ..ReadOptions::default()
            },
        )
        .unwrap()
        .sequences[0],
        Format::RidiCsv,
    );
    assert!(Format::RidiCsv.keeps_gaps() && !Format::RidiRaw.keeps_gaps());
    assert!(
        inspected
            .warnings
            .iter()
            .any(|w| w.starts_with("longest gap 3.005 s")
                && w.ends_with(
                    "`ridi convert --split-at-gaps 0.1` cuts the recording at its gaps"
                )),
        "{:?}",
        inspected.warnings
    );

    let split = ConvertOptions {
        split_at_gaps_s: Some(0.5),
        ..ConvertOptions::default()
    };
    let out = dir.path().join("out2");
    let summary = convert(&src, &out, &split).unwrap();
    let names: Vec<&str> = summary.sequences.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["walk_part1", "walk_part2"]);
    let (a, b) = (
        read_sequence(out.join("walk_part1"), &opts).unwrap(),
        read_sequence(out.join("walk_part2"), &opts).unwrap(),
    );
    assert_eq!((a.len(), b.len()), (2000, paused.len() - 2000));
    assert!((b.time()[0] - paused.time()[2000]).abs() < 1e-9);
}

/// Lists an earlier conversion of another source left in the output folder stay, and a
/// warning names them: they no longer agree with `list_all.txt`.
#[test]
fn lists_of_another_sources_conversion_in_the_output_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let first = sources_named(&dir.path().join("a"), &["Bo_Nexus5_NoDist_Texting"]);
    let second = sources_named(&dir.path().join("b"), &["walk"]);
    let out = dir.path().join("out");
    convert(&first, &out, &ConvertOptions::default()).unwrap();
    assert!(out.join("list_Bo.txt").is_file());
    let summary = convert(&second, &out, &ConvertOptions::default()).unwrap();
    let named: Vec<&String> = summary
        .warnings
        .iter()
        .filter(|w| w.contains("holds list files of a conversion of another source"))
        .collect();
    assert_eq!(named.len(), 1, "{:?}", summary.warnings);
    assert!(
        named[0].contains("left as they are: list_Bo.txt ("),
        "{named:?}"
    );
    assert!(out.join("list_Bo.txt").is_file());
    // The first source again, spelt otherwise (a trailing `/`, its absolute path): it writes
    // list_Bo.txt itself, and the second's lists are the first's too.
    let spelt = std::path::PathBuf::from(format!("{}/", first.canonicalize().unwrap().display()));
    let again = convert(&spelt, &out, &ConvertOptions::default()).unwrap();
    assert!(
        again.warnings.iter().all(|w| !w.contains("another source")),
        "{:?}",
        again.warnings
    );
    // A person's runs gone from the same source, spelt otherwise: their list is left, and is
    // not another source's.
    let both = sources_named(
        &dir.path().join("c"),
        &["Al_Nexus5_NoDist_Texting", "Bo_Nexus5_NoDist_Texting"],
    );
    let out = dir.path().join("out-c");
    convert(&both, &out, &ConvertOptions::default()).unwrap();
    std::fs::remove_dir_all(both.join("Al_Nexus5_NoDist_Texting")).unwrap();
    let spelt = std::path::PathBuf::from(format!("{}/", both.canonicalize().unwrap().display()));
    let later = convert(&spelt, &out, &ConvertOptions::default()).unwrap();
    assert!(out.join("list_Al.txt").is_file());
    assert!(
        later.warnings.iter().all(|w| !w.contains("another source")),
        "{:?}",
        later.warnings
    );
}

/// A sequence converted alone takes its placement from the lists beside it, in its parent
/// folder, as a whole folder's sequences take theirs from the lists in it.
#[test]
fn a_sequence_converted_alone_keeps_the_label_the_lists_beside_it_give() {
    let dir = tempfile::tempdir().unwrap();
    let src = sources_named(dir.path(), &["walk"]);
    std::fs::write(src.join("list_train.txt"), "walk,Texting\n").unwrap();
    let out = dir.path().join("out");
    let summary = convert(&src.join("walk"), &out, &ConvertOptions::default()).unwrap();
    assert_eq!(summary.sequences[0].placement.as_deref(), Some("Texting"));
    let list = std::fs::read_to_string(out.join("list_all.txt")).unwrap();
    assert!(list.ends_with("\nwalk,Texting\n"), "{list}");
    // Given as its data.csv, the sequence is its folder: the same label.
    let file = src.join("walk/processed/data.csv");
    let summary = convert(&file, &dir.path().join("out2"), &ConvertOptions::default()).unwrap();
    assert_eq!(summary.sequences[0].placement.as_deref(), Some("Texting"));
}
