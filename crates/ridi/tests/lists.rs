//! List files and placement labels for training and evaluation: each error is one line naming
//! the list file and line; labels a model does not know are a warning.

use std::path::{Path, PathBuf};

use ridi::data::{ListEntry, Listed, ReadOptions, Sequence, read_sequence, write_ridi_csv};
use ridi::regress::NoProgress;
use ridi::{EvalOptions, GridChoice, Method, PlacementMap, Purpose, TrainOptions, load_listed};
use ridi_test_support::sample_dataset;

fn seq(name: &str) -> PathBuf {
    sample_dataset().join(name)
}

/// Writes a list file of `lines` into `dir`.
fn list(dir: &Path, name: &str, lines: &[String]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    path
}

fn line(name: &str, placement: &str) -> String {
    format!("{},{placement}", seq(name).display())
}

fn load(
    lists: &[&Path],
    map: Option<&PlacementMap>,
    purpose: Purpose,
) -> ridi::Result<Vec<Sequence>> {
    let entries = ListEntry::read(lists)?;
    load_listed(entries, map, purpose, &ReadOptions::default()).map(Listed::into_sequences)
}

fn err<T: std::fmt::Debug>(r: ridi::Result<T>) -> String {
    let e = r.expect_err("expected an error").to_string();
    assert_eq!(e.lines().count(), 1, "{e}");
    e
}

#[test]
fn unknown_placement_labels_name_the_list_line_and_the_known_labels() {
    let dir = tempfile::tempdir().unwrap();
    let tyrex4 = PlacementMap::tyrex4();
    for label in ["Hovering", "Swingin"] {
        let l = list(
            dir.path(),
            "unk.txt",
            &[
                "# header".into(),
                line("Guillaume_Nexus5_NoDist_Texting", "Texting"),
                line("Guillaume_Nexus5_NoDist_BackPocket", label),
                line("Jakob_Nexus5_NoDist_BackPocket", label),
            ],
        );
        let e = err(load(&[&l], Some(&tyrex4), Purpose::Training));
        assert_eq!(
            e,
            format!(
                "{}:3: field `placement`: placement `{label}` is not in the placement map tyrex4 \
                 (labels AR, BackPocket, FrontPocket, Phoning, RunningHand, RunningPocket, \
                 Swinging, Texting; classes hand, pocket, running, swing)",
                l.display()
            )
        );
    }
    // A map file without an entry for a label in use: the same error, naming the map file.
    let map1 = dir.path().join("map1.txt");
    std::fs::write(&map1, "Texting,hand\n").unwrap();
    let map1 = PlacementMap::read(&map1).unwrap();
    let l = list(
        dir.path(),
        "good.txt",
        &[
            line("Guillaume_Nexus5_NoDist_Texting", "Texting"),
            line("Guillaume_Nexus5_NoDist_BackPocket", "BackPocket"),
        ],
    );
    let e = err(load(&[&l], Some(&map1), Purpose::Evaluation));
    assert!(
        e.starts_with(&format!("{}:2: field `placement`", l.display()))
            && e.contains("placement `BackPocket` is not in the placement map")
            && e.contains("map1.txt (labels Texting; classes hand)"),
        "{e}"
    );
    // With every label known, the classes replace the labels; a class is its own class.
    let l = list(
        dir.path(),
        "good.txt",
        &[
            line("Guillaume_Nexus5_NoDist_Texting", "Texting"),
            line("Guillaume_Nexus5_NoDist_BackPocket", "BackPocket"),
            line("Jakob_Nexus5_NoDist_Texting", "hand"),
        ],
    );
    let seqs = load(&[&l], Some(&tyrex4), Purpose::Training).unwrap();
    let got: Vec<_> = seqs.iter().map(|s| s.placement().unwrap()).collect();
    assert_eq!(got, ["hand", "pocket", "hand"]);
}

#[test]
fn a_label_from_the_source_is_checked_at_its_list_line_too() {
    // A Tyrex run listed without a label has its motion as placement: checked all the same.
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("Jakob_Nexus5_NoDist_Hovering");
    std::fs::create_dir_all(run.join("processed")).unwrap();
    // Another recording than the listed one (a copy of it would be refused as such).
    let mut s = read_sequence(seq("Jakob_Nexus5_NoDist_Phoning"), &ReadOptions::default()).unwrap();
    s.set_placement(None);
    write_ridi_csv(&s, run.join("processed/data.csv")).unwrap();
    let l = list(
        dir.path(),
        "l.txt",
        &[
            line("Jakob_Nexus5_NoDist_Texting", "Texting"),
            format!("{}", run.display()),
        ],
    );
    // No label at all: fine for evaluation, an error for training.
    let seqs = load(&[&l], None, Purpose::Evaluation).unwrap();
    assert_eq!(seqs[1].placement(), None);
    let e = err(load(&[&l], None, Purpose::Training));
    assert_eq!(
        e,
        format!(
            "{}:2: field `placement`: sequence `Jakob_Nexus5_NoDist_Hovering` has no placement \
             label, which training needs (give it after the path: `path,placement`)",
            l.display()
        )
    );
}

#[test]
fn missing_labels_ground_truth_and_sequences_name_the_list_file() {
    let dir = tempfile::tempdir().unwrap();
    // Empty, or only comments.
    for text in ["", "# nothing yet\n\n"] {
        let l = dir.path().join("empty.txt");
        std::fs::write(&l, text).unwrap();
        for purpose in [Purpose::Training, Purpose::Evaluation] {
            let e = err(load(&[&l], None, purpose));
            assert_eq!(
                e,
                format!(
                    "{}: no sequences listed (expected `path,placement` lines)",
                    l.display()
                )
            );
        }
    }
    // `path,` and `path`: no placement label, which training needs.
    for placement_cell in [",", ""] {
        let l = list(
            dir.path(),
            "ep.txt",
            &[
                line("Guillaume_Nexus5_NoDist_Texting", "Texting"),
                format!(
                    "{}{placement_cell}",
                    seq("Guillaume_Nexus5_NoDist_BackPocket").display()
                ),
            ],
        );
        let e = err(load(&[&l], None, Purpose::Training));
        assert!(
            e.starts_with(&format!("{}:2: field `placement`: ", l.display()))
                && e.contains("`Guillaume_Nexus5_NoDist_BackPocket` has no placement label"),
            "{e}"
        );
    }
    // No ground truth: neither training nor evaluation can use it.
    let mut parts = read_sequence(seq("Jakob_Nexus5_NoDist_Texting"), &ReadOptions::default())
        .unwrap()
        .into_parts();
    parts.ground_truth = None;
    parts.name = "nogt".into();
    std::fs::create_dir_all(dir.path().join("nogt/processed")).unwrap();
    write_ridi_csv(
        &Sequence::new(parts).unwrap(),
        dir.path().join("nogt/processed/data.csv"),
    )
    .unwrap();
    let l = list(
        dir.path(),
        "nogt.txt",
        &[
            line("Guillaume_Nexus5_NoDist_Texting", "Texting"),
            "# no ground truth:".into(),
            "nogt,Texting".into(),
        ],
    );
    for (purpose, name) in [
        (Purpose::Training, "training"),
        (Purpose::Evaluation, "evaluation"),
    ] {
        let e = err(load(&[&l], None, purpose));
        assert_eq!(
            e,
            format!(
                "{}:3: sequence `nogt` has no ground truth, which {name} needs",
                l.display()
            )
        );
    }
    // Several lists: the line is in the list that has it.
    let good = list(
        dir.path(),
        "good.txt",
        &[line("Thibaud_Nexus5_NoDist_Texting", "Texting")],
    );
    let e = err(load(&[good.as_path(), &l], None, Purpose::Training));
    assert!(e.starts_with(&format!("{}:3: ", l.display())), "{e}");
    // One recording in two lists: refused at the second, naming the first.
    let again = list(
        dir.path(),
        "again.txt",
        &[line("Thibaud_Nexus5_NoDist_Texting", "Texting")],
    );
    let e = err(load(&[good.as_path(), &again], None, Purpose::Training));
    assert!(
        e.starts_with(&format!("{}:1: field `path`: ", again.display()))
            && e.contains(&format!("already listed at {}:1", good.display())),
        "{e}"
    );
}

#[test]
fn labels_the_model_does_not_know_are_a_warning_in_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let l = list(
        dir.path(),
        "train.txt",
        &[
            line("Guillaume_Nexus5_NoDist_Texting", "Texting"),
            line("Guillaume_Nexus5_NoDist_BackPocket", "BackPocket"),
            line("Jakob_Nexus5_NoDist_Texting", "Texting"),
            line("Jakob_Nexus5_NoDist_BackPocket", "BackPocket"),
        ],
    );
    let tyrex4 = PlacementMap::tyrex4();
    let train = load(&[&l], Some(&tyrex4), Purpose::Training).unwrap();
    let mut opts = TrainOptions::default();
    opts.cascade.regressors = GridChoice::None.regressors();
    let model = ridi::train(&train, &opts, &mut NoProgress).unwrap();
    assert_eq!(model.placement_names(), ["hand", "pocket"]);

    let t = list(
        dir.path(),
        "test.txt",
        &[
            line("Thibaud_Nexus5_NoDist_Swinging", "Swinging"),
            line("Thibaud_Nexus5_NoDist_Texting", "Texting"),
        ],
    );
    let test = load(&[&t], Some(&tyrex4), Purpose::Evaluation).unwrap();
    let want = "placement `swing` of 1 sequence (Thibaud_Nexus5_NoDist_Swinging) is not one of \
                the model's classes (hand, pocket): its placement accuracy is 0";
    assert_eq!(ridi::placement_warnings(&test, &model), [want]);
    // Unmapped Tyrex motion names, one warning for both labels; no map to give, as `Swinging`'s
    // group, swing, is not the model's.
    let unmapped = load(&[&t], None, Purpose::Evaluation).unwrap();
    assert_eq!(
        ridi::placement_warnings(&unmapped, &model),
        [
            "2 placement labels are not among the model's classes (hand, pocket), so their \
          sequences' placement accuracy is 0: `Swinging` of 1 sequence \
          (Thibaud_Nexus5_NoDist_Swinging), `Texting` of 1 sequence \
          (Thibaud_Nexus5_NoDist_Texting)"
        ]
    );
    // Where the map takes every label to one of the model's classes, the warning gives it.
    let both = list(
        dir.path(),
        "both.txt",
        &[
            line("Thibaud_Nexus5_NoDist_Texting", "Texting"),
            line("Thibaud_Nexus5_NoDist_BackPocket", "BackPocket"),
        ],
    );
    let warnings =
        ridi::placement_warnings(&load(&[&both], None, Purpose::Evaluation).unwrap(), &model);
    assert!(
        warnings.len() == 1
            && warnings[0].ends_with(
                "(Thibaud_Nexus5_NoDist_Texting) (Tyrex motion names: give `--placement-map \
                 tyrex4`, in Python `placement_map=\"tyrex4\"`)"
            ),
        "{warnings:?}"
    );
    let opts = EvalOptions {
        methods: vec![Method::Ridi],
        ..EvalOptions::default()
    };
    let (report, _) = ridi::evaluate(&test, &model, &opts).unwrap();
    // Then the one about intervals: two runs are too few.
    assert_eq!(report.warnings[0], want);
    assert!(
        report.warnings[1].starts_with("2 sequences (2 runs, the parts of a recording split at")
            && report.warnings[1].contains("too few for 95 % intervals, which need 5 runs"),
        "{:?}",
        report.warnings
    );
    assert_eq!(report.warnings.len(), 2);
    assert_eq!(report.sequences[0].placement_accuracy, Some(0.0));
    assert!(report.to_markdown().contains(want));
    let json = serde_json::to_value(&report).unwrap();
    assert_eq!(json["warnings"][0], want);
    // Without a method that uses the model there is no placement accuracy to warn about.
    let pdr = EvalOptions {
        methods: vec![Method::Pdr],
        ..EvalOptions::default()
    };
    let (report, _) = ridi::evaluate(&test, &model, &pdr).unwrap();
    assert!(
        report.warnings.len() == 1 && report.warnings[0].contains("too few for 95 % intervals"),
        "{:?}",
        report.warnings
    );

    // Nothing to evaluate or train on is an error, not an empty result.
    assert!(ridi::evaluate(&[], &model, &opts).is_err());
    let opts = TrainOptions::default();
    let e = ridi::train(&[], &opts, &mut NoProgress).unwrap_err();
    assert_eq!(e.to_string(), "no sequences to train on");
}
