//! List files for training and evaluation: the sequences with the labels those need, checked
//! where a user can fix them, at the list file and line.

use ridi_data::{DataError, ListEntry, Listed, ReadOptions, Sequence};

use crate::error::{PipelineError, Result};
use crate::placement::PlacementMap;

/// What the listed sequences are for, and so what each must have.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Purpose {
    /// Training: ground truth and a placement label.
    Training,
    /// Evaluation: ground truth; a placement label is optional (without one a sequence has no
    /// placement accuracy).
    Evaluation,
}

impl Purpose {
    fn name(self) -> &'static str {
        match self {
            Purpose::Training => "training",
            Purpose::Evaluation => "evaluation",
        }
    }
}

/// Reads the sequences of the list `entries` ([`ListEntry::read`]), in order, for `purpose`,
/// and relabels their placements with `map` when given: [`Listed::load`] with the checks that
/// training and evaluation need. Every error names the list file and line of the sequence
/// concerned:
///
/// - a listed path that does not exist, or a recording listed twice ([`Listed::load`]);
/// - a placement label `map` does not have (at the first sequence with that label; the labels
///   written in the lists are checked before any sequence is read);
/// - for training, a sequence without a placement label (neither in the list nor from its
///   source, as a Tyrex run's motion);
/// - a sequence without ground truth;
/// - for evaluation, two sequences of the same name (from different folders): the report's
///   rows and plot files are named after the sequence.
pub fn load_listed(
    entries: Vec<ListEntry>,
    map: Option<&PlacementMap>,
    purpose: Purpose,
    opts: &ReadOptions,
) -> Result<Listed> {
    if let Some(map) = map {
        for e in &entries {
            if let Some(label) = &e.placement {
                map.class_at(label, e.location())?;
            }
        }
    }
    let mut listed = Listed::load(entries, opts)?;
    let (seqs, entries) = (listed.sequences(), listed.entries());
    let mut labels = Vec::with_capacity(seqs.len());
    for (seq, entry) in seqs.iter().zip(entries) {
        labels.push(check(seq, entry, map, purpose)?);
    }
    if purpose == Purpose::Evaluation {
        for (i, (seq, entry)) in seqs.iter().zip(entries).enumerate() {
            if let Some(j) = seqs[..i].iter().position(|s| s.name() == seq.name()) {
                return Err(DataError::format(
                    entry.location().with_field("path"),
                    format!(
                        "a sequence named `{}` is already listed at {}:{} (another recording): \
                         an evaluation names its report rows and plots after the sequence; \
                         rename one",
                        ridi_data::shown(seq.name()),
                        ridi_data::shown(&entries[j].list),
                        entries[j].line
                    ),
                )
                .into());
            }
        }
    }
    for (seq, label) in listed.sequences_mut().iter_mut().zip(labels) {
        if let Some(class) = label {
            seq.set_placement(Some(class));
        }
    }
    Ok(listed)
}

/// Checks one listed sequence for `purpose`; its placement class in `map`, when there is one.
fn check(
    seq: &Sequence,
    entry: &ListEntry,
    map: Option<&PlacementMap>,
    purpose: Purpose,
) -> Result<Option<String>> {
    if seq.ground_truth().is_none() {
        return Err(DataError::format(
            entry.location(),
            format!(
                "sequence `{}` has no ground truth, which {} needs",
                seq.name(),
                purpose.name()
            ),
        )
        .into());
    }
    match (seq.placement(), map) {
        (None, _) if purpose == Purpose::Training => Err(DataError::format(
            entry.location().with_field("placement"),
            format!(
                "sequence `{}` has no placement label, which training needs (give it after the \
                 path: `path,placement`)",
                seq.name()
            ),
        )
        .into()),
        (Some(label), Some(map)) => Ok(Some(map.class_at(label, entry.location())?.to_string())),
        _ => Ok(None),
    }
}

impl PipelineError {
    /// This error at the list file and line of the sequence it is about
    /// ([`PipelineError::Listed`]), when it is a [`PipelineError::Sequence`] error and that
    /// sequence's name is one sequence's alone in `listed` (training takes recordings of one
    /// name); otherwise the error as it is.
    pub fn locate_in(self, listed: &Listed) -> PipelineError {
        let PipelineError::Sequence { sequence, .. } = &self else {
            return self;
        };
        let mut named = listed
            .sequences()
            .iter()
            .enumerate()
            .filter(|(_, s)| s.name() == sequence);
        match (named.next(), named.next()) {
            (Some((i, _)), None) => PipelineError::Listed {
                at: listed.entries()[i].location(),
                source: Box::new(self),
            },
            _ => self,
        }
    }
}

/// Refuses two of `seqs` that are one recording, whatever their names
/// ([`Sequence::is_same_recording`]): it would count twice in every mean, or be tested on after
/// training on it. [`Listed::load`] refuses copies within list files; this makes the same check
/// for sequences given otherwise (built in a program, in Python). The error names the later
/// one and the index of the earlier.
pub fn check_distinct_recordings(seqs: &[Sequence]) -> Result<()> {
    match Sequence::first_repeated(seqs) {
        Some((i, j)) => Err(PipelineError::sequence(
            seqs[j].name(),
            format!(
                "is the same recording as sequence {i}, `{}` (the same timestamps, gyro and \
                 accelerometer samples); given twice it would count twice in a \
                 training or in an evaluation's means",
                ridi_data::shown(seqs[i].name())
            ),
        )),
        None => Ok(()),
    }
}
