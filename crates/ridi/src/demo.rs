//! The demo (`ridi demo`): train on the training list of a sample folder, evaluate on its
//! held-out list, and write the model, the reports and the plots into one folder.
//!
//! Everything that can be checked is checked before the training, so that a bad recording or
//! output folder fails in a second rather than after it: the output folder, the lists, that no
//! recording is on both (also not as a copy in another folder or format), and that every
//! held-out run can be evaluated.

use std::path::Path;

use ridi_data::{ListEntry, Listed, ReadOptions, Sequence};
use ridi_regress::{Cascade, Progress};

use crate::error::Result;
use crate::evaluate::{EvalOptions, Report, Traces, check_evaluable};
use crate::lists::{Purpose, load_listed};
use crate::output::{EvalFolder, EvalPlots, EvalWritten};
use crate::placement::PlacementMap;
use crate::train::{GridChoice, TrainOptions};

/// A demo ready to run: its sequences read and checked, its output folder checked. Its steps
/// are separate so that a caller can report on each: [`Demo::train`], [`Demo::evaluate`],
/// [`Demo::write`]. An error about one listed sequence names its list file and line.
#[derive(Debug)]
pub struct Demo {
    train: Listed,
    test: Listed,
    options: TrainOptions,
    folder: EvalFolder,
}

/// The model's file name in the demo's output folder.
const MODEL_FILE: &str = "model.ridi";

impl Demo {
    /// Reads the demo in `data` (`list_train.txt` and `list_test.txt`, labels grouped as the
    /// four Tyrex groups, [`PlacementMap::tyrex4`]) to write into `out`, with the
    /// regressor search `grid` and `plots`. Refused: an output folder that cannot be written,
    /// list errors, a recording on both lists or in both as copies, and each sequence's
    /// problems as [`load_listed`] finds them.
    pub fn prepare(data: &Path, out: &Path, grid: GridChoice, plots: EvalPlots) -> Result<Self> {
        let folder = EvalFolder::new(out, plots)?;
        let map = PlacementMap::tyrex4();
        let read = ReadOptions::default();
        let load = |list: &str, purpose| {
            let entries = ListEntry::read(&[data.join(list)])?;
            load_listed(entries, Some(&map), purpose, &read)
        };
        let train = load("list_train.txt", Purpose::Training)?;
        let test = load("list_test.txt", Purpose::Evaluation)?;
        // Held out means held out: no recording on both lists, also not as a copy in another
        // folder or format.
        train.check_distinct(&test)?;
        let mut options = TrainOptions::default();
        options.cascade.regressors = grid.regressors();
        Ok(Self {
            train,
            test,
            options,
            folder,
        })
    }

    /// The training sequences.
    pub fn train_sequences(&self) -> &[Sequence] {
        self.train.sequences()
    }

    /// The held-out sequences.
    pub fn test_sequences(&self) -> &[Sequence] {
        self.test.sequences()
    }

    /// The output folder.
    pub fn folder(&self) -> &EvalFolder {
        &self.folder
    }

    /// Checks that every held-out run can be evaluated ([`check_evaluable`]), then trains the
    /// model on the training sequences ([`crate::train()`]), reporting to `progress`.
    pub fn train(&self, progress: &mut dyn Progress) -> Result<Cascade> {
        // A held-out run that cannot be evaluated fails before the training, not after it.
        for seq in self.test.sequences() {
            check_evaluable(seq, &self.options.features, &EvalOptions::default())
                .map_err(|e| e.locate_in(&self.test))?;
        }
        crate::train(self.train.sequences(), &self.options, progress)
            .map_err(|e| e.locate_in(&self.train))
    }

    /// Evaluates `model` on the held-out sequences with every method ([`crate::evaluate()`]
    /// with the default [`EvalOptions`]).
    pub fn evaluate(&self, model: &Cascade) -> Result<(Report, Vec<Traces>)> {
        crate::evaluate(self.test.sequences(), model, &EvalOptions::default())
            .map_err(|e| e.locate_in(&self.test))
    }

    /// Writes `model` (as `model.ridi`), `report` and the plots of `traces` into the output
    /// folder, all or nothing ([`EvalFolder::write`]).
    pub fn write(
        &self,
        model: &Cascade,
        report: &Report,
        traces: &[Traces],
    ) -> Result<EvalWritten> {
        self.folder
            .write(report, traces, Some((MODEL_FILE, model)))
            .map_err(|e| e.locate_in(&self.test))
    }
}
