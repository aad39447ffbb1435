//! The bundled model (feature `bundled-model`): it decodes with this build's format, was
//! trained with this build's feature defaults, stays compact, and tracks.
#![cfg(feature = "bundled-model")]

use ridi::data::{Listed, ReadOptions};
use ridi::regress::{MODEL_FORMAT_VERSION, Solver, StoredAs};
use ridi::{EvalOptions, PlacementMap, TrainOptions};
use ridi_test_support::sample_dataset;

#[test]
fn the_bundled_model_decodes_with_this_builds_format_and_defaults() {
    // A change of the model format or of the feature defaults fails here: rebuild the model
    // with `cargo xtask model`.
    let model = ridi::bundled_model().expect("rebuild it: cargo xtask model");
    assert_eq!(model.format_version(), MODEL_FORMAT_VERSION);
    // Every setting but the standardization, which training fits (compared as a bool: the
    // explanation of a difference would print 2400 values).
    let mut config = model.feature_config().clone();
    assert!(config.standardization.take().is_some());
    let same = config == TrainOptions::default().features;
    assert!(
        same,
        "trained with other feature settings than this build's defaults"
    );
    assert!(matches!(model.solver(), Solver::Nystrom(_)));
    // The Nyström solver's projection (`Storage::NYSTROM_DEFAULT`), not the exact one's.
    let StoredAs::Projected { energy, .. } = model.stored_as() else {
        panic!("stored in half precision")
    };
    assert!((0.9..0.9999).contains(&energy), "{energy}");
    assert_eq!(
        model.placement_names(),
        ["hand", "pocket", "running", "swing"]
    );
    // The scaling issue's bound, and crates.io's package limit with room for the rest.
    let size = model.to_bytes().unwrap().len();
    assert!(size <= 10 << 20, "{size}");
}

#[test]
fn the_bundled_model_tracks_the_sample_far_better_than_double_integration() {
    // The sample's runs are excerpts of runs it was trained on: this checks that it tracks,
    // not how well it generalizes (docs/model-card.md has that, leaving each person out).
    let mut seqs = Listed::read(
        &[sample_dataset().join("list_test.txt")],
        &ReadOptions::default(),
    )
    .unwrap()
    .into_sequences();
    PlacementMap::tyrex4().apply(&mut seqs);
    let model = ridi::bundled_model().unwrap();
    let (report, _) = ridi::evaluate(&seqs, &model, &EvalOptions::default()).unwrap();
    let (ridi, raw) = (report.summary["ridi"], report.summary["raw"]);
    assert!(
        ridi.rte_5s_m < 0.5 * raw.rte_5s_m,
        "{ridi:?} vs raw {raw:?}"
    );
    let ratio = ridi.path_length_ratio.unwrap();
    assert!((0.7..1.3).contains(&ratio), "path length ratio {ratio}");
    assert!(
        report.velocity_mse.iter().all(|m| *m < 0.3),
        "{:?}",
        report.velocity_mse
    );
    assert!(report.placement_accuracy.unwrap() > 0.8);
    // And the report says so: every one of them is a run the model was trained on.
    let trained_on: Vec<&String> = report
        .warnings
        .iter()
        .filter(|w| w.contains("the bundled model was trained on"))
        .collect();
    assert_eq!(trained_on.len(), 1, "{:?}", report.warnings);
    assert_eq!(
        trained_on[0],
        "10 of 10 sequences (Thibaud_Nexus5_NoDist_AR, Thibaud_Nexus5_NoDist_BackPocket, \
         Thibaud_Nexus5_NoDist_FrontPocket, and 7 more) are among the runs the bundled model was \
         trained on: its figures there are not those of a person or phone it never saw \
         (docs/model-card.md has those, each person left out); to measure that on your data, \
         evaluate a model trained without them (`ridi train`, then `--model`; in Python \
         `ridi.train`)"
    );
    // A part of such a run counts, also one split again; another name does not.
    let renamed = |i: usize, name: String| {
        let mut s: ridi::data::Sequence = seqs[i].clone();
        s.set_name(name);
        s
    };
    let parts = [
        renamed(0, format!("{}_part2", seqs[0].name())),
        renamed(1, format!("{}_part1_part2", seqs[1].name())),
        renamed(2, "my_walk_part2".to_string()),
    ];
    let (report, _) = ridi::evaluate(&parts, &model, &EvalOptions::default()).unwrap();
    assert!(
        report.warnings.iter().any(|w| w.starts_with(
            "2 of 3 sequences (Thibaud_Nexus5_NoDist_AR_part2, \
             Thibaud_Nexus5_NoDist_BackPocket_part1_part2) are among the runs"
        )),
        "{:?}",
        report.warnings
    );
}

#[test]
fn the_bundled_model_is_known_by_its_file_fingerprint() {
    // The report fingerprints the decoded model's encoding; the warning above compares it with
    // the embedded file's: the two are the same bytes (encoding is deterministic, and nothing
    // a decode rebuilds is written).
    let model = ridi::bundled_model().unwrap();
    let embedded = include_bytes!("../model/ridi-tyrex.ridi");
    assert!(
        model.to_bytes().unwrap() == embedded,
        "re-encoded bytes differ"
    );
}

#[test]
fn the_bundled_models_training_runs_are_the_committed_run_list() {
    let list = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../datasets/protocols/tyrex-runs.txt"),
    )
    .unwrap();
    let committed: Vec<&str> = list
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| l.trim().rsplit('/').next().unwrap())
        .collect();
    assert_eq!(committed.len(), 66);
    assert_eq!(ridi::bundled_training_runs().collect::<Vec<_>>(), committed);
}
