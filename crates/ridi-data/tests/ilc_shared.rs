//! Checks against the real Indoor Location Competition 2.0 path files in `../shared` (beside the
//! checkout). The tests are `#[ignore]`d, so that `cargo test` shows them as not run; `.ci/run`
//! runs them with `--ignored`.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use ridi_data::ilc::{self, IlcOptions, IlcPath};
use ridi_data::interpolate_vec3;
use ridi_data::ridi_frames::{DeviceVec, WorldVec};
use ridi_data::{Format, OrientationSource, ReadOptions, detect, read_sequence};

fn root() -> PathBuf {
    ridi_test_support::shared_dataset(
        "indoor-location-competition-20",
        "data/site1/F1/path_data_files",
    )
}

fn read_all(root: &Path) -> Vec<(PathBuf, IlcPath)> {
    let files = ilc::list_paths(root).unwrap();
    assert_eq!(files.len(), 12, "{files:?}");
    files
        .into_iter()
        .map(|f| {
            let p = ilc::read(&f, &IlcOptions::default()).unwrap();
            (f, p)
        })
        .collect()
}

fn mean(v: &[DeviceVec]) -> DeviceVec {
    v.iter().fold(DeviceVec::ZERO, |a, &b| a + b) / v.len() as f64
}

#[test]
#[ignore = "needs ../shared beside the checkout: `cargo test --workspace --tests -- --ignored` (.ci/run)"]
fn every_path_reads_onto_a_200_hz_timeline_with_waypoint_ground_truth() {
    let root = root();
    for (file, p) in read_all(&root) {
        let seq = &p.sequence;
        let name = file.file_stem().unwrap().to_string_lossy();
        assert_eq!(seq.name(), name);
        assert_eq!(seq.placement(), Some("hand"));
        assert_eq!(
            seq.orientation_source(),
            Some(OrientationSource::RotationVector)
        );
        assert_eq!(p.device.as_deref(), Some("OPPO PBCM10 (Android 8.1.0)"));
        assert_eq!(p.floor.as_deref(), Some("F1"));
        assert!(seq.magnet().is_some());
        assert!((seq.rate_hz() - 200.0).abs() < 1e-3, "{}", seq.rate_hz());
        assert!(seq.max_gap() < 0.0051);
        // No sensor dropouts: nothing to warn of.
        assert!(p.warnings.is_empty(), "{name}: {:?}", p.warnings);
        // 20-40 s walks, 4-8 waypoints; the sequence spans the waypoints (the first is marked
        // up to 0.2 s before the IMU starts).
        assert!((18.0..42.0).contains(&seq.duration()), "{}", seq.duration());
        assert!((4..=8).contains(&p.waypoints.len()));
        let (first, last) = (p.waypoints[0].time, p.waypoints[p.waypoints.len() - 1].time);
        assert!(seq.time()[0] >= first && seq.time()[0] - first < 0.2);
        assert!((seq.time()[seq.len() - 1] - last).abs() < 0.005);

        // The ground truth passes through every waypoint inside the span (up to the corner cut
        // between two 5 ms frames).
        let gt = seq.ground_truth().unwrap();
        assert_eq!(gt.orientation, seq.orientation());
        assert!(gt.position.iter().all(|q| q.z() == 0.0));
        for w in &p.waypoints {
            if w.time < seq.time()[0] {
                continue;
            }
            let at = interpolate_vec3(seq.time(), &gt.position, &[w.time])[0];
            let d = ((at.x() - w.position[0]).powi(2) + (at.y() - w.position[1]).powi(2)).sqrt();
            assert!(
                d < 0.01,
                "{name}: {d} m off the waypoint of line {}",
                w.line
            );
        }
        // Plausible walks: 10-70 m at a walking pace.
        let length = seq.path_length().unwrap();
        let speed = length / seq.duration();
        assert!((10.0..70.0).contains(&length), "{name}: {length} m");
        assert!((0.5..2.0).contains(&speed), "{name}: {speed} m/s");

        // Gravity from the rotation vector roughly agrees with the accelerometer: the angle
        // between the walk's mean accelerometer and mean gravity, and the mean linear
        // acceleration, are small. Not as small as on Tyrex (0.5-1 degree for Texting): this
        // phone's rotation vector is tilted 2.6-5.0 degrees from its own accelerometer, always
        // pitched the same way (0.4-0.9 m/s^2 more gravity along device +y).
        let g = mean(seq.gravity());
        let a = mean(seq.acce());
        assert!((g.norm() - 9.8).abs() < 0.3, "{name}: |g| = {}", g.norm());
        let angle = (g.dot(a) / g.norm() / a.norm())
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees();
        let lin = mean(seq.linacce());
        assert!(
            angle < 6.0,
            "{name}: {angle} deg between mean gravity and accelerometer"
        );
        assert!(
            lin.norm() < 1.0,
            "{name}: mean linear acceleration {lin:?} m/s^2"
        );
        assert!(
            (0.3..1.0).contains(&(g.y() - a.y())),
            "{name}: {g:?} vs {a:?}"
        );
        // Held flat in front of the body: gravity mostly along the screen normal.
        assert!(g.z() > 8.0, "{name}: {g:?}");
    }
}

#[test]
#[ignore = "needs ../shared beside the checkout: `cargo test --workspace --tests -- --ignored` (.ci/run)"]
fn the_floor_map_is_a_rotation_of_the_device_world_not_a_mirror_image() {
    // With the phone held flat and pointing forward, the device's +y axis in the world frame
    // points where the surveyor walks. Between two waypoints the walking direction in the map
    // frame and that heading should differ by one fixed rotation (the map's north); a mirrored
    // map (y down) would make the difference change sign with the walking direction.
    let root = root();
    let mut sum = [0.0, 0.0];
    let mut mirrored = [0.0, 0.0];
    let mut segments = 0;
    for (_, p) in read_all(&root) {
        let seq = &p.sequence;
        for w in p.waypoints.windows(2) {
            let (dx, dy) = (
                w[1].position[0] - w[0].position[0],
                w[1].position[1] - w[0].position[1],
            );
            if dx.hypot(dy) < 3.0 {
                continue;
            }
            let frames: Vec<usize> = (0..seq.len())
                .filter(|&i| (w[0].time..w[1].time).contains(&seq.time()[i]))
                .collect();
            if frames.len() < 200 {
                continue;
            }
            let fwd = frames.iter().fold(WorldVec::ZERO, |acc, &i| {
                acc + seq.orientation()[i] * DeviceVec::new(0.0, 1.0, 0.0)
            });
            let heading = fwd.y().atan2(fwd.x());
            for (acc, map_dir) in [(&mut sum, dy.atan2(dx)), (&mut mirrored, (-dy).atan2(dx))] {
                let off = map_dir - heading;
                acc[0] += off.cos();
                acc[1] += off.sin();
            }
            segments += 1;
        }
    }
    let r = sum[0].hypot(sum[1]) / segments as f64;
    let r_mirrored = mirrored[0].hypot(mirrored[1]) / segments as f64;
    let offset = sum[1].atan2(sum[0]) * 180.0 / PI;
    eprintln!(
        "{segments} segments: resultant {r:.3} (mirrored {r_mirrored:.3}), map offset {offset:.1} deg"
    );
    assert!(segments >= 20, "{segments}");
    assert!(
        r > 0.8 && r_mirrored < r - 0.3,
        "{r} vs mirrored {r_mirrored}"
    );
}

#[test]
#[ignore = "needs ../shared beside the checkout: `cargo test --workspace --tests -- --ignored` (.ci/run)"]
fn files_are_detected_and_read_by_the_generic_reader() {
    let root = root();
    let dir = root.join("data/site1/F1/path_data_files");
    let file = ilc::list_paths(&dir).unwrap().remove(0);
    assert_eq!(detect(&file).unwrap(), Format::Ilc);
    // The floor info next to the folder is not a path file.
    assert!(!ilc::is_path_file(
        &root.join("data/site1/F1/floor_info.json")
    ));
    let seq = read_sequence(&file, &ReadOptions::default()).unwrap();
    assert_eq!(
        seq,
        ilc::read(&file, &IlcOptions::default()).unwrap().sequence
    );
}
