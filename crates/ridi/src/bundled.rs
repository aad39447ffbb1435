//! The model that ships inside the crate (feature `bundled-model`, on by default), so that a
//! phone can be tracked without training: `ridi track` and `ridi eval` use it when no
//! `--model` is given.
//!
//! It is a Nyström cascade ([`ridi_regress::Solver::Nystrom`]) trained on every run of the
//! committed Tyrex list (`datasets/protocols/tyrex-runs.txt`: a Nexus 5 with and without
//! magnetic disturbance and an iPhone 4S, three people, 4 placement groups, about 2.2 hours),
//! orientation estimated from gyro and accelerometer. `docs/model-card.md` in the repository
//! has its figures on each device and placement (trained without the test person), and what
//! it cannot be expected to do. `cargo xtask model` rebuilds it; the Tyrex data are CeCILL
//! v2.1 (`model/PROVENANCE.md` and the licence beside the file).

use std::collections::BTreeSet;

use ridi_data::Sequence;
use ridi_regress::{Cascade, RegressError};

/// The model file's bytes.
const BYTES: &[u8] = include_bytes!("../model/ridi-tyrex.ridi");

/// One line naming the bundled model, as the command line prints it when it uses it.
pub const BUNDLED_MODEL_SUMMARY: &str = "the bundled model (Nyström, trained on 66 Tyrex runs \
     of a Nexus 5 and an iPhone 4S, three people; its card: docs/model-card.md)";

/// The names of the runs the bundled model was trained on, one per line after `#` comments.
const TRAINING_RUNS: &str = include_str!("../model/training-runs.txt");

/// The names of the runs the bundled model was trained on (`Thibaud_Nexus5_NoDist_AR`, ...):
/// its figures on them, or on a part of one (`<run>_part2`), are not those of a person or phone
/// it never saw.
pub fn bundled_training_runs() -> impl Iterator<Item = &'static str> {
    TRAINING_RUNS
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
}

/// Whether a model whose bytes have `fingerprint` ([`crate::Provenance::model_fingerprint`]) is
/// the bundled model.
fn is_bundled(fingerprint: &str) -> bool {
    static BUNDLED: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    BUNDLED.get_or_init(|| crate::evaluate::fingerprint(BYTES)) == fingerprint
}

/// A warning when the model of `fingerprint` is the bundled one and some of `seqs` are runs it
/// was trained on
/// (or parts of them): its figures there are not a new person's or phone's.
pub(crate) fn trained_on_warning(seqs: &[Sequence], fingerprint: &str) -> Option<String> {
    if !is_bundled(fingerprint) {
        return None;
    }
    let runs: BTreeSet<&str> = bundled_training_runs().collect();
    let seen: Vec<&str> = seqs
        .iter()
        .map(Sequence::name)
        .filter(|name| runs.contains(ridi_eval::run_of(name)))
        .collect();
    (!seen.is_empty()).then(|| {
        format!(
            "{} of {} ({}) {} the runs the bundled model was trained on: its figures there are \
             not those of a person or phone it never saw (docs/model-card.md has those, each \
             person left out); to measure that on your data, evaluate a model trained without \
             them (`ridi train`, then `--model`; in Python `ridi.train`)",
            seen.len(),
            ridi_data::counted(seqs.len(), "sequence"),
            ridi_data::first_few(seen.iter(), 3),
            if seen.len() == 1 {
                "is one of"
            } else {
                "are among"
            },
        )
    })
}

/// The bundled model, decoded (a few milliseconds; decode once and keep it).
///
/// # Errors
/// Only if the bundled bytes do not decode, which a test of this crate rules out for every
/// build: `cargo xtask model` rebuilds the file after a format change.
pub fn bundled_model() -> Result<Cascade, RegressError> {
    Cascade::from_bytes(BYTES)
}
