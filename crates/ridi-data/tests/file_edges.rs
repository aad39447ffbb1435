//! Input that still parses but is wrong (a file cut inside its last value, one corrupt
//! ground-truth position, a count too large for an integer) and values of extreme magnitude in
//! written files.

mod common;

use std::io::Write as _;
use std::path::Path;

use common::*;
use ridi_data::ridi_frames::DeviceVec;
use ridi_data::{ReadOptions, Sequence, ridi_csv, ridi_plain, write_ridi_csv, write_ridi_plain};
use ridi_test_support::{assert_err, edit_cells, edit_file, with_cell, write_files};

/// `text` without its final line break and the last `n` characters of its last value, and the
/// number of its last line.
fn cut_last_value(text: &str, n: usize) -> (String, usize) {
    let body = text.trim_end_matches('\n');
    let cut = &body[..body.len() - n];
    assert!(cut.ends_with(|c: char| c.is_ascii_digit()), "{cut:?}");
    (cut.to_owned(), cut.lines().count())
}

#[test]
fn processed_files_cut_before_their_last_line_break_are_refused() {
    let opts = ReadOptions::default();
    let path = Path::new("walk/data.csv");
    let (cut, last) = cut_last_value(&String::from_utf8(valid_csv(20)).unwrap(), 3);
    // With its line break the cut file would read: the cut value still parses.
    ridi_csv::parse(format!("{cut}\n").as_bytes(), path, &opts).unwrap();
    assert_err(
        ridi_csv::parse(cut.as_bytes(), path, &opts),
        &[&format!(
            "walk/data.csv:{last}: the file ends inside this record, without a line break: cut \
             off while being written?"
        )],
    );

    // The same through gzip.
    let dir = tempfile::tempdir().unwrap();
    let gz = dir.path().join("data.csv.gz");
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    enc.write_all(cut.as_bytes()).unwrap();
    std::fs::write(&gz, enc.finish().unwrap()).unwrap();
    assert_err(
        ridi_csv::read(&gz, &opts),
        &[&format!(
            "data.csv.gz:{last}: the file ends inside this record"
        )],
    );

    let path = Path::new("data_plain.txt");
    let (cut, last) = cut_last_value(&String::from_utf8(valid_plain(10)).unwrap(), 3);
    ridi_plain::parse(format!("{cut}\n").as_bytes(), path, &opts).unwrap();
    assert_err(
        ridi_plain::parse(cut.as_bytes(), path, &opts),
        &[&format!(
            "data_plain.txt:{last}: the file ends inside this record"
        )],
    );

    // Empty and header-only files keep their own errors.
    assert_err(ridi_csv::parse(b"", path, &opts), &["file is empty"]);
    let csv = String::from_utf8(valid_csv(5)).unwrap();
    let header = csv.lines().next().unwrap();
    assert_err(
        ridi_csv::parse(header.as_bytes(), path, &opts),
        &["only a header line, no data rows"],
    );
    assert_err(
        ridi_plain::parse(b"5 27", path, &opts),
        &["file ends after 0 of the 5 rows"],
    );
}

#[test]
fn raw_files_cut_before_their_last_line_break_are_refused() {
    let mut last = 0;
    let (_d, r) = raw_with(|f| {
        edit_file(f, "acce.txt", |s| {
            let (cut, line) = cut_last_value(s, 3);
            last = line;
            cut
        })
    });
    assert_err(
        r,
        &[&format!(
            "acce.txt:{last}: the file ends inside this record, without a line break"
        )],
    );
    // A file that ends in its `#` header (no records) is still an optional file without rows.
    let (_d, r) = raw_with(|f| edit_file(f, "magnet.txt", |_| "# t_ns x y z".to_owned()));
    assert!(r.unwrap().magnet().is_none());
}

#[test]
fn a_single_corrupt_ground_truth_position_is_named_on_its_line() {
    let text = String::from_utf8(valid_csv(20)).unwrap();
    // Column 17 is `pos_x` (after the pandas index and `time`); line 9 is frame 7. A spike on
    // the first frame (line 2) is named there, not on the second, which agrees with the rest.
    for line in [9, 2] {
        let spiked = with_cell(&text, line, 17, "999999");
        assert_err(
            ridi_csv::parse(
                spiked.as_bytes(),
                Path::new("walk/data.csv"),
                &ReadOptions::default(),
            ),
            &[
                &format!("walk/data.csv:{line}: field `pos_x`: jumps 99999"),
                "faster than any pedestrian (speed <= 100 m/s), a corrupt position?",
            ],
        );
    }

    // In a raw folder, on the line of `pose.txt` it was read from.
    let (_d, r) = raw_with(|f| {
        edit_file(f, "pose.txt", |s| {
            edit_cells(s, ' ', |line, cells| {
                if line == 20 {
                    cells[1] = "999999".to_owned();
                }
            })
        })
    });
    assert_err(r, &["pose.txt:20: field `tx`: jumps 99999"]);
}

#[test]
fn a_row_count_too_large_for_an_integer_is_named_as_such() {
    let text = String::from_utf8(valid_plain(10)).unwrap();
    let (_, rows) = text.split_once('\n').unwrap();
    let huge = format!("99999999999999999999999 27\n{rows}");
    assert_err(
        ridi_plain::parse(
            huge.as_bytes(),
            Path::new("data_plain.txt"),
            &ReadOptions::default(),
        ),
        &["data_plain.txt:1: field `rows`: `99999999999999999999999` is too large"],
    );
}

#[test]
fn tiny_and_huge_values_are_written_short_and_read_back_exactly() {
    let mut parts = sample_sequence("walk", 30, true, true).into_parts();
    parts.gyro[3] = DeviceVec::new(1.28e-300, -4.9e-324, 0.25);
    parts.magnet.as_mut().unwrap()[4] = DeviceVec::new(-2.5e-20, 1e-4, 9.9e-5);
    let seq = Sequence::new(parts).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("walk/data.csv");
    let plain = dir.path().join("walk/data_plain.txt");
    std::fs::create_dir_all(csv.parent().unwrap()).unwrap();
    write_ridi_csv(&seq, &csv).unwrap();
    write_ridi_plain(&seq, &plain).unwrap();
    for path in [&csv, &plain] {
        let text = std::fs::read_to_string(path).unwrap();
        for value in [
            "1.28e-300",
            "-5e-324",
            "-2.5e-20",
            "0.0001",
            "9.9e-5",
            "0.25",
        ] {
            assert!(text.contains(value), "{value} not in {}", path.display());
        }
        // 27 values of at most 24 characters each.
        assert!(
            text.lines().all(|l| l.len() < 27 * 25),
            "{}",
            path.display()
        );
    }
    assert_eq!(ridi_csv::read(&csv, &ReadOptions::default()).unwrap(), seq);
    assert_eq!(
        ridi_plain::read(&plain, &ReadOptions::default()).unwrap(),
        seq
    );
}

/// A gzip bomb (a small `data.csv.gz` of newlines that expands a thousandfold) is refused while
/// decompressing, naming the file, before it can fill the memory; a real compressed recording
/// (ratio 2-10) reads.
#[test]
fn a_gzip_bomb_is_refused_while_decompressing() {
    let dir = tempfile::tempdir().unwrap();
    let gz = |name: &str, content: &dyn Fn(&mut dyn std::io::Write)| {
        let path = dir.path().join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
        content(&mut enc);
        std::fs::write(&path, enc.finish().unwrap()).unwrap();
        path
    };
    // 200 MB of newlines: about 200 KB compressed, 1000 times smaller.
    let bomb = gz("bomb/data.csv.gz", &|w| {
        let block = vec![b'\n'; 1 << 20];
        for _ in 0..200 {
            w.write_all(&block).unwrap();
        }
    });
    let compressed = std::fs::metadata(&bomb).unwrap().len();
    assert!(compressed < 1 << 20, "{compressed}");
    let e = ridi_csv::read(&bomb, &ReadOptions::default()).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("bomb/data.csv.gz") && text.contains("over 200 times its"),
        "{text}"
    );
    // A valid recording through gzip reads.
    let ok = gz("ok/data.csv.gz", &|w| w.write_all(&valid_csv(500)).unwrap());
    ridi_csv::read(&ok, &ReadOptions::default()).unwrap();
}

/// An optional file (`pose.txt`) or a required one that is a symbolic link to nothing, or a
/// folder, is named as such: it was taken as absent (a recording read without its ground
/// truth) or as missing.
#[cfg(unix)]
#[test]
fn files_that_are_broken_links_or_folders_are_named_not_skipped() {
    let folder = || {
        let dir = tempfile::tempdir().unwrap();
        write_files(dir.path(), &raw_files(60, true));
        dir
    };
    let read = |dir: &Path| ridi_data::read_sequence(dir, &raw_options());
    for (file, target) in [("pose.txt", "missing.txt"), ("gyro.txt", "gyro.txt")] {
        let dir = folder();
        std::fs::remove_file(dir.path().join(file)).unwrap();
        std::os::unix::fs::symlink(target, dir.path().join(file)).unwrap();
        let why = match target == file {
            true => "that cannot be followed (",
            false => "that cannot be followed (its target does not exist)",
        };
        // A relative target, shown joined to the link's folder.
        let to = dir.path().join(target);
        assert_err(
            read(dir.path()),
            &[
                &format!("{file}: is a symbolic link to {} ", to.display()),
                why,
            ],
        );
    }
    let dir = folder();
    std::fs::remove_file(dir.path().join("gyro.txt")).unwrap();
    std::fs::create_dir(dir.path().join("gyro.txt")).unwrap();
    assert_err(
        read(dir.path()),
        &["gyro.txt: is a folder: it is not a regular file"],
    );
    // A processed file's sidecar, a link to nothing: named, not read as no sidecar.
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("data.csv");
    ridi_data::write_ridi_csv(&read(folder().path()).unwrap(), &csv).unwrap();
    std::os::unix::fs::symlink("gone.meta", dir.path().join("data.csv.meta")).unwrap();
    assert_err(
        ridi_data::read_sequence(&csv, &ReadOptions::default()),
        &[
            "data.csv.meta: is a symbolic link to ",
            "(its target does not exist)",
        ],
    );
    // The file given itself, a link in a loop.
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("data.csv");
    std::os::unix::fs::symlink("data.csv", &csv).unwrap();
    assert_err(
        ridi_data::read_sequence(&csv, &ReadOptions::default()),
        &[
            "data.csv: is a symbolic link to ",
            "data.csv that cannot be followed",
        ],
    );
}

/// A raw file whose clock stops: up to `MAX_REPEATED_TIMESTAMPS` records repeating a
/// timestamp are dropped as duplicates, more are refused on the line where they exceed it
/// (their times are unknown: 3 hours of them were read as 97 % of a file, dropped unsaid).
#[test]
fn a_raw_clock_that_stops_is_refused_beyond_a_few_repeats() {
    let stall = |repeats: usize| {
        raw_with(|f| {
            edit_file(f, "gyro.txt", |s| {
                let mut lines: Vec<String> = s.lines().map(str::to_owned).collect();
                // Record i is on line i + 2 (after the header); records 10.. repeat record 9's.
                let frozen = lines[10].split(' ').next().unwrap().to_owned();
                for line in &mut lines[11..11 + repeats] {
                    let rest = line.split_once(' ').unwrap().1.to_owned();
                    *line = format!("{frozen} {rest}");
                }
                lines.join("\n") + "\n"
            })
        })
    };
    let max = ridi_data::ridi_raw::MAX_REPEATED_TIMESTAMPS;
    assert!(stall(max).1.is_ok());
    assert_err(
        stall(max + 1).1,
        &[&format!(
            "gyro.txt:22: field `t`: the timestamp of line 11 repeated by more than {max} \
             records in a row: a clock that stopped"
        )],
    );
}

/// An output path that is a symbolic link is written through it (the link stays); a pipe, a
/// device or a link in a loop is refused, never replaced by a regular file.
#[cfg(unix)]
#[test]
fn outputs_write_through_links_and_refuse_pipes_and_devices() {
    let dir = tempfile::tempdir().unwrap();
    let write = |path: &Path| {
        ridi_data::write_atomically(path, |w: &mut dyn std::io::Write| w.write_all(b"x\n"))
    };
    let link = dir.path().join("latest.txt");
    std::os::unix::fs::symlink("v3.txt", &link).unwrap();
    write(&link).unwrap();
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(std::fs::read(dir.path().join("v3.txt")).unwrap(), b"x\n");
    let fifo = dir.path().join("pipe");
    ridi_test_support::make_fifo(&fifo);
    // (A pipe, not /dev/null: were the check to fail, a test run as root would replace it.)
    assert_err(write(&fifo), &["is a device, a pipe or a socket"]);
    assert!(ridi_test_support::is_fifo(&fifo));
    let looped = dir.path().join("loop.txt");
    std::os::unix::fs::symlink("loop.txt", &looped).unwrap();
    assert_err(write(&looped), &["links in a loop"]);
}

#[test]
fn a_rotation_that_is_not_a_finite_unit_quaternion_is_named_on_its_frame() {
    // Rot's constructors normalize, but a NaN angle (a corrupt value) gives a NaN rotation.
    let nan = ridi_data::ridi_frames::WorldFromDevice::from_axis_angle(
        &ridi_data::ridi_frames::nalgebra::Vector3::z_axis(),
        f64::NAN,
    );
    let mut parts = sample_sequence("walk", 30, true, false).into_parts();
    parts.orientation[7] = nan;
    let e = Sequence::new(parts).unwrap_err().to_string();
    assert_eq!(
        e,
        "`orientation` at frame 7 is not a rotation (not a finite unit quaternion)"
    );
    let mut parts = sample_sequence("walk", 30, true, false).into_parts();
    parts.ground_truth.as_mut().unwrap().orientation[9] = nan;
    let e = Sequence::new(parts).unwrap_err().to_string();
    assert!(
        e.contains("ground_truth.orientation") && e.contains("9"),
        "{e}"
    );
}
