//! Training: features and targets of labelled sequences, then the regression cascade.

use std::collections::BTreeSet;

use rayon::prelude::*;
use ridi_data::Sequence;
use ridi_features::{
    FeatureConfig, FeatureExtractor, FeatureMatrix, FeatureMatrixRef, GroundTruthView, Orientation,
    SampleSchedule, Standardization, compute_targets,
};
use ridi_frames::{Frame, Rot, StabHorizontal, UpAxis, Vec3};
use ridi_regress::{Cascade, CascadeParams, GridSpec, Progress, RegressorChoice, TrainingSet};
use serde::{Deserialize, Serialize};

use crate::error::{PipelineError, Result};
use crate::orientation::oriented;
use crate::track::check_frames;

/// Which regressor hyper-parameters to search.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum GridChoice {
    /// The paper's grid: C in {0.1, 1, 10, 100} x epsilon in {0.001, 0.01, 0.1, 1}, 3 folds.
    Paper,
    /// C in {1, 10} x epsilon in {0.01, 0.1}, 3 folds: a quick check.
    Small,
    /// No search: C = 10, epsilon = 0.01 for every placement and channel.
    None,
}

impl GridChoice {
    /// The regressor choice of this grid.
    pub fn regressors(self) -> RegressorChoice {
        match self {
            GridChoice::Paper => RegressorChoice::Grid(GridSpec::default()),
            GridChoice::Small => RegressorChoice::Grid(GridSpec {
                c: vec![1.0, 10.0],
                epsilon: vec![0.01, 0.1],
                ..GridSpec::default()
            }),
            GridChoice::None => RegressorChoice::Fixed {
                c: 10.0,
                epsilon: 0.01,
            },
        }
    }
}

/// How to train. [`Default`] is the paper's method (features, cascade, paper grid) with
/// additions measured on the Tyrex leave-one-subject-out protocol (docs/bench-accuracy.md):
/// one turned copy of each training window, taken every [`default_step`]`(1)` = 20 frames
/// instead of 10 (so the rows, and the training time, stay the paper's), a speed regressor
/// per placement, S built on device -y while the phone is upside down
/// ([`UpAxis::PlusOrMinusY`]), and the orientation estimated from gyro and accelerometer
/// ([`Orientation::Estimated`]; measured on the across-devices protocol, docs/bench-devices.md).
/// Set `turned_copies: 0`, `features.step: 10`, `features.up_axis: UpAxis::PlusY`,
/// `features.orientation: Orientation::Recorded` and `cascade.speed: false` for the paper's
/// cascade on standardized features, and `standardize: false` too for the original's raw
/// features.
#[derive(Debug, Clone, PartialEq)]
pub struct TrainOptions {
    /// Feature configuration (its `standardization` is filled in when `standardize` is set).
    pub features: FeatureConfig,
    /// Learn a per-dimension z-scoring on the training features (not in the paper; it made
    /// the placement classifier markedly better on the Tyrex data).
    pub standardize: bool,
    /// Cascade hyper-parameters.
    pub cascade: CascadeParams,
    /// Turned copies of each training window ([`TrainingData::with_turned_copies`]; not in
    /// the paper, default 1): 0 trains on the windows as recorded. Training time grows faster
    /// than the square of the rows, hence the default step of 20 frames with one copy.
    pub turned_copies: usize,
}

/// Training sample step for `turned_copies` copies of each window: the paper's 10 frames times
/// `turned_copies + 1`, so that the number of rows stays the paper's.
pub const fn default_step(turned_copies: usize) -> usize {
    10usize.saturating_mul(turned_copies.saturating_add(1))
}

impl Default for TrainOptions {
    fn default() -> Self {
        Self {
            features: FeatureConfig {
                step: default_step(1),
                up_axis: UpAxis::PlusOrMinusY,
                orientation: Orientation::Estimated,
                ..FeatureConfig::default()
            },
            standardize: true,
            cascade: CascadeParams {
                regressors: GridChoice::Paper.regressors(),
                speed: true,
                ..CascadeParams::default()
            },
            turned_copies: 1,
        }
    }
}

/// Features, targets and labels of a training set, one row per sample, the sequences' rows in
/// an order of their own (by name, then content), so that the order in which sequences are
/// given changes neither these rows nor the model trained on them.
#[derive(Debug, Clone, PartialEq)]
pub struct TrainingData {
    /// Features (`n x dim`), not standardized.
    pub features: FeatureMatrix,
    /// Targets `[S-x, S-z]`, m/s.
    pub targets: Vec<StabHorizontal>,
    /// Placement index of each sample into `placement_names`.
    pub placements: Vec<usize>,
    /// Placement names, sorted.
    pub placement_names: Vec<String>,
    /// The sequence each sample comes from, numbered in the rows' order (not the order the
    /// sequences were given in).
    pub groups: Vec<u64>,
}

impl TrainingData {
    /// Adds `copies` copies of every sample turned about S-up, features and targets together
    /// ([`ridi_features::turned_copies`]), with the placement and group of the sample they
    /// come from (so cross-validation folds still keep a sequence whole). Teaches the
    /// regressors that the velocity turns with the signal, for people who carry the phone at
    /// other headings than the training people did.
    pub fn with_turned_copies(self, copies: usize) -> Result<Self> {
        if copies == 0 {
            return Ok(self);
        }
        // The fields are public: rows whose placements or groups do not match are refused.
        let rows = self.features.rows();
        for (what, found) in [
            ("placements (one per feature row)", self.placements.len()),
            ("group ids (one per feature row)", self.groups.len()),
        ] {
            if found != rows {
                return Err(PipelineError::Features(
                    ridi_features::FeatureError::LengthMismatch {
                        what,
                        expected: rows,
                        found,
                    },
                ));
            }
        }
        let turned = ridi_features::turned_copies(&self.features, &self.targets, copies)?;
        Ok(Self {
            placements: turned.source.iter().map(|&i| self.placements[i]).collect(),
            groups: turned.source.iter().map(|&i| self.groups[i]).collect(),
            features: turned.features,
            targets: turned.targets,
            placement_names: self.placement_names,
        })
    }
}

/// Ground truth of `seq` as target input; an error names the sequence when it has none.
pub fn ground_truth_view(seq: &Sequence) -> Result<GroundTruthView<'_>> {
    let gt = seq
        .ground_truth()
        .ok_or_else(|| PipelineError::sequence(seq.name(), "has no ground truth"))?;
    Ok(GroundTruthView {
        time: seq.time(),
        position: &gt.position,
        orientation: &gt.orientation,
        gravity: seq.gravity(),
    })
}

/// Features and targets of every sequence at the training schedule of `config` (standardization
/// in `config` is ignored: it is learned from this data).
pub fn training_data(seqs: &[Sequence], config: &FeatureConfig) -> Result<TrainingData> {
    if seqs.is_empty() {
        return Err(PipelineError::NoSequences("train on"));
    }
    crate::check_distinct_recordings(seqs)?;
    let config = FeatureConfig {
        standardization: None,
        ..config.clone()
    };
    let names: BTreeSet<&str> = seqs
        .iter()
        .map(|s| {
            s.placement().ok_or_else(|| {
                PipelineError::sequence(
                    s.name(),
                    "has no placement label (give it in the list file, or set it: `with_placement` in \
                     Python, `Sequence::set_placement` in Rust)",
                )
            })
        })
        .collect::<Result<_>>()?;
    let names: Vec<String> = names.into_iter().map(str::to_string).collect();
    // Every sequence before any work, in the order given: a bad one fails at once and the
    // same one whatever the threads (the parallel pass below would report whichever it met).
    for s in seqs {
        check_frames(s, &config)?;
        ground_truth_view(s)?;
    }
    let ordered = canonical_order(seqs);
    let schedule = SampleSchedule::training(&config)?;
    let fx = FeatureExtractor::new(config.clone())?;
    let per_seq: Vec<(FeatureMatrix, Vec<StabHorizontal>)> = ordered
        .par_iter()
        .map(|s| {
            // Features and targets do not see the heading (both live in S, and targets come
            // from the ground truth's orientation), so training skips its correction.
            let s = oriented(s, config.orientation, None)?;
            let s = s.as_ref();
            let frames = schedule.frames(s.len());
            let features = fx.features(&fx.stabilize(&s.imu())?, &frames)?;
            let targets = compute_targets(&ground_truth_view(s)?, &config, &frames)?;
            Ok((features, targets.values))
        })
        .collect::<Vec<Result<_>>>()
        .into_iter()
        .collect::<Result<_>>()?;
    let mut data = TrainingData {
        features: FeatureMatrix::zeros(0, fx.dim()),
        targets: Vec::new(),
        placements: Vec::new(),
        placement_names: names,
        groups: Vec::new(),
    };
    for (g, (&seq, (features, targets))) in ordered.iter().zip(per_seq).enumerate() {
        let p = data
            .placement_names
            .iter()
            .position(|n| Some(n.as_str()) == seq.placement())
            .unwrap_or_default();
        data.features.append(&features)?;
        data.placements
            .extend(std::iter::repeat_n(p, targets.len()));
        data.groups
            .extend(std::iter::repeat_n(g as u64, targets.len()));
        data.targets.extend(targets);
    }
    if data.targets.is_empty() {
        return Err(PipelineError::sequence(
            seqs.first().map(|s| s.name()).unwrap_or("(none)"),
            format!(
                "no training sample: every sequence is shorter than the {}-frame window",
                config.window
            ),
        ));
    }
    Ok(data)
}

/// `seqs` in an order of their own: by name and placement label, then length, then the bit
/// patterns of every channel training reads (timestamps, IMU, gravity, orientation, ground
/// truth), so that sequences it cannot tell apart give the same rows. The rows of
/// [`training_data`] follow it, and the solvers are order-sensitive (the Nyström landmark
/// draw and its classifier's sweeps, the folds of the grid search): without it, the same
/// recordings listed in another order would give another model, and `ridi train` on `ridi
/// convert`'s lists another model than training on the reader's sequences.
fn canonical_order(seqs: &[Sequence]) -> Vec<&Sequence> {
    fn vecs<F: Frame>(v: &[Vec3<F>]) -> impl Iterator<Item = u64> + '_ {
        v.iter().flat_map(|v| v.to_array()).map(f64::to_bits)
    }
    fn rots<A: Frame, B: Frame>(r: &[Rot<A, B>]) -> impl Iterator<Item = u64> + '_ {
        r.iter().flat_map(|q| q.to_wxyz()).map(f64::to_bits)
    }
    // Lazy: two sequences are compared only as far as they agree.
    fn content(s: &Sequence) -> impl Iterator<Item = u64> + '_ {
        let gt = s.ground_truth();
        let gt_position = gt.map_or(&[][..], |g| &g.position[..]);
        let gt_orientation = gt.map_or(&[][..], |g| &g.orientation[..]);
        s.time()
            .iter()
            .map(|t| t.to_bits())
            .chain(vecs(s.gyro()))
            .chain(vecs(s.acce()))
            .chain(vecs(s.linacce()))
            .chain(vecs(s.gravity()))
            .chain(rots(s.orientation()))
            .chain(std::iter::once(u64::from(gt.is_some())))
            .chain(vecs(gt_position))
            .chain(rots(gt_orientation))
    }
    let mut order: Vec<&Sequence> = seqs.iter().collect();
    order.sort_by(|a, b| {
        (a.name(), a.placement(), a.len())
            .cmp(&(b.name(), b.placement(), b.len()))
            .then_with(|| content(a).cmp(content(b)))
    });
    order
}

/// The training windows (rows) [`train`] would build from `seqs` with `opts`, turned copies
/// included, counted from the sequences' lengths alone: what training will cost before it
/// starts (the exact solver's time grows faster than the square of the rows).
pub fn training_windows(seqs: &[Sequence], opts: &TrainOptions) -> Result<usize> {
    let schedule = SampleSchedule::training(&opts.features)?;
    let windows: usize = seqs.iter().map(|s| schedule.frames(s.len()).len()).sum();
    opts.turned_copies
        .checked_add(1)
        .and_then(|copies| windows.checked_mul(copies))
        .ok_or_else(|| {
            PipelineError::Features(ridi_features::FeatureError::InvalidConfig(format!(
                "{windows} windows with {} turned copies each: too many rows to count",
                opts.turned_copies
            )))
        })
}

/// Fewer changes of velocity a second than this, and the ground truth moves in straight lines
/// at constant speed between a few points: waypoints, interpolated. Counted per second, not per
/// frame, so that the frame rate does not matter (a change: an acceleration over 0.2 m/s²
/// between two frames' velocities). Measured: the 12 Indoor Location Competition paths of
/// `../shared`, converted, 0.1-0.35 a second (a waypoint every 2-10 s, each a change over one
/// or two frames); the motion capture of every part of every shared Tyrex run, 82 a second and
/// more.
pub const MIN_VELOCITY_CHANGES_PER_S: f64 = 2.0;

/// An acceleration (m/s²) between two frames' velocities that counts as a change of velocity
/// ([`MIN_VELOCITY_CHANGES_PER_S`]): far above what timestamps' round-off (f64 seconds since
/// 1970, about 0.2 µs) makes of a straight line walked briskly, far below a step's.
const VELOCITY_CHANGE_M_S2: f64 = 0.2;

/// What a training set holds that is no error but makes a poorer model, one warning per kind,
/// for the caller to show (`ridi train` prints them; Python warns): sequences whose ground
/// truth moves in straight lines at constant speed between a few points (waypoints,
/// [`MIN_VELOCITY_CHANGES_PER_S`]), whose velocity targets are those lines' average speeds, not the
/// walk's. A ground truth that never changes velocity (a still or synthetic recording) is not
/// named: nothing tells it from a walk in one straight line.
pub fn training_warnings(seqs: &[Sequence]) -> Vec<String> {
    let straight: Vec<String> = seqs
        .iter()
        .filter_map(|s| {
            let changes = velocity_changes(s)?;
            let per_s = changes as f64 / s.duration();
            (changes > 0 && per_s < MIN_VELOCITY_CHANGES_PER_S)
                .then(|| format!("{} ({per_s:.1} a second)", ridi_data::shown(s.name())))
        })
        .collect();
    if straight.is_empty() {
        return Vec::new();
    }
    vec![format!(
        "{} of {} ({}) {} a ground truth that moves in straight lines at constant speed between \
         a few points, its velocity changing under {MIN_VELOCITY_CHANGES_PER_S} times a second (waypoints, \
         as the Indoor Location Competition's; motion capture's changes at every frame): the \
         velocity targets are those lines' average speeds, not the walk's, and a model learns \
         them; train on motion capture or a visual-inertial track (docs/datasets.md), and keep \
         waypoints to evaluate positions",
        straight.len(),
        ridi_data::counted(seqs.len(), "training sequence"),
        ridi_data::first_few(straight.iter(), 3),
        if straight.len() == 1 { "has" } else { "have" },
    )]
}

/// How many times the horizontal velocity of `seq`'s ground truth changes between frames
/// ([`VELOCITY_CHANGE_M_S2`]); `None` without ground truth.
fn velocity_changes(seq: &Sequence) -> Option<usize> {
    let (t, p) = (seq.time(), &seq.ground_truth()?.position);
    let velocity: Vec<[f64; 2]> = t
        .windows(2)
        .zip(p.windows(2))
        .map(|(t, p)| {
            let dt = t[1] - t[0];
            [(p[1].x() - p[0].x()) / dt, (p[1].y() - p[0].y()) / dt]
        })
        .collect();
    let changes = velocity.windows(2).zip(t.windows(3)).filter(|(v, t)| {
        let dt = 0.5 * (t[2] - t[0]);
        (v[1][0] - v[0][0]).hypot(v[1][1] - v[0][1]) > VELOCITY_CHANGE_M_S2 * dt
    });
    Some(changes.count())
}

/// Trains the cascade on labelled sequences (placement and ground truth required).
pub fn train(
    seqs: &[Sequence],
    opts: &TrainOptions,
    progress: &mut dyn Progress,
) -> Result<Cascade> {
    let mut data = training_data(seqs, &opts.features)?.with_turned_copies(opts.turned_copies)?;
    let mut config = FeatureConfig {
        standardization: None,
        ..opts.features.clone()
    };
    if opts.standardize {
        let s = Standardization::fit([&data.features])?;
        s.apply(&mut data.features)?;
        config.standardization = Some(s);
    }
    let set = TrainingSet {
        features: FeatureMatrixRef::try_from(&data.features)?,
        targets: &data.targets,
        placements: &data.placements,
        placement_names: &data.placement_names,
        groups: &data.groups,
        feature_config: &config,
    };
    Cascade::train(&set, &opts.cascade, progress).map_err(|e| match e {
        // One window every `step` frames: a coarse step leaves a placement few samples.
        ridi_regress::RegressError::NotEnoughData(why) => {
            ridi_regress::RegressError::NotEnoughData(format!(
                "{why} (training takes a window every {} frames of {}: a smaller sample \
                 step, `--step`, or more recordings of that placement give more)",
                config.step,
                ridi_data::counted(seqs.len(), "sequence")
            ))
            .into()
        }
        e => e.into(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turned_copies_of_rows_without_their_labels_are_refused() {
        let data = TrainingData {
            features: FeatureMatrix::zeros(10, 1200),
            targets: vec![StabHorizontal::new(1.0, 0.0); 10],
            placements: vec![0; 5],
            placement_names: vec!["hand".into()],
            groups: vec![0; 10],
        };
        let e = data.clone().with_turned_copies(1).unwrap_err().to_string();
        assert!(e.contains("placements") && e.contains("10"), "{e}");
        let data = TrainingData {
            placements: vec![0; 10],
            groups: vec![0; 3],
            ..data
        };
        let e = data.clone().with_turned_copies(1).unwrap_err().to_string();
        assert!(e.contains("group ids"), "{e}");
        let data = TrainingData {
            groups: vec![0; 10],
            ..data
        };
        assert_eq!(data.with_turned_copies(1).unwrap().placements.len(), 20);
    }
}
