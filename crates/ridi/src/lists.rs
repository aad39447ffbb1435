//! List files for training and evaluation: the sequences with the labels those need, checked
//! where a user can fix them, at the list file and line.

use std::path::Path;

use ridi_data::{DataError, ListEntry, ReadOptions, Sequence, load_entries, read_list};

use crate::error::{PipelineError, Result};
use crate::placement::PlacementMap;

/// Sequences read from list files, each with the list entry (file and line) it was read from,
/// so that an error found later about one of them (a recording too short to track, say) can
/// name its list line too.
#[derive(Debug, Clone)]
pub struct Listed {
    sequences: Vec<Sequence>,
    entries: Vec<ListEntry>,
}

impl Listed {
    /// [`load_listed`], keeping the entries.
    pub fn load(
        entries: Vec<ListEntry>,
        map: Option<&PlacementMap>,
        purpose: Purpose,
        opts: &ReadOptions,
    ) -> Result<Self> {
        let sequences = load_listed(&entries, map, purpose, opts)?;
        Ok(Self { sequences, entries })
    }

    /// The sequences, in list order.
    pub fn sequences(&self) -> &[Sequence] {
        &self.sequences
    }

    /// The list entry of each sequence.
    pub fn entries(&self) -> &[ListEntry] {
        &self.entries
    }

    /// `e` at the list file and line of the sequence it is about ([`PipelineError::Listed`]),
    /// when it is a [`PipelineError::Sequence`] error and that sequence's name is one listed
    /// sequence's alone (training takes recordings of one name); otherwise `e` as it is.
    pub fn locate(&self, e: PipelineError) -> PipelineError {
        let PipelineError::Sequence { sequence, .. } = &e else {
            return e;
        };
        let mut named = self
            .sequences
            .iter()
            .enumerate()
            .filter(|(_, s)| s.name() == sequence);
        match (named.next(), named.next()) {
            (Some((i, _)), None) => PipelineError::Listed {
                at: self.entries[i].location(),
                source: Box::new(e),
            },
            _ => e,
        }
    }
}

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

/// Reads the sequences of the list files `lists`, in order, for `purpose`, and relabels their
/// placements with `map` when given. Every error names the list file and line of the sequence
/// concerned:
///
/// - a list that lists nothing ("no sequences listed"), or a listed path that does not exist;
/// - a placement label `map` does not have (at the first sequence with that label; the labels
///   written in the lists are checked before any sequence is read);
/// - for training, a sequence without a placement label (neither in the list nor from its
///   source, as a Tyrex run's motion);
/// - a sequence without ground truth;
/// - a recording listed twice ([`ridi_data::load_entries`]);
/// - for evaluation, two sequences of the same name (from different folders): the report's
///   rows and plot files are named after the sequence.
pub fn load_lists(
    lists: &[impl AsRef<Path>],
    map: Option<&PlacementMap>,
    purpose: Purpose,
    opts: &ReadOptions,
) -> Result<Vec<Sequence>> {
    load_listed(&read_lists(lists)?, map, purpose, opts)
}

/// The entries of the list files `lists`, in order (syntax checked, sequences not read).
pub fn read_lists(lists: &[impl AsRef<Path>]) -> Result<Vec<ListEntry>> {
    let mut entries = Vec::new();
    for list in lists {
        entries.extend(read_list(list)?);
    }
    Ok(entries)
}

/// [`load_lists`] for list entries already read ([`read_list`]): the sequence of each entry,
/// in order, so that a caller can name an entry's list file and line in later errors.
pub fn load_listed(
    entries: &[ListEntry],
    map: Option<&PlacementMap>,
    purpose: Purpose,
    opts: &ReadOptions,
) -> Result<Vec<Sequence>> {
    if let Some(map) = map {
        for e in entries {
            if let Some(label) = &e.placement {
                map.class_at(label, e.location())?;
            }
        }
    }
    let mut seqs = load_entries(entries, opts)?;
    for (seq, entry) in seqs.iter_mut().zip(entries) {
        check(seq, entry, map, purpose)?;
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
                        seq.name(),
                        entries[j].list.display(),
                        entries[j].line
                    ),
                )
                .into());
            }
        }
    }
    Ok(seqs)
}

/// Checks one listed sequence for `purpose` and maps its placement.
fn check(
    seq: &mut Sequence,
    entry: &ListEntry,
    map: Option<&PlacementMap>,
    purpose: Purpose,
) -> Result<()> {
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
        (Some(label), Some(map)) => {
            let class = map.class_at(label, entry.location())?.to_string();
            seq.set_placement(Some(class));
            Ok(())
        }
        _ => Ok(()),
    }
}
