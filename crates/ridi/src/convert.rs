//! `ridi convert`: any supported source to the RIDI processed layout, with list files.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use ridi_data::{
    DataError, DeviceInfo, Format, Location, ReadOptions, Sequence, SequenceError, SplitParts,
    counted, detect, short, sidecar_path, spans_text, unlistable_name, write_atomically,
    write_ridi_csv,
};
use ridi_data::{ilc, tyrex};

use crate::source::{Loaded, ReadFiles, is_a, not_a, read_any, source_format, with_article};
use crate::staging::Staging;

/// One sequence written by [`convert`].
#[derive(Debug, Clone, PartialEq)]
pub struct Converted {
    /// Sequence name (the output folder's name).
    pub name: String,
    /// Placement label written to the list files.
    pub placement: Option<String>,
    /// The `data.csv` written.
    pub path: PathBuf,
    /// Number of frames.
    pub frames: usize,
    /// The phone it was recorded with, when the source says; kept in the sidecar beside the
    /// `data.csv` ([`ridi_data::sidecar_path`]).
    pub device: Option<DeviceInfo>,
    /// The source it was read from (a file or a folder).
    pub source: PathBuf,
    /// Whether it has ground truth; the list files name only those that do.
    pub ground_truth: bool,
}

/// What [`convert`] wrote.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ConvertSummary {
    /// Every sequence written, sorted by name.
    pub sequences: Vec<Converted>,
    /// The list files written.
    pub lists: Vec<PathBuf>,
    /// Splits, dropped parts and other things to know.
    pub warnings: Vec<String>,
    /// The file the warnings were also written to ([`WARNINGS_FILE`] in the output folder),
    /// when there were any: what a conversion split or dropped stays beside its output.
    pub warnings_file: Option<PathBuf>,
}

/// The file in a conversion's output folder that keeps its warnings, one per line; a
/// conversion without warnings removes an earlier one.
pub const WARNINGS_FILE: &str = "convert-warnings.txt";

/// How to convert.
#[derive(Debug, Clone, Default)]
pub struct ConvertOptions {
    /// Read every source as this format instead of detecting it.
    pub from: Option<Format>,
    /// How to read (validation limits).
    pub read: ReadOptions,
    /// Resample every sequence to this rate, Hz ([`Sequence::resampled`]), within
    /// [`ridi_data::RESAMPLE_RATE_RANGE_HZ`]; `None` keeps each sequence's timeline.
    ///
    /// [`Sequence::resampled`]: ridi_data::Sequence::resampled
    pub rate_hz: Option<f64>,
    /// Cut every sequence at each gap longer than this many seconds, before resampling
    /// ([`Sequence::split_at_gaps`]): parts `<name>_part1`, `_part2`, ... (the plain name when
    /// one is left); a part shorter than [`SPLIT_MIN_PART_S`] is dropped with a warning, and a
    /// conversion left without any sequence is an error. `None` keeps sequences whole. What
    /// `ridi track` (a gap over 0.1 s) and `rate_hz` (over 5 frame intervals) refuse. Each
    /// source is read by [`read_split`], which also cuts pauses longer than the readers' limit.
    pub split_at_gaps_s: Option<f64>,
}

/// Shortest part [`ConvertOptions::split_at_gaps_s`] keeps, seconds: one feature window of the
/// paper's models (200 frames at 200 Hz), the least anything can be tracked on.
pub const SPLIT_MIN_PART_S: f64 = 1.0;

/// Longest gap `--rate` interpolates across, in frame intervals of the source (its median):
/// longer ones would be filled with invented frames, so the recording has to be split there
/// first.
pub(crate) const RESAMPLE_MAX_GAP_FRAMES: f64 = 5.0;

/// The longest gap in `seq` that `ridi convert --rate` (and Python's `Sequence.resampled`)
/// interpolates across, seconds: 5 of its median frame intervals.
pub fn resample_max_gap(seq: &Sequence) -> f64 {
    RESAMPLE_MAX_GAP_FRAMES / seq.median_rate_hz()
}

/// A split limit (`--split-at-gaps`, `split_at_gaps`) that cuts every gap longer than
/// `max_gap_s`, for a message: rounded down to the millisecond, as one rounded up would leave
/// the gap in.
pub fn split_limit(max_gap_s: f64) -> f64 {
    (max_gap_s * 1000.0).floor() / 1000.0
}

/// `seqs` cut at their gaps longer than `max_gap_s` ([`Sequence::split_at_gaps`]), parts
/// under [`SPLIT_MIN_PART_S`] dropped, with one warning per sequence cut. A source may be left
/// without any part (its warning says so); [`convert`] fails only when every source is.
fn split(
    seqs: Vec<Sequence>,
    max_gap_s: f64,
    warnings: &mut Vec<String>,
) -> std::result::Result<Vec<Sequence>, SequenceError> {
    let mut kept = Vec::new();
    for seq in seqs {
        let name = seq.name().to_owned();
        let SplitParts { parts, dropped } = seq.split_at_gaps(max_gap_s, SPLIT_MIN_PART_S)?;
        // One stretch more than gaps, each kept or dropped.
        let gaps = parts.len() + dropped.len() - 1;
        if gaps > 0 {
            let mut warning = format!(
                "sequence `{name}`: split at {} longer than {} s",
                counted(gaps, "gap"),
                short(max_gap_s)
            );
            if !dropped.is_empty() {
                let _ = write!(
                    warning,
                    "; {} shorter than {SPLIT_MIN_PART_S} s dropped ({})",
                    counted(dropped.len(), "part"),
                    spans_text(&dropped)
                );
            }
            warning.push_str(&match parts.len() {
                0 => "; nothing left".to_string(),
                1 => format!("; 1 part kept, named `{}`", parts[0].name()),
                n => format!("; {} kept", counted(n, "part")),
            });
            warnings.push(warning);
        } else if parts.is_empty() {
            warnings.push(format!(
                "sequence `{name}`: shorter than {SPLIT_MIN_PART_S} s ({}), dropped",
                spans_text(&dropped)
            ));
        }
        kept.extend(parts);
    }
    Ok(kept)
}

/// [`read_any`] of `path`, its sequences cut at every gap longer than `max_gap_s`
/// ([`Sequence::split_at_gaps`]), parts under [`SPLIT_MIN_PART_S`] dropped, one warning per
/// sequence cut after the reader's: what `ridi convert --split-at-gaps` reads. `max_gap_s` is
/// below `opts`' [`max_gap_s`](ridi_data::Validation::max_gap_s); pauses longer than that limit
/// are read and cut too, in every format whose reader keeps them as gaps
/// ([`Format::keeps_gaps`]; elsewhere the limit stands), so no part keeps a gap the readers
/// refuse. A source left without any part has no sequence (its warning says so).
///
/// # Errors
/// As [`read_any`]; [`SequenceError::InvalidGap`] (named by `path`) for a `max_gap_s` that is
/// not a finite number above 0, and an error for one not below the readers' limit.
pub fn read_split(
    path: &Path,
    from: Option<Format>,
    opts: &ReadOptions,
    max_gap_s: f64,
) -> Result<Loaded, DataError> {
    let limit = opts.validation.max_gap_s;
    if !(max_gap_s.is_finite() && max_gap_s > 0.0) {
        let e = SequenceError::InvalidGap {
            max_gap_s,
            min_duration_s: SPLIT_MIN_PART_S,
        };
        return Err(DataError::sequence(path, e));
    }
    if max_gap_s >= limit {
        return Err(DataError::format(
            Location::file(path),
            format!(
                "cannot split at gaps longer than {} s: the readers accept gaps of up to {} s, \
                 so a split must be below that to cut every pause",
                short(max_gap_s),
                short(limit)
            ),
        ));
    }
    let path = &crate::source::forced_file(path, from);
    let format = source_format(path, from)?;
    let mut loaded = read_any(path, Some(format), &opts.reading_pauses(format))?;
    let sequences = std::mem::take(&mut loaded.sequences);
    loaded.sequences = split(sequences, max_gap_s, &mut loaded.warnings)
        .map_err(|e| DataError::sequence(path, e))?;
    Ok(loaded)
}

/// What converting one source produced: the sequences written and the warnings.
type Written = (Vec<Converted>, Vec<String>);

/// What [`sources`] found: the sources to convert, and a warning about what it skipped.
#[derive(Debug, PartialEq)]
struct Sources {
    paths: Vec<PathBuf>,
    /// Tyrex run folders without motion capture in a root.
    skipped: Option<String>,
}

impl From<Vec<PathBuf>> for Sources {
    fn from(paths: Vec<PathBuf>) -> Self {
        Self {
            paths,
            skipped: None,
        }
    }
}

/// The runs with motion capture of a Tyrex root, and a warning naming those without (skipped);
/// when no run has motion capture, every run, without ground truth, and a warning saying so.
fn tyrex_sources(source: &Path) -> Result<Sources, DataError> {
    let runs = tyrex::list_sequences(source)?;
    if runs.runs.is_empty() {
        // Recordings in the Tyrex layout without any motion capture (one's own, say): what
        // there is to convert is the phone data.
        return Ok(Sources {
            skipped: Some(format!(
                "no run has a Qualisys file in ../../qualisys/: the {} converted without \
                 ground truth",
                counted(runs.without_mocap.len(), "run")
            )),
            paths: runs.without_mocap,
        });
    }
    Ok(Sources {
        skipped: runs.warning(),
        paths: runs.runs,
    })
}

/// The sources under `source`: one sequence, the runs of a Tyrex root (those with motion
/// capture), the sequences one level below a folder (a RIDI dataset folder), or else the Indoor
/// Location Competition path files in the folder and its sub-folders. With `from`, only sources
/// of that format: a `source` of another format is an error saying so.
fn sources(source: &Path, from: Option<Format>) -> Result<Sources, DataError> {
    let Some(want) = from else {
        return detected_sources(source);
    };
    if is_a(source, want) {
        return Ok(vec![source.to_path_buf()].into());
    }
    if detect(source).is_ok() || !source.is_dir() {
        return Err(not_a(source, want));
    }
    let found = match want {
        Format::Tyrex => tyrex_sources(source),
        Format::Ilc => ilc::list_paths(source).map(Sources::from),
        _ => sub_folders(source, |p| is_a(p, want)).and_then(|found| {
            if found.is_empty() {
                Err(DataError::format(
                    Location::file(source),
                    format!("no {want} here or one level below: {}", want.layout()),
                ))
            } else {
                Ok(found.into())
            }
        }),
    };
    // A folder of another format: say what it holds rather than only what it lacks.
    found.map_err(|e| match detected_sources(source) {
        Ok(Sources { paths: other, .. }) if !other.is_empty() => {
            let (what, with) = match detect(&other[0]) {
                Ok(f) => (with_article(&f.to_string()), format!("--from {}", f.key())),
                Err(_) => ("a sequence".to_string(), "that format's --from".to_string()),
            };
            DataError::format(
                Location::file(source),
                format!(
                    "no {want} here, but {} of another format (the first, {}, is {what}): \
                     convert without --from, or with {with}",
                    counted(other.len(), "source"),
                    ridi_data::shown(&other[0]),
                ),
            )
        }
        _ => e,
    })
}

/// [`sources`] without a format given: whatever is detected.
fn detected_sources(source: &Path) -> Result<Sources, DataError> {
    if detect(source).is_ok() {
        return Ok(vec![source.to_path_buf()].into());
    }
    if let Ok(runs) = tyrex_sources(source) {
        return Ok(runs);
    }
    if !source.is_dir() {
        // Say why the file is not a sequence rather than that it is not a folder.
        return detect(source).map(|_| vec![source.to_path_buf()].into());
    }
    let found = sub_folders(source, |p| detect(p).is_ok())?;
    if !found.is_empty() {
        return Ok(found.into());
    }
    ilc::list_paths(source).map(Sources::from).map_err(|_| {
        DataError::format(
            Location::file(source),
            "no sequence found: expected a RIDI data.csv, data_plain.txt or raw folder, a Tyrex \
             folder or root, a RoNIN sequence folder, a folder of those, or Indoor Location \
             Competition path files",
        )
    })
}

/// The folders directly in `dir` that `keep` accepts, sorted.
fn sub_folders(dir: &Path, keep: impl Fn(&Path) -> bool) -> Result<Vec<PathBuf>, DataError> {
    let entries = std::fs::read_dir(dir).map_err(|e| DataError::io(dir, e))?;
    let mut found = Vec::new();
    for entry in entries {
        let path = entry.map_err(|e| DataError::io(dir, e))?.path();
        if path.is_dir() && keep(&path) {
            found.push(path);
        }
    }
    found.sort();
    Ok(found)
}

/// Labels that list files give the sequences of a source folder.
#[derive(Debug, Default)]
struct ListLabels {
    /// Placement by canonical sequence folder.
    labels: BTreeMap<PathBuf, String>,
    /// The list files read.
    lists: Vec<PathBuf>,
    warnings: Vec<String>,
}

/// The sequence folder a list entry or a source stands for, resolved: a file's folder, and
/// for `<sequence>/processed/data.csv`, `<sequence>`.
fn labelled(path: &Path) -> Option<PathBuf> {
    let path = path.canonicalize().ok()?;
    if !path.is_file() {
        return Some(path);
    }
    let folder = match path.parent() {
        Some(p) if p.ends_with("processed") => p.parent(),
        other => other,
    };
    Some(folder.map_or(path.clone(), Path::to_path_buf))
}

/// Placement labels that list files directly in a `source` folder (`list*.txt`) give its
/// sequences: the RIDI layout keeps them there, not in the data ([`convert`] also reads the
/// parent folder's for a sequence given alone). A file that does not parse
/// as a list is skipped; an entry may name the sequence folder or its `processed/` file; a
/// sequence two lists label differently keeps the first label (lists by name), with a warning.
fn labels_from_lists(source: &Path) -> ListLabels {
    let mut out = ListLabels::default();
    let Ok(entries) = std::fs::read_dir(source) else {
        return out;
    };
    let mut lists: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let name = p.file_name().unwrap_or_default().to_string_lossy();
            p.is_file() && name.starts_with("list") && name.ends_with(".txt")
        })
        .collect();
    lists.sort();
    let (labels, warnings) = (&mut out.labels, &mut out.warnings);
    for list in lists {
        let Ok(entries) = ridi_data::ListEntry::read(&[&list]) else {
            continue;
        };
        out.lists.push(list.clone());
        for e in entries {
            let (Some(label), Some(path)) = (e.placement, labelled(&e.path)) else {
                continue;
            };
            match labels.get(&path) {
                None => {
                    labels.insert(path, label);
                }
                Some(first) if *first != label => warnings.push(format!(
                    "{}:{}: placement `{label}` of {} differs from `{first}` in an earlier \
                     list: kept `{first}`",
                    ridi_data::shown(&list),
                    e.line,
                    ridi_data::shown(&e.path)
                )),
                Some(_) => {}
            }
        }
    }
    out
}

/// Refuses a conversion whose outputs would replace a file it read: a source file, or a list
/// that labelled the sources (e.g. `--out` the source folder itself).
fn check_overwrites(
    sources: &[PathBuf],
    lists: &[PathBuf],
    sequences: &[Converted],
    written_lists: &[PathBuf],
) -> Result<(), DataError> {
    let inputs = ReadFiles::of(sources.iter().chain(lists));
    let outputs = sequences.iter().map(|c| &c.path).chain(written_lists);
    for out in outputs {
        if inputs.overwritten_by(out).is_some() {
            return Err(DataError::format(
                Location::file(out),
                "cannot write it: the command reads it; choose an --out outside the source",
            ));
        }
    }
    Ok(())
}

/// A list file an earlier conversion wrote into `out` that this one does not rewrite and that
/// names one of the `unlisted` sequences, now rewritten without ground truth: left as it was,
/// it would still offer them to training and evaluation.
struct StaleList {
    /// Its file name in `out`.
    name: String,
    /// Its text without those sequences' lines; `None` when no sequence is left.
    kept: Option<String>,
}

/// The [`StaleList`]s of `out`: lists whose first line says `ridi convert` wrote them (a list
/// of one's own is never touched), other than those this conversion writes (`lists`, compared
/// ignoring case, as some file systems do) and those it read (`read`, the source's lists).
fn stale_lists(
    out: &Path,
    lists: &BTreeMap<String, Vec<&Converted>>,
    unlisted: &[&Converted],
    read: &[PathBuf],
) -> Vec<StaleList> {
    let read: Vec<PathBuf> = read.iter().filter_map(|p| p.canonicalize().ok()).collect();
    let mut stale: Vec<StaleList> = lists_not_written(out, lists)
        .into_iter()
        .filter(|name| {
            let path = out.join(name);
            path.is_file() && !path.canonicalize().is_ok_and(|p| read.contains(&p))
        })
        .filter_map(|name| {
            let text = std::fs::read_to_string(out.join(&name)).ok()?;
            if !text.starts_with(LIST_HEADER) {
                return None;
            }
            let names_one = |l: &str| {
                let listed = l.split(',').next().unwrap_or("");
                !l.starts_with('#') && unlisted.iter().any(|c| c.name == listed)
            };
            if !text.lines().any(names_one) {
                return None;
            }
            let lines: Vec<&str> = text.lines().filter(|l| !names_one(l)).collect();
            let kept = lines
                .iter()
                .any(|l| !l.starts_with('#') && !l.trim().is_empty())
                .then(|| lines.join("\n") + "\n");
            Some(StaleList { name, kept })
        })
        .collect();
    stale.sort_by(|a, b| a.name.cmp(&b.name));
    stale
}

/// How a list file `ridi convert` writes begins: this, the source as given, and a backquote.
const LIST_HEADER: &str = "# written by `ridi convert ";

/// The names of the `list_<key>.txt` files in `out` that are none of `lists` (keys compared
/// ignoring case, as some file systems do).
fn lists_not_written(out: &Path, lists: &BTreeMap<String, Vec<&Converted>>) -> Vec<String> {
    let Ok(entries) = std::fs::read_dir(out) else {
        return Vec::new();
    };
    entries
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|name| {
            name.strip_prefix("list_")
                .and_then(|n| n.strip_suffix(".txt"))
                .is_some_and(|key| !lists.keys().any(|k| k.eq_ignore_ascii_case(key)))
        })
        .collect()
}

/// The list files in `out` that an earlier `ridi convert` of another source wrote (by their
/// first line) and this one neither writes (`lists`) nor rewrote (`rewritten`): other files in
/// an output folder stay, but lists that disagree deserve a word.
fn other_sources_lists(
    out: &Path,
    lists: &BTreeMap<String, Vec<&Converted>>,
    rewritten: &[String],
    source: &Path,
) -> Vec<String> {
    // The source as a list names it, resolved where it can be: `data`, `data/` and its absolute
    // path are one source.
    let (spelt, resolved) = (source.display().to_string(), source.canonicalize().ok());
    let same = |written: &str| {
        written == spelt || resolved.is_some() && Path::new(written).canonicalize().ok() == resolved
    };
    let mut found: Vec<String> = lists_not_written(out, lists)
        .into_iter()
        .filter(|name| !rewritten.contains(name))
        .filter(|name| {
            // The first line only, and a bounded one: the file may be anything.
            use std::io::{BufRead as _, Read as _};
            let Ok(file) = std::fs::File::open(out.join(name)) else {
                return false;
            };
            let mut first = String::new();
            let read = std::io::BufReader::new(file.take(64 * 1024)).read_line(&mut first);
            let first = first.trim_end_matches(['\n', '\r']);
            let written = first
                .strip_prefix(LIST_HEADER)
                .and_then(|rest| rest.strip_suffix('`'));
            read.is_ok() && written.is_some_and(|w| !same(w))
        })
        .collect();
    found.sort();
    found
}

/// The warning naming the sequences without ground truth, which no list names.
fn unlisted_warning(
    out: &Path,
    unlisted: &[&Converted],
    no_lists: bool,
    stale: &[StaleList],
) -> String {
    let lists = if no_lists {
        "no list file written"
    } else {
        "left out of the list files"
    };
    let (its, it) = match unlisted.len() {
        1 => ("its", "it"),
        _ => ("each one's", "them"),
    };
    // Each earlier list either lost the lines of those sequences or, left empty, went.
    let edits: Vec<String> = [(true, "removed"), (false, "left out of")]
        .into_iter()
        .filter_map(|(gone, verb)| {
            let names: Vec<&str> = stale
                .iter()
                .filter(|l| l.kept.is_none() == gone)
                .map(|l| l.name.as_str())
                .collect();
            (!names.is_empty()).then(|| format!("{verb} the earlier {}", names.join(", ")))
        })
        .collect();
    let removed = match edits.as_slice() {
        [] => String::new(),
        _ => format!(" ({}, which named {it})", edits.join("; ")),
    };
    format!(
        "{}: {} without ground truth ({}): {lists}, as training and evaluation need ground \
         truth{removed}; `ridi track` takes {its} data.csv",
        ridi_data::shown(out),
        counted(unlisted.len(), "sequence"),
        ridi_data::first_few(unlisted.iter().map(|c| &c.name), 3)
    )
}

/// The person of a Tyrex run name `<Person>_<Phone>_<Dist>_<Motion>`, also for the parts
/// of a split run (`..._<Motion>_part2`).
fn tyrex_subject(name: &str) -> Option<&str> {
    let run = ridi_eval::run_of(name);
    tyrex::motion_of(run)?;
    let mut parts = run.split('_');
    let person = parts.next();
    // `<Person>_<Phone>_<Dist>_<Motion>`: a bare motion (`texting.csv`) names no person.
    (parts.count() >= 3).then_some(person).flatten()
}

/// The list of each device, keyed by [`DeviceInfo::key`] (`nexus5`, `iphone4s`), for the
/// sequences that name their device; `taken` are the lists already there (`all`, the people). A
/// device whose key is one of those (ignoring case, as some file systems do) gets no list, with a
/// warning; models with the same key (`Nexus 5`, `NEXUS-5`) share one.
fn device_lists<'a>(
    sequences: &[&'a Converted],
    taken: &BTreeMap<String, Vec<&'a Converted>>,
) -> (BTreeMap<String, Vec<&'a Converted>>, Vec<String>) {
    let mut lists: BTreeMap<String, Vec<&Converted>> = BTreeMap::new();
    for &c in sequences {
        if let Some(d) = &c.device {
            lists.entry(d.key()).or_default().push(c);
        }
    }
    let mut warnings = Vec::new();
    lists.retain(|key, entries| {
        let clash = taken.keys().find(|t| t.eq_ignore_ascii_case(key));
        if let Some(clash) = clash {
            let model = entries[0].device.as_ref().map_or("", |d| d.model());
            warnings.push(format!(
                "{} of the device `{model}`: no list_{key}.txt, as list_{clash}.txt is another \
                 list",
                counted(entries.len(), "sequence")
            ));
        }
        clash.is_none()
    });
    (lists, warnings)
}

/// Converts every sequence under `source` into `<out>/<name>/processed/data.csv` (with the
/// sidecar `data.csv.meta` when the sequence names its device, see
/// [`ridi_data::sidecar_path`]) and writes list files (`name,placement` per line, relative to
/// `out`) of the sequences with ground truth, which training and evaluation need (the others,
/// such as the Indoor Location Competition's test paths, are in none, with a warning):
/// `list_all.txt`, for Tyrex sources one `list_<person>.txt` per person, and one
/// `list_<device>.txt` per device the sequences name ([`DeviceInfo::key`]: `list_nexus5.txt`,
/// `list_iphone4s.txt`). The placement of a Tyrex run is its motion name, that of an Indoor
/// Location Competition path `hand`, that of a RIDI sequence the label list files directly in
/// `source` give it, or for one sequence given alone (its folder or its `data.csv`) the lists
/// beside its folder (none otherwise).
///
/// All or nothing: every source is read and validated, and its files written to a staging
/// folder in `out`, before any is moved into place; on an error `out` is left as it was (a
/// folder `out` or its parents created for the conversion is removed again). A `data.csv` and
/// its sidecar are replaced together: a sequence without a device removes an old sidecar at its
/// place in the same commit.
pub fn convert(
    source: &Path,
    out: &Path,
    opts: &ConvertOptions,
) -> Result<ConvertSummary, DataError> {
    let from = opts.from;
    let Sources {
        paths: dirs,
        skipped,
    } = sources(source, from)?;
    let mut listed = labels_from_lists(source);
    // One sequence given alone: the RIDI layout keeps its lists beside it, in its folder's
    // parent (`datasets/sample/list_test.txt` labels `datasets/sample/<run>`).
    if let [only] = &dirs[..]
        && let Some(folder) = labelled(only)
        && !listed.labels.contains_key(&folder)
        && let Some(parent) = folder.parent()
    {
        let beside = labels_from_lists(parent);
        if let Some(label) = beside.labels.get(&folder) {
            listed.labels.insert(folder.clone(), label.clone());
            listed.lists.extend(beside.lists);
        }
    }
    let labels = &listed.labels;
    let mut staging = Staging::new(out)?;
    let results: Vec<Result<Written, DataError>> = dirs
        .par_iter()
        .map(|dir| {
            let loaded = match opts.split_at_gaps_s {
                Some(max_gap) => read_split(dir, from, &opts.read, max_gap)?,
                None => read_any(dir, from, &opts.read)?,
            };
            let mut written = Vec::new();
            let listed = labelled(dir).and_then(|d| labels.get(&d));
            for seq in &loaded.sequences {
                let resampled = match opts.rate_hz {
                    Some(rate) => {
                        let max_gap = resample_max_gap(seq);
                        Some(seq.resampled(rate, max_gap).map_err(|e| match e {
                            // Interpolating would invent the gap's frames.
                            SequenceError::Gap { .. } => DataError::format(
                                Location::file(dir),
                                format!(
                                    "sequence `{}`: {e}: split the recording there first \
                                     (--split-at-gaps {})",
                                    seq.name(),
                                    short(split_limit(max_gap))
                                ),
                            ),
                            e => DataError::sequence(dir, e),
                        })?)
                    }
                    None => None,
                };
                let seq = resampled.as_ref().unwrap_or(seq);
                if let Some(why) = unlistable_name(seq.name()) {
                    return Err(DataError::format(
                        Location::file(dir),
                        format!(
                            "the sequence name {:?} cannot be written to a list file ({why}): \
                             rename the folder",
                            seq.name()
                        ),
                    ));
                }
                let rel = Path::new(seq.name()).join("processed").join("data.csv");
                write_ridi_csv(seq, staging.file(&rel)?)?;
                written.push(Converted {
                    name: seq.name().to_string(),
                    placement: seq
                        .placement()
                        .or(listed.map(String::as_str))
                        .map(str::to_string),
                    path: out.join(rel),
                    frames: seq.len(),
                    device: seq.device().cloned(),
                    source: dir.clone(),
                    ground_truth: seq.ground_truth().is_some(),
                });
            }
            // Named by the source, unless the warning names it (or a file in it) already.
            let source = dir.display().to_string();
            let warnings = loaded
                .warnings
                .into_iter()
                .map(|w| {
                    let names_it = w.strip_prefix(&source).is_some_and(|rest| {
                        rest.starts_with(':') || rest.starts_with(std::path::MAIN_SEPARATOR)
                    });
                    if names_it {
                        w
                    } else {
                        format!("{source}: {w}")
                    }
                })
                .collect();
            Ok((written, warnings))
        })
        .collect();
    let mut summary = ConvertSummary::default();
    summary.warnings.extend(skipped);
    summary.warnings.extend(listed.warnings.iter().cloned());
    for r in results {
        let (written, warnings) = r?;
        summary.sequences.extend(written);
        summary.warnings.extend(warnings);
    }
    summary.sequences.sort_by(|a, b| a.name.cmp(&b.name));
    // Two sequences of one name would be written to one folder, the last one winning; names
    // differing in case too, as some file systems do not tell them apart.
    let mut seen: BTreeMap<String, &Converted> = BTreeMap::new();
    for c in &summary.sequences {
        if let Some(first) = seen.insert(c.name.to_lowercase(), c) {
            return Err(DataError::format(
                Location::file(&c.source),
                format!(
                    "gives a sequence named `{}`, as {} gives `{}`: an output folder holds one \
                     sequence per name, whatever its case (rename one source)",
                    c.name,
                    ridi_data::shown(&first.source),
                    first.name
                ),
            ));
        }
    }
    if let Some(max_gap) = opts.split_at_gaps_s
        && summary.sequences.is_empty()
    {
        return Err(DataError::format(
            Location::file(source),
            format!(
                "no part of at least {SPLIT_MIN_PART_S} s between gaps longer than {} s in any \
                 sequence",
                short(max_gap)
            ),
        ));
    }
    for c in summary.sequences.iter().filter(|c| c.device.is_none()) {
        // A sequence without a device replaces one that had it: its old sidecar must go too.
        let rel = Path::new(&c.name).join("processed").join("data.csv");
        staging.remove(&sidecar_path(&rel));
    }

    // Lists are what training and evaluation read, and both need ground truth.
    let (listable, unlisted): (Vec<&Converted>, Vec<&Converted>) =
        summary.sequences.iter().partition(|c| c.ground_truth);
    let mut lists: BTreeMap<String, Vec<&Converted>> = BTreeMap::new();
    for &c in &listable {
        lists.entry("all".into()).or_default().push(c);
        if let Some(subject) = tyrex_subject(&c.name) {
            lists.entry(subject.to_string()).or_default().push(c);
        }
    }
    let (by_device, warnings) = device_lists(&listable, &lists);
    summary.warnings.extend(warnings);
    lists.extend(by_device);
    let mut rewritten = Vec::new();
    if !unlisted.is_empty() {
        let stale = stale_lists(out, &lists, &unlisted, &listed.lists);
        rewritten.extend(stale.iter().map(|l| l.name.clone()));
        for list in &stale {
            let rel = Path::new(&list.name);
            match &list.kept {
                Some(text) => write_atomically(&staging.file(rel)?, |w| write!(w, "{text}"))?,
                None => staging.remove(rel),
            }
        }
        summary
            .warnings
            .push(unlisted_warning(out, &unlisted, lists.is_empty(), &stale));
    }
    let mut written_lists = Vec::new();
    for (key, entries) in &lists {
        let name = format!("list_{key}.txt");
        write_atomically(&staging.file(Path::new(&name))?, |w| {
            writeln!(w, "{LIST_HEADER}{}`", source.display())?;
            for c in entries {
                writeln!(w, "{},{}", c.name, c.placement.as_deref().unwrap_or(""))?;
            }
            Ok(())
        })?;
        written_lists.push(out.join(name));
    }
    check_overwrites(&dirs, &listed.lists, &summary.sequences, &written_lists)?;
    let earlier = other_sources_lists(out, &lists, &rewritten, source);
    if !earlier.is_empty() {
        summary.warnings.push(format!(
            "{} holds list files of a conversion of another source, left as they are: {} (the \
             lists written now name this conversion's sequences alone)",
            ridi_data::shown(out),
            ridi_data::first_few(earlier.iter(), 5)
        ));
    }
    let warnings_file = Path::new(WARNINGS_FILE);
    if summary.warnings.is_empty() {
        staging.remove(warnings_file);
    } else {
        write_atomically(&staging.file(warnings_file)?, |w| {
            writeln!(w, "# warnings of `ridi convert {}`", source.display())?;
            for warning in &summary.warnings {
                writeln!(w, "{}", ridi_data::shown(warning))?;
            }
            Ok(())
        })?;
        summary.warnings_file = Some(out.join(WARNINGS_FILE));
    }
    staging.commit()?;
    summary.lists = written_lists;
    Ok(summary)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subject_is_the_first_part_of_a_tyrex_name() {
        assert_eq!(tyrex_subject("Jakob_Nexus5_NoDist_Texting"), Some("Jakob"));
        assert_eq!(
            tyrex_subject("Thibaud_Nexus5_NoDist_Phoning_part3"),
            Some("Thibaud")
        );
        // A reader's part split again at a gap.
        assert_eq!(
            tyrex_subject("Thibaud_Nexus5_NoDist_Phoning_part1_part2"),
            Some("Thibaud")
        );
        assert_eq!(tyrex_subject("dan_body1"), None);
        assert_eq!(tyrex_subject("x_Texting_partly"), None);
        assert_eq!(tyrex_subject("texting"), None);
    }

    #[test]
    fn path_files_are_found_in_sub_folders_as_a_fallback() {
        let dir = tempfile::tempdir().unwrap();
        let floor = dir.path().join("data/site1/F1");
        std::fs::create_dir_all(floor.join("path_data_files")).unwrap();
        for name in ["b.txt", "a.txt"] {
            let f = floor.join("path_data_files").join(name);
            std::fs::write(f, "#\tstartTime:1574559495255\n").unwrap();
        }
        std::fs::write(floor.join("floor_info.json"), "{}").unwrap();
        std::fs::write(floor.join("notes.txt"), "not a path file\n").unwrap();
        let want: Vec<PathBuf> = ["a.txt", "b.txt"]
            .iter()
            .map(|n| floor.join("path_data_files").join(n))
            .collect();
        assert_eq!(sources(dir.path(), None).unwrap().paths, want);
        assert_eq!(sources(dir.path(), Some(Format::Ilc)).unwrap().paths, want);
        assert_eq!(
            sources(&want[1], Some(Format::Ilc)).unwrap().paths,
            &want[1..]
        );
        assert_eq!(sources(&want[1], None).unwrap().paths, &want[1..]);
        let e = sources(&floor.join("notes.txt"), Some(Format::Ilc)).unwrap_err();
        assert!(
            e.to_string().contains(
                "notes.txt: not an Indoor Location Competition path file (it is a RIDI \
                 data_plain.txt): an Indoor Location Competition path file is a `.txt`"
            ),
            "{e}"
        );
        // Empty, a `.txt` is of no format: said so, not "a RIDI data_plain.txt".
        std::fs::write(floor.join("empty.txt"), "").unwrap();
        let e = sources(&floor.join("empty.txt"), Some(Format::Ilc)).unwrap_err();
        assert!(
            e.to_string()
                .contains("empty.txt: not an Indoor Location Competition path file (it is empty)"),
            "{e}"
        );
        let e = sources(&floor.join("floor_info.json"), None).unwrap_err();
        assert!(e.to_string().contains("unknown file type"), "{e}");
    }
}
