//! `convert` on the full Tyrex and Indoor Location Competition data in `../shared` (beside the
//! checkout). The tests are `#[ignore]`d, so that `cargo test` shows them as not run; `.ci/run`
//! runs them with `--ignored`.

use ridi::data::{ListEntry, Listed, ReadOptions};
use ridi_test_support::shared_dataset;

/// Every run with motion capture in the shared root: the 42 Android runs (24 Nexus 5 runs and 18
/// near magnetic disturbance) and the 24 iOS runs (iPhone 4S) side by side; the one run folder
/// without it is skipped with one warning. Lists per person, per device and of all.
#[test]
#[ignore = "needs ../shared beside the checkout: `cargo test --workspace --tests -- --ignored` (.ci/run)"]
fn the_whole_tyrex_root_converts_with_one_list_per_person_and_device() {
    let root = shared_dataset("tyrex-attitude-smartphones", "datasets/ios");
    let out = tempfile::tempdir().unwrap();
    let started = std::time::Instant::now();
    // As `ridi convert --from tyrex <root>`.
    let opts = ridi::ConvertOptions {
        from: Some(ridi::data::Format::Tyrex),
        ..Default::default()
    };
    let summary = ridi::convert(&root, out.path(), &opts).unwrap();
    eprintln!(
        "{} sequences converted in {:.1?}",
        summary.sequences.len(),
        started.elapsed()
    );
    // 66 runs, some split at long mocap or sensor gaps into parts, each named and listed.
    let mut runs: Vec<&str> = summary
        .sequences
        .iter()
        .map(|c| c.name.split("_part").next().unwrap())
        .collect();
    runs.dedup();
    assert_eq!(runs.len(), 66, "{runs:?}");
    assert_eq!(runs.iter().filter(|r| r.contains("_Dist_")).count(), 18);
    assert_eq!(runs.iter().filter(|r| r.contains("_iPhone4S_")).count(), 24);
    let skipped: Vec<&String> = summary
        .warnings
        .iter()
        .filter(|w| w.contains("without a Qualisys file"))
        .collect();
    assert_eq!(skipped.len(), 1, "{:?}", summary.warnings);
    assert!(
        skipped[0].contains("1 run folder without")
            && skipped[0].ends_with("Jakob_Nexus5_Dist_Swinging_old"),
        "{}",
        skipped[0]
    );
    assert!(
        summary
            .warnings
            .iter()
            .any(|w| w.contains("recording split")),
        "splits are reported"
    );
    assert!(
        summary.warnings.iter().any(|w| w
            .contains("Jakob_Nexus5_Dist_BackPocket/rotation-vector.txt: the orientation jumps")),
        "the run the gyro check refused reads, with its orientation jumps reported"
    );
    let all = ListEntry::read(&[out.path().join("list_all.txt")]).unwrap();
    assert_eq!(all.len(), summary.sequences.len());
    let mut per_person = 0;
    for person in ["Guillaume", "Jakob", "Thibaud"] {
        let list = ListEntry::read(&[out.path().join(format!("list_{person}.txt"))]).unwrap();
        assert!(
            list.iter()
                .all(|e| e.path.to_string_lossy().contains(person))
        );
        assert!(list.iter().all(|e| e.placement.is_some()));
        per_person += list.len();
    }
    assert_eq!(per_person, all.len(), "every part is in its person's list");
    let mut per_device = 0;
    for (key, phone) in [("nexus5", "_Nexus5_"), ("iphone4s", "_iPhone4S_")] {
        let list = ListEntry::read(&[out.path().join(format!("list_{key}.txt"))]).unwrap();
        assert!(
            list.iter()
                .all(|e| e.path.to_string_lossy().contains(phone))
        );
        per_device += list.len();
    }
    assert_eq!(per_device, all.len(), "every part is in its device's list");
    assert_eq!(summary.lists.len(), 6, "{:?}", summary.lists);
    for c in &summary.sequences {
        assert!(c.path.is_file(), "{}", c.path.display());
        let phone = if c.name.contains("_iPhone4S_") {
            "iPhone 4S"
        } else {
            "Nexus 5"
        };
        assert_eq!(
            c.device.as_ref().map(|d| d.model()),
            Some(phone),
            "{}",
            c.name
        );
    }
    // The converted files read back with their device, through the sidecar; the run whose
    // Qualisys file is spelled in another case has its ground truth and its placement.
    let opts = ReadOptions::default();
    let back =
        ridi::data::read_sequence(out.path().join("Jakob_iPhone4S_NoDist_Backpocket"), &opts)
            .unwrap();
    assert!(back.ground_truth().is_some());
    let device = back.device().unwrap();
    assert_eq!(device.model(), "iPhone 4S");
    assert!((89.0..91.0).contains(&device.imu_rate_hz().unwrap()));
    let listed = all
        .iter()
        .find(|e| e.path.ends_with("Jakob_iPhone4S_NoDist_Backpocket"))
        .unwrap();
    assert_eq!(listed.placement.as_deref(), Some("BackPocket"));
}

#[test]
#[ignore = "needs ../shared beside the checkout: `cargo test --workspace --tests -- --ignored` (.ci/run)"]
fn indoor_location_competition_paths_convert_with_the_hand_placement() {
    let root = shared_dataset("indoor-location-competition-20", "data");
    let out = tempfile::tempdir().unwrap();
    let summary = ridi::convert(&root, out.path(), &Default::default()).unwrap();
    assert_eq!(summary.sequences.len(), 12);
    assert!(summary.warnings.is_empty(), "{:?}", summary.warnings);
    let all = ListEntry::read(&[out.path().join("list_all.txt")]).unwrap();
    assert_eq!(all.len(), 12);
    assert!(all.iter().all(|e| e.placement.as_deref() == Some("hand")));
    // The converted files read back with their ground truth, at 200 Hz.
    let seqs = Listed::read(&[out.path().join("list_all.txt")], &ReadOptions::default())
        .unwrap()
        .into_sequences();
    for s in &seqs {
        assert!(s.ground_truth().is_some() && s.magnet().is_some());
        assert!((s.rate_hz() - 200.0).abs() < 0.01, "{}", s.rate_hz());
    }
    // Their waypoints, interpolated, are no ground truth to train on: all 12 are named.
    let warnings = ridi::training_warnings(&seqs);
    assert!(
        warnings.len() == 1 && warnings[0].starts_with("12 of 12 training sequences ("),
        "{warnings:?}"
    );
}

/// `ridi track`'s reading: a run the mocap's losses split into parts is one recording without
/// ground truth, its phone streams being whole; a run read whole stays as it was.
#[test]
#[ignore = "needs ../shared beside the checkout: `cargo test --workspace --tests -- --ignored` (.ci/run)"]
fn a_run_split_by_the_mocap_is_tracked_whole_without_ground_truth() {
    let root = shared_dataset("tyrex-attitude-smartphones", "datasets/android");
    let opts = ReadOptions::default();
    let split = root.join("datasets/android/Jakob_Nexus5_NoDist_Swinging");
    let parts = ridi::read_any(&split, None, &opts).unwrap();
    assert_eq!(parts.sequences.len(), 3, "{:?}", parts.warnings);
    let whole = ridi::read_to_track(&split, None, &opts).unwrap();
    let [seq] = &whole.sequences[..] else {
        panic!("{} sequences", whole.sequences.len())
    };
    assert_eq!(seq.name(), "Jakob_Nexus5_NoDist_Swinging");
    assert!(seq.ground_truth().is_none());
    let framed: usize = parts.sequences.iter().map(|s| s.len()).sum();
    assert!(seq.len() > framed, "{} against {framed}", seq.len());
    assert!(
        whole.warnings[0].contains(
            "mocap losses split the run into 3 parts with ground truth; tracked as one \
             recording without it"
        ),
        "{:?}",
        whole.warnings
    );
    assert!(!whole.warnings.iter().any(|w| w.contains("mocap lost")));
    let one = root.join("datasets/android/Guillaume_Nexus5_NoDist_Texting");
    let read = ridi::read_to_track(&one, None, &opts).unwrap();
    assert_eq!(read.sequences.len(), 1);
    assert!(read.sequences[0].ground_truth().is_some());
    // Tracked, it gives one pose per frame of the whole recording.
    #[cfg(feature = "bundled-model")]
    {
        let model = ridi::bundled_model().unwrap();
        let track = ridi::track(seq, &model, &ridi::TrackOptions::default()).unwrap();
        assert_eq!(track.time.len(), seq.len());
    }
}
