//! The device of a sequence: kept through the RIDI processed layout in a sidecar beside the data
//! file, which RIDI's own readers never open, and read back by this crate's readers.

mod common;

use common::sample_sequence;
use ridi_data::{
    DeviceInfo, OrientationSource, ReadOptions, Sequence, SequenceError, SplitParts, read_sequence,
    ridi_csv, ridi_plain, sidecar_path, source_files, write_ridi_csv, write_ridi_plain,
};
use ridi_test_support::assert_names_file;

fn iphone() -> DeviceInfo {
    // A rate with many digits: it must come back bit for bit.
    DeviceInfo::new("iPhone 4S")
        .unwrap()
        .with_imu_rate(90.187_342_118_3)
        .unwrap()
}

fn with_device(name: &str) -> Sequence {
    let mut seq = sample_sequence(name, 300, true, false);
    seq.set_device(Some(iphone()));
    seq
}

#[test]
fn the_device_goes_to_a_sidecar_and_comes_back() {
    let dir = tempfile::tempdir().unwrap();
    let opts = ReadOptions::default();
    let seq = with_device("walk");
    for file in [
        "walk/processed/data.csv",
        "csvgz/data.csv.gz",
        "plain/data_plain.txt",
    ] {
        let path = dir.path().join(file);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        if file.ends_with(".txt") {
            write_ridi_plain(&seq, &path).unwrap();
        } else {
            write_ridi_csv(&seq, &path).unwrap();
        }
        let sidecar = sidecar_path(&path);
        assert_eq!(
            sidecar.file_name().unwrap().to_string_lossy(),
            format!("{}.meta", path.file_name().unwrap().to_string_lossy())
        );
        let text = std::fs::read_to_string(&sidecar).unwrap();
        assert!(
            text.starts_with("# ridi-rs: what ") && text.contains("\ndevice = iPhone 4S\n"),
            "{text}"
        );
        let back = if file.ends_with(".txt") {
            ridi_plain::read(&path, &opts).unwrap()
        } else {
            ridi_csv::read(&path, &opts).unwrap()
        };
        assert_eq!(back.device(), Some(&iphone()), "{file}");
        assert!(source_files(&path).unwrap().contains(&sidecar));
    }
    // Through the folder, as `ridi convert`'s output is read.
    let back = read_sequence(dir.path().join("walk"), &opts).unwrap();
    assert_eq!(back, seq);
    // The sidecar is optional: without it, no device.
    std::fs::remove_file(sidecar_path(&dir.path().join("walk/processed/data.csv"))).unwrap();
    let back = read_sequence(dir.path().join("walk"), &opts).unwrap();
    assert_eq!(back.device(), None);
    // `parse` reads the bytes alone.
    let path = dir.path().join("walk/processed/data.csv");
    write_ridi_csv(&seq, &path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(
        ridi_csv::parse(&bytes, &path, &opts).unwrap().device(),
        None
    );
}

/// Where the orientation comes from goes to the sidecar too, when it is not the layout's own (RIDI's
/// game rotation vector): a converted Tyrex run's magnetic rotation vector, a phone's Core Motion
/// attitude, stay what they are.
#[test]
fn the_orientation_source_goes_to_the_sidecar_and_comes_back() {
    let dir = tempfile::tempdir().unwrap();
    let opts = ReadOptions::default();
    for (device, source) in [
        (None, OrientationSource::RotationVector),
        (Some(iphone()), OrientationSource::CoreMotionAttitude),
        (None, OrientationSource::Estimated),
    ] {
        let mut parts = sample_sequence("walk", 300, true, false).into_parts();
        parts.orientation_source = Some(source);
        parts.device = device.clone();
        let seq = Sequence::new(parts).unwrap();
        let path = dir.path().join(format!("{}/data.csv", source.key()));
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        write_ridi_csv(&seq, &path).unwrap();
        let text = std::fs::read_to_string(sidecar_path(&path)).unwrap();
        assert!(
            text.contains(&format!("\norientation_source = {}\n", source.key())),
            "{text}"
        );
        let back = ridi_csv::read(&path, &opts).unwrap();
        assert_eq!(back.orientation_source(), Some(source));
        assert_eq!(back.device(), device.as_ref());
    }
    // The layout's own source needs no sidecar, and a file without one reads as RIDI's.
    let path = dir.path().join("grv/data.csv");
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    write_ridi_csv(&sample_sequence("walk", 300, true, false), &path).unwrap();
    assert!(!sidecar_path(&path).exists());
    assert_eq!(
        ridi_csv::read(&path, &opts).unwrap().orientation_source(),
        Some(OrientationSource::GameRotationVector)
    );
}

#[test]
fn the_data_file_is_what_ridi_reads_whatever_the_device() {
    let dir = tempfile::tempdir().unwrap();
    let plain = sample_sequence("walk", 300, true, false);
    let a = dir.path().join("a.csv");
    let b = dir.path().join("b.csv");
    write_ridi_csv(&plain, &a).unwrap();
    write_ridi_csv(&with_device("walk"), &b).unwrap();
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert!(!sidecar_path(&a).exists() && sidecar_path(&b).exists());
}

#[test]
fn a_sequence_without_a_device_replaces_the_old_sidecar_too() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("data.csv");
    write_ridi_csv(&with_device("walk"), &path).unwrap();
    assert!(sidecar_path(&path).is_file());
    write_ridi_csv(&sample_sequence("walk", 300, true, false), &path).unwrap();
    assert!(!sidecar_path(&path).exists());
    let back = ridi_csv::read(&path, &ReadOptions::default()).unwrap();
    assert_eq!(back.device(), None);
}

#[test]
fn slices_and_resampling_keep_the_device() {
    let seq = with_device("walk");
    assert_eq!(seq.slice(10..200).device(), Some(&iphone()));
    assert_eq!(
        seq.resampled(100.0, 0.05).unwrap().device(),
        Some(&iphone())
    );
}

/// `split_at_gaps` cuts at each gap over the limit and only there, names the parts as the
/// Tyrex reader does, and keeps every channel and the device; resampling interpolates the step
/// counter with the rest (it kept the old timeline's steps, which the new one refused).
#[test]
fn splits_at_gaps_and_resampling_keep_every_channel() {
    let seq = with_device("walk");
    let whole = seq.clone().split_at_gaps(0.1, 1.0).unwrap();
    assert_eq!((whole.parts, whole.dropped), (vec![seq.clone()], vec![]));
    // Without a gap too, nothing shorter than the minimum is kept.
    let (first, last) = (seq.time()[0], seq.time()[seq.len() - 1]);
    let none = seq.clone().split_at_gaps(0.1, last - first + 0.01).unwrap();
    assert_eq!((none.parts, none.dropped), (vec![], vec![(first, last)]));
    let mut parts = seq.clone().into_parts();
    let steps: Vec<f64> = (0..seq.len()).map(|i| (i / 40) as f64).collect();
    parts.steps = Some(steps.clone());
    // Gaps of 0.2 s before frames 100 and 250, a 0.05 s one before frame 200.
    for (i, t) in parts.time.iter_mut().enumerate() {
        *t += 0.2 * [100, 250].iter().filter(|&&g| i >= g).count() as f64
            + 0.045 * f64::from(u8::from(i >= 200));
    }
    let gappy = Sequence::new(parts).unwrap();
    let SplitParts {
        parts: split,
        dropped,
    } = gappy.clone().split_at_gaps(0.1, 0.0).unwrap();
    assert!(dropped.is_empty());
    let names: Vec<&str> = split.iter().map(Sequence::name).collect();
    assert_eq!(names, ["walk_part1", "walk_part2", "walk_part3"]);
    let lens: Vec<usize> = split.iter().map(Sequence::len).collect();
    assert_eq!(lens, [100, 150, gappy.len() - 250]);
    assert_eq!(split[1].time()[0], gappy.time()[100]);
    assert_eq!(split[1].steps().unwrap(), &steps[100..250]);
    assert_eq!(split[2].gyro(), &gappy.gyro()[250..]);
    assert!(split.iter().all(|s| s.device() == Some(&iphone())));
    assert_eq!(
        gappy.clone().split_at_gaps(1.0, 0.0).unwrap().parts.len(),
        1
    );
    // Parts shorter than the minimum go, and the rest are numbered as the Tyrex reader numbers
    // what it keeps: one part left keeps the plain name.
    // (0.495 s, 0.79 s and 0.245 s long)
    let SplitParts {
        parts: kept,
        dropped,
    } = gappy.clone().split_at_gaps(0.1, 0.3).unwrap();
    let names: Vec<&str> = kept.iter().map(Sequence::name).collect();
    assert_eq!(names, ["walk_part1", "walk_part2"]);
    assert_eq!(kept[1].time()[0], gappy.time()[100]);
    assert_eq!(dropped, [(gappy.time()[250], gappy.time()[299])]);
    let SplitParts {
        parts: kept,
        dropped,
    } = gappy.clone().split_at_gaps(0.1, 0.6).unwrap();
    assert_eq!((kept.len(), kept[0].name(), dropped.len()), (1, "walk", 2));
    assert_eq!(kept[0].time()[0], gappy.time()[100]);
    for (gap, min) in [
        (0.0, 1.0),
        (-1.0, 1.0),
        (f64::NAN, 1.0),
        (f64::INFINITY, 1.0),
        (0.1, -1.0),
        (0.1, f64::NAN),
    ] {
        assert!(matches!(
            gappy.clone().split_at_gaps(gap, min),
            Err(ridi_data::SequenceError::InvalidGap { .. })
        ));
    }

    let at_100 = split[1].resampled(100.0, 0.05).unwrap();
    let counted = at_100.steps().unwrap();
    assert_eq!(counted.len(), at_100.len());
    assert_eq!((counted[0], counted[counted.len() - 1]), (2.0, 6.0));
    // A rate no timeline may step at is refused before any frame is made (1e9 Hz would be
    // billions of them).
    for rate in [0.0, -5.0, f64::NAN, 1e9, 0.5] {
        let e = split[1].resampled(rate, 0.05).unwrap_err();
        assert!(matches!(e, SequenceError::InvalidRate { .. }), "{e}");
    }
    // A gap limit that is no number above 0 would refuse every step, or (NaN) none.
    for gap in [0.0, -1.0, f64::NAN] {
        let e = split[1].resampled(100.0, gap).unwrap_err().to_string();
        assert!(e.contains("the gap limit a number above 0"), "{e}");
    }
    assert!(
        split[1]
            .resampled(ridi_data::RESAMPLE_RATE_RANGE_HZ.1, 0.05)
            .is_ok()
    );
    assert!(
        split[1]
            .resampled(ridi_data::RESAMPLE_RATE_RANGE_HZ.0, 5.0)
            .is_ok()
    );
    assert!(split[1].resampled(100.0, f64::INFINITY).is_ok());
    // Across a gap of 11 days, most of the result would be invented: refused before it is made.
    let mut parts = split[1].parts().clone();
    let mid = parts.time.len() / 2;
    parts.time[mid..].iter_mut().for_each(|t| *t += 1e6);
    let validation = ridi_data::Validation {
        max_gap_s: f64::INFINITY,
        ..ridi_data::Validation::default()
    };
    let paused = Sequence::with_validation(parts, &validation).unwrap();
    let e = paused.resampled(100.0, f64::INFINITY).unwrap_err();
    assert!(
        matches!(e, SequenceError::ResampledAcrossGaps { frames, .. } if frames > 100_000_000),
        "{e}"
    );
}

#[test]
fn a_bad_sidecar_names_its_file_line_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("data.csv");
    write_ridi_csv(&with_device("walk"), &path).unwrap();
    let sidecar = sidecar_path(&path);
    let opts = ReadOptions::default();
    for (text, line, field, words) in [
        (
            "# c\ndevice iPhone\n",
            Some(2),
            None,
            "expected `key = value`",
        ),
        (
            "device =  \n",
            Some(1),
            Some("device"),
            "empty device model",
        ),
        (
            "device = a\ndevice = b\n",
            Some(2),
            Some("device"),
            "given twice (first on line 1)",
        ),
        (
            "device = a\ndevice_imu_rate_hz = 0\n",
            Some(2),
            Some("device_imu_rate_hz"),
            "must be a finite number above 0",
        ),
        (
            "device = a\ndevice_imu_rate_hz = NaN\n",
            Some(2),
            Some("device_imu_rate_hz"),
            "`NaN` is not a finite number",
        ),
        (
            "device_imu_rate_hz = 100\n",
            Some(1),
            Some("device_imu_rate_hz"),
            "a device rate without `device = <model>`",
        ),
    ] {
        std::fs::write(&sidecar, text).unwrap();
        let e = ridi_csv::read(&path, &opts).unwrap_err();
        let blame = assert_names_file(&e, &sidecar);
        assert_eq!(
            (blame.line, blame.field.as_deref()),
            (line, field),
            "{text:?}: {e}"
        );
        assert!(e.to_string().contains(words), "{text:?}: {e}");
        blame.assert_line_in(text.as_bytes());
    }
    std::fs::write(&sidecar, b"device = a\n\xff\n").unwrap();
    let e = ridi_csv::read(&path, &opts).unwrap_err();
    assert_eq!(assert_names_file(&e, &sidecar).line, Some(2), "{e}");
    assert!(e.to_string().ends_with("is not UTF-8 text"), "{e}");
    // Keys of a later version are skipped.
    std::fs::write(
        &sidecar,
        "device = Pixel 8\norientation = rotation vector\n",
    )
    .unwrap();
    let seq = ridi_csv::read(&path, &opts).unwrap();
    assert_eq!(seq.device().unwrap().model(), "Pixel 8");
    // Not a file, or far too large for one of ours.
    std::fs::remove_file(&sidecar).unwrap();
    std::fs::create_dir(&sidecar).unwrap();
    let e = ridi_csv::read(&path, &opts).unwrap_err();
    assert_names_file(&e, &sidecar);
    assert!(e.to_string().ends_with("is not a regular file"), "{e}");
    std::fs::remove_dir(&sidecar).unwrap();
    std::fs::write(&sidecar, "#".repeat(100_000)).unwrap();
    let e = ridi_csv::read(&path, &opts).unwrap_err();
    assert_names_file(&e, &sidecar);
}
