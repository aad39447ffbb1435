//! What the pipeline's commands write, and how: an output is checked before any work, and
//! written all or nothing.
//!
//! - [`check_output_file`], [`check_output_folder`] and [`check_not_input`] refuse, in a
//!   second, an output that could not be written after minutes of training or tracking, or
//!   that would replace what the command reads. They make and remove an empty temporary folder
//!   to see that the folder takes new entries, as the write will need.
//! - [`TrackOutput`]: a trajectory CSV and, optionally, its plot, both written in full before
//!   either replaces a file.
//! - [`EvalFolder`]: an evaluation's folder (`report.json`, `report.md`, `plots/`, and the
//!   model for the demo), written through [`Staging`] all or nothing, the plots an earlier
//!   evaluation left there that this one did not write removed with the same commit, so that
//!   the folder matches its report.
//! - [`save_model`]: a model file.
//!
//! Every file goes through [`ridi_data::write_atomically`] (or [`ridi_data::write_pending`],
//! its first half), the one writer of ridi-rs, with its one permission mode.

use std::path::{Path, PathBuf};

use ridi_data::{
    Sequence, TEMPORARY_FILE_PREFIX, register_temporary, temporary_prefix, write_pending,
};
use ridi_regress::Cascade;

use crate::error::{PipelineError, Result};
use crate::evaluate::{Report, Traces};
use crate::source::{ReadFiles, folder_of, resolved};
use crate::staging::Staging;
use crate::track::Track;

/// An output that cannot be written, or must not be. Each message names the output as the
/// user gave it.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OutputError {
    /// The folder of an output file does not exist.
    #[error(
        "cannot write {}: the folder {} does not exist",
        ridi_data::shown(path),
        ridi_data::shown(folder)
    )]
    NoFolder {
        /// The output file.
        path: PathBuf,
        /// Its folder.
        folder: PathBuf,
    },
    /// The folder of an output file, or one on the way to it, is a file.
    #[error(
        "cannot write {}: {} is a file, not a folder",
        ridi_data::shown(path),
        ridi_data::shown(file)
    )]
    FolderIsFile {
        /// The output file.
        path: PathBuf,
        /// The file on its folder's path.
        file: PathBuf,
    },
    /// An output file's path ends in `/` (or `.`, `..`): it names a folder, even one that does
    /// not exist, which no file can be written as.
    #[error(
        "cannot write {}: a path ending in `/`, `.` or `..` names a folder; give a file name",
        ridi_data::shown(path)
    )]
    FolderName {
        /// The output file.
        path: PathBuf,
    },
    /// An output file's path is a folder.
    #[error("cannot write {}: it is a folder", ridi_data::shown(path))]
    IsFolder {
        /// The output file.
        path: PathBuf,
    },
    /// An output file's path is no file ridi writes ([`ridi_data::output_target`]): a device,
    /// a pipe or a socket, or a link in a loop.
    #[error("cannot write {}: it {error}", ridi_data::shown(path))]
    NotRegular {
        /// The output file.
        path: PathBuf,
        /// Why.
        error: std::io::Error,
    },
    /// The folder of an output file takes no new files.
    #[error(
        "cannot write {}: cannot create files in {} ({kind})",
        ridi_data::shown(path),
        ridi_data::shown(folder)
    )]
    FolderNotWritable {
        /// The output file.
        path: PathBuf,
        /// Its folder.
        folder: PathBuf,
        /// Why, as the system said it.
        kind: std::io::ErrorKind,
    },
    /// An output folder is a file.
    #[error(
        "cannot write into {}: it is a file, not a folder",
        ridi_data::shown(dir)
    )]
    IsFile {
        /// The output folder.
        dir: PathBuf,
    },
    /// An output folder would have to be made inside a file.
    #[error(
        "cannot write into {}: {} is a file, not a folder",
        ridi_data::shown(dir),
        ridi_data::shown(file)
    )]
    InsideFile {
        /// The output folder.
        dir: PathBuf,
        /// The nearest existing path on the way to it, a file.
        file: PathBuf,
    },
    /// An output folder could not be made, or takes no new entries.
    #[error(
        "cannot write into {}: cannot create folders in {} ({kind})",
        ridi_data::shown(dir),
        ridi_data::shown(existing)
    )]
    ParentNotWritable {
        /// The output folder.
        dir: PathBuf,
        /// The output folder, or the nearest existing folder it would be made in.
        existing: PathBuf,
        /// Why, as the system said it.
        kind: std::io::ErrorKind,
    },
    /// An output would replace a file the command reads. The input is named when it is given
    /// by another path (a link, `..`, a hard link), not again when it is the output's.
    #[error(
        "cannot write {}: the command reads it{}; choose another output",
        ridi_data::shown(path),
        if path == input {
            String::new()
        } else {
            format!(" as {}", ridi_data::shown(input))
        }
    )]
    Input {
        /// The output.
        path: PathBuf,
        /// The input, as given.
        input: PathBuf,
    },
    /// One file is given as two outputs, which would overwrite each other.
    #[error("cannot write {}: it is given as two outputs", ridi_data::shown(path))]
    TwoOutputs {
        /// The output.
        path: PathBuf,
    },
    /// A plot's path does not name a plot format (`.svg`, `.png`).
    #[cfg(feature = "plot")]
    #[error(transparent)]
    PlotFormat(crate::plot::PlotError),
    /// The file system refused to write an output file (full, read-only, gone): the error is
    /// its own, without the path again.
    #[error("cannot write {}", ridi_data::shown(path))]
    Io {
        /// The output file.
        path: PathBuf,
        /// What the file system said.
        #[source]
        error: std::io::Error,
    },
    /// Writing an output file failed.
    #[error("cannot write {}", ridi_data::shown(path))]
    Write {
        /// The output file.
        path: PathBuf,
        /// What failed.
        #[source]
        source: Box<PipelineError>,
    },
    /// Writing into an output folder failed.
    #[error("cannot write into {}", ridi_data::shown(dir))]
    WriteInto {
        /// The output folder.
        dir: PathBuf,
        /// What failed.
        #[source]
        source: Box<PipelineError>,
    },
}

impl OutputError {
    fn write(path: &Path, source: impl Into<PipelineError>) -> Self {
        match source.into() {
            // An I/O error of this very file names it already: keep the cause only, so that
            // the message does not name the file twice.
            PipelineError::Data(ridi_data::DataError::Io { path: p, error }) if p == path => {
                OutputError::Io { path: p, error }
            }
            source => OutputError::Write {
                path: path.to_path_buf(),
                source: Box::new(source),
            },
        }
    }
}

/// Refuses an output file that cannot be written: its folder missing, not a folder or taking
/// no new files, or the path itself a folder. For a check before long work (training,
/// tracking) rather than a failure after it.
pub fn check_output_file(path: &Path) -> Result<(), OutputError> {
    if names_a_folder(path) {
        return Err(OutputError::FolderName {
            path: path.to_path_buf(),
        });
    }
    // Through a symbolic link, the file it leads to is the one written.
    let target = ridi_data::output_target(path).map_err(|error| OutputError::NotRegular {
        path: path.to_path_buf(),
        error,
    })?;
    let folder = folder_of(&target);
    if let Some(file) = folder.ancestors().find(|d| d.exists() && !d.is_dir()) {
        return Err(OutputError::FolderIsFile {
            path: path.to_path_buf(),
            file: file.to_path_buf(),
        });
    }
    if !folder.is_dir() {
        return Err(OutputError::NoFolder {
            path: path.to_path_buf(),
            folder: folder.to_path_buf(),
        });
    }
    if target.is_dir() {
        return Err(OutputError::IsFolder {
            path: path.to_path_buf(),
        });
    }
    // Outputs are written through a temporary file beside them.
    probe(folder).map_err(|kind| OutputError::FolderNotWritable {
        path: path.to_path_buf(),
        folder: folder.to_path_buf(),
        kind,
    })
}

/// Whether `path` can only name a folder: it ends in a separator, or in `.` or `..`
/// (`Path::file_name` looks through a trailing `/` and `/.`; the system does not).
fn names_a_folder(path: &Path) -> bool {
    let text = path.as_os_str().as_encoded_bytes();
    let last = text
        .rsplit(|&b| std::path::is_separator(char::from(b)))
        .next()
        .unwrap_or_default();
    matches!(last, b"" | b"." | b"..")
}

/// Refuses an output folder that exists as something else (a file) or could not be written
/// (nor made), before any work.
pub fn check_output_folder(dir: &Path) -> Result<(), OutputError> {
    if dir.exists() && !dir.is_dir() {
        return Err(OutputError::IsFile {
            dir: dir.to_path_buf(),
        });
    }
    // The folder, or the nearest existing one it would be made in, must take new entries.
    let Some(existing) = dir
        .ancestors()
        .map(|d| {
            if d.as_os_str().is_empty() {
                Path::new(".")
            } else {
                d
            }
        })
        .find(|d| d.exists())
    else {
        return Ok(());
    };
    if !existing.is_dir() {
        return Err(OutputError::InsideFile {
            dir: dir.to_path_buf(),
            file: existing.to_path_buf(),
        });
    }
    probe(existing).map_err(|kind| OutputError::ParentNotWritable {
        dir: dir.to_path_buf(),
        existing: existing.to_path_buf(),
        kind,
    })
}

/// Whether new entries can be made in the folder `dir`: makes and removes an empty temporary
/// folder there, named and registered as the outputs' temporaries are, so that a signal
/// between the two removes it too. The error is its kind alone, since the error's own text
/// names the temporary entry, not the output.
fn probe(dir: &Path) -> std::result::Result<(), std::io::ErrorKind> {
    let prefix = temporary_prefix(TEMPORARY_FILE_PREFIX);
    let (made, _registered) = register_temporary(|| {
        let made = tempfile::Builder::new().prefix(&prefix).tempdir_in(dir)?;
        let path = made.path().to_path_buf();
        Ok((made, path))
    })
    .map_err(|e| e.kind())?;
    made.close().map_err(|e| e.kind())
}

/// Refuses an output that would replace what the command reads (`inputs`) or another of its
/// outputs (`others`).
pub fn check_not_input(
    out: &Path,
    inputs: &ReadFiles,
    others: &[&Path],
) -> Result<(), OutputError> {
    if let Some(input) = inputs.overwritten_by(out) {
        return Err(OutputError::Input {
            path: out.to_path_buf(),
            input: input.to_path_buf(),
        });
    }
    let target = resolved(out);
    if target.is_some() && others.iter().any(|o| resolved(o) == target) {
        return Err(OutputError::TwoOutputs {
            path: out.to_path_buf(),
        });
    }
    Ok(())
}

/// Writes `model`'s file ([`Cascade::to_bytes`]) to `path` through
/// [`ridi_data::write_atomically`], as every output of ridi-rs is written.
pub fn save_model(model: &Cascade, path: &Path) -> Result<()> {
    check_output_file(path)?;
    let bytes = model.to_bytes()?;
    ridi_data::write_atomically(path, |w| w.write_all(&bytes))?;
    Ok(())
}

/// The outputs of tracking one recording: the trajectory CSV ([`Track::write_csv`]) and,
/// optionally, its plot ([`Track::plot`]). Both are checked when made, before the tracking;
/// [`TrackOutput::write`] writes both in full before either replaces a file.
#[derive(Debug, Clone)]
pub struct TrackOutput {
    csv: PathBuf,
    #[cfg(feature = "plot")]
    plot: Option<PathBuf>,
}

impl TrackOutput {
    /// The trajectory CSV `csv`, refused when it cannot be written ([`check_output_file`]) or
    /// would replace one of `inputs` ([`check_not_input`]).
    pub fn new(csv: &Path, inputs: &ReadFiles) -> Result<Self> {
        check_output_file(csv)?;
        check_not_input(csv, inputs, &[])?;
        Ok(Self {
            csv: csv.to_path_buf(),
            #[cfg(feature = "plot")]
            plot: None,
        })
    }

    /// Also the plot `plot` (`.svg` or `.png`), refused as the CSV is, and when it is the CSV
    /// or no plot format.
    #[cfg(feature = "plot")]
    pub fn with_plot(self, plot: &Path, inputs: &ReadFiles) -> Result<Self> {
        check_output_file(plot)?;
        check_not_input(plot, inputs, &[&self.csv])?;
        crate::plot::PlotFormat::from_path(plot).map_err(OutputError::PlotFormat)?;
        Ok(Self {
            plot: Some(plot.to_path_buf()),
            ..self
        })
    }

    /// Writes the trajectory `track` of `seq`: the CSV in full under a temporary name beside
    /// it, then the plot (itself written through a temporary file), then the CSV renamed into
    /// place. A failed write leaves both files as they were; only a failed rename, after the
    /// plot's, would not.
    pub fn write(&self, seq: &Sequence, track: &Track) -> Result<()> {
        let csv = write_pending(&self.csv, |w| track.csv(w))
            .map_err(|e| OutputError::write(&self.csv, e))?;
        #[cfg(feature = "plot")]
        if let Some(plot) = &self.plot {
            track.plot(seq, plot)?;
        }
        #[cfg(not(feature = "plot"))]
        let _ = seq;
        csv.commit().map_err(|e| OutputError::write(&self.csv, e))?;
        Ok(())
    }

    /// Tracks the recording `rows` reads, online, writing the trajectory CSV as the poses come
    /// (the same CSV as [`Self::write`] of an online [`crate::track()`]) under a temporary name
    /// beside it, then the plot if there is one, then the CSV renamed into place once the
    /// whole recording was tracked and checked. A failed write leaves both files as they were;
    /// only a failed rename, after the plot's, would not. Memory does not grow with the
    /// recording: the plot keeps the time and horizontal position of at most 2^18 frames and
    /// of their ground truth (40 bytes a frame), every frame of a shorter recording, every
    /// second (fourth, ...) of a longer one.
    pub fn write_stream(
        &self,
        rows: ridi_data::RowReader,
        model: &Cascade,
        opts: &crate::TrackOptions,
    ) -> Result<crate::track::StreamedTrack> {
        #[cfg(feature = "plot")]
        let mut points = self
            .plot
            .as_ref()
            .map(|_| crate::track::TrackPoints::default());
        #[cfg(not(feature = "plot"))]
        let mut points: Option<crate::track::TrackPoints> = None;
        let mut tracked = None;
        let pending = write_pending(&self.csv, |w| {
            let t = crate::track::track_stream(rows, model, opts, w, points.as_mut())?;
            let failed = t.is_err();
            tracked = Some(t);
            match failed {
                true => Err(std::io::Error::other("not tracked")),
                false => Ok(()),
            }
        });
        if let Some(Err(e)) = tracked {
            return Err(e);
        }
        let csv = pending.map_err(|e| OutputError::write(&self.csv, e))?;
        // `write_pending` ran the content, which tracked.
        let Some(Ok(tracked)) = tracked else {
            return Err(PipelineError::Live("the recording was not tracked".into()));
        };
        #[cfg(feature = "plot")]
        if let (Some(plot), Some(points)) = (&self.plot, &points) {
            points.plot(&tracked.name, plot)?;
        }
        csv.commit().map_err(|e| OutputError::write(&self.csv, e))?;
        Ok(tracked)
    }
}

/// Which plots an evaluation draws beside its report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EvalPlots {
    /// None.
    #[default]
    None,
    /// PNG images.
    #[cfg(feature = "plot")]
    Png,
    /// SVG drawings.
    #[cfg(feature = "plot")]
    Svg,
}

impl EvalPlots {
    /// The plot files' extension, `None` for no plots.
    #[cfg(feature = "plot")]
    fn extension(self) -> Option<&'static str> {
        match self {
            EvalPlots::None => None,
            #[cfg(feature = "plot")]
            EvalPlots::Png => Some("png"),
            #[cfg(feature = "plot")]
            EvalPlots::Svg => Some("svg"),
        }
    }
}

/// An evaluation's output folder: `report.json` and `report.md` ([`Report::write`]), the plots
/// of each sequence in `plots/` ([`Traces::plot`]) and, for the demo, the model evaluated.
#[derive(Debug, Clone)]
pub struct EvalFolder {
    dir: PathBuf,
    plots: EvalPlots,
    /// What the evaluation reads: no file it writes may replace one.
    inputs: ReadFiles,
}

/// What [`EvalFolder::write`] wrote.
#[derive(Debug, Clone, Default, PartialEq)]
#[non_exhaustive]
pub struct EvalWritten {
    /// `report.json` and `report.md`.
    pub reports: Vec<PathBuf>,
    /// The plot files, in sequence order.
    pub plots: Vec<PathBuf>,
    /// The model file, when one was asked for.
    pub model: Option<PathBuf>,
    /// How many plots of an earlier evaluation were removed from `plots/`.
    pub stale_plots: usize,
    /// What went wrong after the new files were in place, one sentence each: worth a warning,
    /// not a failure. (Old plots now go with the commit, so none so far.)
    pub warnings: Vec<String>,
}

impl EvalFolder {
    /// The folder `dir` with `plots`, refused before any work when it (or its `plots/`, if
    /// plots are drawn) exists as a file or cannot be written ([`check_output_folder`]).
    pub fn new(dir: &Path, plots: EvalPlots) -> Result<Self, OutputError> {
        check_output_folder(dir)?;
        if plots != EvalPlots::None {
            check_output_folder(&dir.join("plots"))?;
        }
        Ok(Self {
            dir: dir.to_path_buf(),
            plots,
            inputs: ReadFiles::default(),
        })
    }

    /// The same folder, refusing to write any file that would replace one of `inputs` (the
    /// model, the lists, the recordings): [`EvalFolder::write`] checks every name it writes,
    /// plots included, before anything is replaced.
    pub fn reading(self, inputs: ReadFiles) -> Self {
        Self { inputs, ..self }
    }

    /// The folder, as given.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The plots it gets.
    pub fn plots(&self) -> EvalPlots {
        self.plots
    }

    /// Writes `report`, the plots of `traces` and, when given, `model` under the file name
    /// `model.0`, all or nothing ([`Staging`]): a failure on the way leaves the folder as it
    /// was, and a kill is finished or rolled back by the next write into it. The same commit
    /// removes the plots of the sequences of the `report.json` it replaces, and of `report`,
    /// that it did not write (other sequences, the other format, or no plots), so that
    /// `plots/` matches the report; other files there stay, and `plots/` goes if that empties
    /// it.
    pub fn write(
        &self,
        report: &Report,
        traces: &[Traces],
        model: Option<(&str, &Cascade)>,
    ) -> Result<EvalWritten> {
        let out = &self.dir;
        let plot_dir = out.join("plots");
        // Read before report.json is replaced: whose plots an earlier evaluation wrote.
        let mut plotted = earlier_sequences(out);
        plotted.extend(report.sequences.iter().map(|s| s.name.clone()));
        let mut staging = Staging::new(out).map_err(|e| OutputError::WriteInto {
            dir: out.clone(),
            source: Box::new(e.into()),
        })?;
        let mut written = EvalWritten::default();
        if let Some((name, model)) = model {
            let path = out.join(name);
            let bytes = model.to_bytes().map_err(|e| OutputError::write(&path, e))?;
            staging
                .write(Path::new(name), |w| w.write_all(&bytes))
                .map_err(|e| OutputError::write(&path, e))?;
            written.model = Some(path);
        }
        #[cfg(feature = "plot")]
        if let Some(ext) = self.plots.extension() {
            let staged = staging.dir(Path::new("plots"))?;
            for t in traces {
                for file in t
                    .plot(&staged, ext)
                    .map_err(|e| named_as_output(e, &staging))?
                {
                    written
                        .plots
                        .extend(file.file_name().map(|name| plot_dir.join(name)));
                }
            }
        }
        #[cfg(not(feature = "plot"))]
        let _ = traces;
        let reports = report
            .write(&staging.dir(Path::new(""))?)
            .map_err(|e| named_as_output(e, &staging))?;
        for file in reports {
            written
                .reports
                .extend(file.file_name().map(|name| out.join(name)));
        }
        // Names are known only now (plots per sequence); nothing is replaced yet.
        for path in written
            .reports
            .iter()
            .chain(&written.plots)
            .chain(&written.model)
        {
            check_not_input(path, &self.inputs, &[])?;
        }
        // The old plots go with the commit: the folder matches one report, whenever it stops.
        for rel in stale_plots(&plot_dir, &plotted, &written.plots) {
            staging.remove(&rel);
            written.stale_plots += 1;
        }
        staging.commit()?;
        // Only succeeds when nothing else is in the folder.
        let _ = std::fs::remove_dir(&plot_dir);
        Ok(written)
    }
}

/// `e` with the staged file it names (inside the staging folder) named as the output file it
/// was to become: what a user can look for (a full disk when writing `plots/a.trajectory.png`).
fn named_as_output(e: PipelineError, staging: &Staging) -> PipelineError {
    #[cfg(feature = "plot")]
    use crate::plot::PlotError;
    match e {
        PipelineError::Data(ridi_data::DataError::Io { path, error }) => ridi_data::DataError::Io {
            path: staging.destination(&path),
            error,
        }
        .into(),
        #[cfg(feature = "plot")]
        PipelineError::Plot(PlotError::Io { path, error }) => PipelineError::Plot(PlotError::Io {
            path: staging.destination(&path),
            error,
        }),
        #[cfg(feature = "plot")]
        PipelineError::Plot(PlotError::Render { path, message }) => {
            PipelineError::Plot(PlotError::Render {
                path: staging.destination(&path),
                message,
            })
        }
        e => e,
    }
}

/// The sequences of the `report.json` an earlier evaluation left in `dir` (none when there is
/// none, or it cannot be read as a [`Report`]: it only decides which old plots may go).
fn earlier_sequences(dir: &Path) -> Vec<String> {
    Report::read(&dir.join("report.json"))
        .map(|r| r.sequences.into_iter().map(|s| s.name).collect())
        .unwrap_or_default()
}

/// The plots an earlier evaluation left in `dir` that this one did not write (`written`),
/// relative to the evaluation folder (`dir`'s parent). Only the plot files of `sequences` (those
/// of the earlier report and of this evaluation) are named, so other files in `dir` stay.
fn stale_plots(dir: &Path, sequences: &[String], written: &[PathBuf]) -> Vec<PathBuf> {
    let mut stale = Vec::new();
    // A name that is not a plain file name (an edited report.json) must not reach outside.
    let plain = |name: &&String| Path::new(name.as_str()).file_name() == Some(name.as_ref());
    for name in sequences.iter().filter(plain) {
        for kind in ["trajectory", "velocity"] {
            for ext in ["png", "svg"] {
                let file = format!("{name}.{kind}.{ext}");
                let path = dir.join(&file);
                if path.is_file() && !written.contains(&path) && !stale.contains(&file) {
                    stale.push(file);
                }
            }
        }
    }
    stale
        .into_iter()
        .map(|file| Path::new("plots").join(file))
        .collect()
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use super::*;
    use crate::evaluate::SequenceResult;

    /// The error and its causes on one line, as the command line prints them.
    fn chain(e: &dyn std::error::Error) -> String {
        let mut line = e.to_string();
        let mut next = e.source();
        while let Some(c) = next {
            line = format!("{line}: {c}");
            next = c.source();
        }
        line
    }

    #[test]
    fn a_failed_write_names_its_file_once() {
        // A full disk while writing t.csv: the I/O error of that file names it already.
        let path = Path::new("out/t.csv");
        let full = std::io::Error::from(std::io::ErrorKind::StorageFull);
        let e = OutputError::write(path, ridi_data::DataError::io(path, full));
        let line = chain(&e);
        assert_eq!(line.matches("t.csv").count(), 1, "{line}");
        assert!(line.starts_with("cannot write out/t.csv: "), "{line}");
        // Another file's error, or a data error, keeps its own words after the output's.
        let other = Path::new("in/model.ridi");
        let e = OutputError::write(
            path,
            ridi_data::DataError::io(other, std::io::Error::other("x")),
        );
        assert_eq!(chain(&e), "cannot write out/t.csv: in/model.ridi: x");
    }

    /// A report of sequences of these names, with what JSON cannot hold as a number (`NaN`,
    /// written as `null`), as an evaluation without regressions has.
    fn report(names: &[&str]) -> Report {
        Report {
            sequences: names
                .iter()
                .map(|name| SequenceResult {
                    name: name.to_string(),
                    run: name.to_string(),
                    placement: None,
                    device: None,
                    path_length_m: 12.5,
                    alignment_extent_m: 3.0,
                    placement_accuracy: None,
                    velocity_mse: [f64::NAN; 2],
                    methods: BTreeMap::new(),
                })
                .collect(),
            recorded_heading: Some(ridi_frames::HeadingConfig::default()),
            methods: Vec::new(),
            warnings: vec!["a warning".into()],
            ..Report::of_sequences(Vec::new())
        }
    }

    #[test]
    fn a_written_report_reads_back_nan_and_all() {
        let dir = tempfile::tempdir().unwrap();
        let written = report(&["a", "b"]);
        written.write(dir.path()).unwrap();
        let read = Report::read(&dir.path().join("report.json")).unwrap();
        assert!(read.velocity_mse.iter().all(|v| v.is_nan()));
        assert!(read.sequences[1].velocity_mse.iter().all(|v| v.is_nan()));
        // Equal but for NaN, which equals nothing.
        let finite = |mut r: Report| {
            r.velocity_mse = [0.0; 2];
            for s in &mut r.sequences {
                s.velocity_mse = [0.0; 2];
            }
            r
        };
        assert_eq!(finite(read), finite(written));
        let err = Report::read(&dir.path().join("none.json")).unwrap_err();
        assert!(err.to_string().contains("none.json"), "{err}");
    }

    /// Only the plots of the named sequences go, and only inside the folder, whatever an
    /// edited report.json names; a report.json that is no report names nothing.
    #[test]
    fn stale_plots_are_those_of_named_sequences_inside_the_folder() {
        let dir = tempfile::tempdir().unwrap();
        let plots = dir.path().join("plots");
        std::fs::create_dir_all(&plots).unwrap();
        let file = |p: &Path| {
            std::fs::write(p, "x").unwrap();
            p.to_path_buf()
        };
        file(&dir.path().join("x.trajectory.png"));
        file(&plots.join("a.velocity.svg"));
        let kept = file(&plots.join("a.trajectory.png"));
        file(&plots.join("b.trajectory.png"));
        report(&["a", "../x", ""]).write(dir.path()).unwrap();
        let names = earlier_sequences(dir.path());
        assert_eq!(names, ["a", "../x", ""]);
        assert_eq!(
            stale_plots(&plots, &names, std::slice::from_ref(&kept)),
            [Path::new("plots/a.velocity.svg")]
        );
        for text in ["{ cut", r#"{"sequences":[{"name":"a"}]}"#] {
            std::fs::write(dir.path().join("report.json"), text).unwrap();
            assert!(earlier_sequences(dir.path()).is_empty(), "{text}");
        }
        assert!(earlier_sequences(&plots).is_empty());
    }

    #[test]
    fn outputs_that_cannot_be_written_are_refused_before_any_work() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("file.txt");
        std::fs::write(&file, "mine").unwrap();
        let message = |e: OutputError| e.to_string();
        assert!(check_output_file(&dir.path().join("new.csv")).is_ok());
        let e = message(check_output_file(&dir.path().join("no/new.csv")).unwrap_err());
        assert!(e.ends_with("no does not exist"), "{e}");
        let e = message(check_output_file(dir.path()).unwrap_err());
        assert!(e.ends_with("it is a folder"), "{e}");
        for inside in ["t.csv", "a/t.csv"] {
            let e = message(check_output_file(&file.join(inside)).unwrap_err());
            assert!(e.ends_with("file.txt is a file, not a folder"), "{e}");
        }
        // A folder that does not exist yet, named as one: refused before any work, not when
        // the file is renamed into place.
        for name in ["new/", "new/.", "new/..", "."] {
            let e = message(check_output_file(&dir.path().join(name)).unwrap_err());
            assert!(e.contains("names a folder"), "{name}: {e}");
        }
        let e = message(check_output_file(Path::new("new/")).unwrap_err());
        assert!(e.starts_with("cannot write new/: "), "{e}");
        assert!(check_output_folder(&dir.path().join("a/b/c")).is_ok());
        let e = message(check_output_folder(&file).unwrap_err());
        assert!(e.ends_with("it is a file, not a folder"), "{e}");
        let e = message(check_output_folder(&file.join("a/b")).unwrap_err());
        assert!(e.ends_with("file.txt is a file, not a folder"), "{e}");
        let e = message(EvalFolder::new(&file, EvalPlots::None).unwrap_err());
        assert!(e.ends_with("it is a file, not a folder"), "{e}");
        #[cfg(feature = "plot")]
        {
            std::fs::write(dir.path().join("plots"), "mine").unwrap();
            let e = message(EvalFolder::new(dir.path(), EvalPlots::Png).unwrap_err());
            assert!(e.ends_with("plots: it is a file, not a folder"), "{e}");
        }

        let inputs = ReadFiles::of([&file]);
        let e = message(check_not_input(&file, &inputs, &[]).unwrap_err());
        // The input is the output, by the same path: named once.
        assert_eq!(
            e,
            format!(
                "cannot write {}: the command reads it; choose another output",
                file.display()
            )
        );
        let out = dir.path().join("out.csv");
        assert!(check_not_input(&out, &inputs, &[]).is_ok());
        let e =
            message(check_not_input(&out, &inputs, &[&dir.path().join("./out.csv")]).unwrap_err());
        assert!(e.ends_with("it is given as two outputs"), "{e}");
        assert_eq!(std::fs::read(&file).unwrap(), b"mine");
        // A second name of the input (a hard link; a bind mount alike) is the input: paths
        // differ, the file does not.
        let second = dir.path().join("second-name.csv");
        std::fs::hard_link(&file, &second).unwrap();
        let e = message(check_not_input(&second, &inputs, &[]).unwrap_err());
        assert!(
            e.ends_with(&format!(
                "second-name.csv: the command reads it as {}; choose another output",
                file.display()
            )),
            "{e}"
        );
    }

    /// An evaluation whose input (here its model) lies at a name it writes inside `--out`
    /// fails before replacing anything, and the input stays.
    #[test]
    fn an_evaluation_never_writes_over_what_it_reads() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("eval");
        std::fs::create_dir(&out).unwrap();
        let model = out.join("report.json");
        std::fs::write(&model, "the model").unwrap();
        let folder = EvalFolder::new(&out, EvalPlots::None)
            .unwrap()
            .reading(ReadFiles::of([&model]));
        let e = folder
            .write(&report(&["a"]), &[], None)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("report.json") && e.contains("the command reads it"),
            "{e}"
        );
        assert_eq!(std::fs::read(&model).unwrap(), b"the model");
        assert!(!out.join("report.md").exists());
        // Without that input, the same folder is written.
        let folder = EvalFolder::new(&out, EvalPlots::None).unwrap();
        folder.write(&report(&["a"]), &[], None).unwrap();
        assert!(out.join("report.md").exists());
    }

    /// An evaluation folder takes its reports and plots together, and a later evaluation
    /// without plots takes the earlier one's away, and `plots/` with them.
    #[cfg(feature = "plot")]
    #[test]
    fn an_evaluation_folder_matches_its_latest_report() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("eval");
        let points: Vec<[f64; 2]> = (0..50).map(|i| [f64::from(i) * 0.1, 0.0]).collect();
        let traces = Traces {
            name: "a".into(),
            ground_truth: points.clone(),
            methods: vec![(crate::Method::Raw, points)],
            regression_time: Vec::new(),
            regressed: Vec::new(),
            true_velocity: Vec::new(),
            placements: Vec::new(),
        };
        let folder = EvalFolder::new(&out, EvalPlots::Svg).unwrap();
        let written = folder
            .write(&report(&["a"]), std::slice::from_ref(&traces), None)
            .unwrap();
        assert_eq!(written.plots, [out.join("plots/a.trajectory.svg")]);
        assert_eq!(
            written.reports,
            [out.join("report.json"), out.join("report.md")]
        );
        assert!(written.plots[0].is_file() && written.warnings.is_empty());
        #[cfg(unix)]
        {
            // One writer, one permission mode: readable by all, written by the owner alone.
            use std::os::unix::fs::PermissionsExt;
            let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
            let report_mode = mode(&written.reports[0]);
            assert_eq!(mode(&written.plots[0]), report_mode);
            assert_eq!(report_mode & 0o622, 0o600, "{report_mode:o}");
        }

        let again = EvalFolder::new(&out, EvalPlots::None).unwrap();
        let written = again.write(&report(&["b"]), &[traces], None).unwrap();
        assert!(written.plots.is_empty());
        assert_eq!(written.stale_plots, 1);
        assert_eq!(
            ridi_test_support::file_names(&out),
            ["report.json", "report.md"]
        );
    }
}
