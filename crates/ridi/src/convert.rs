//! `ridi convert`: any supported source to the RIDI processed layout, with list files.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use ridi_data::{
    DataError, Format, Location, ReadOptions, detect, write_atomically, write_ridi_csv,
};
use ridi_data::{ilc, tyrex};

use crate::source::read_any;

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
}

/// What converting one source produced: the sequences written and the warnings.
type Written = (Vec<Converted>, Vec<String>);

/// The sources under `source`: one sequence, the runs of a Tyrex root, the sequences one
/// level below a folder (a RIDI dataset folder), or else the Indoor Location Competition path
/// files in the folder and its sub-folders.
fn sources(source: &Path, from: Option<Format>) -> Result<Vec<PathBuf>, DataError> {
    let detected = detect(source).ok();
    if from.is_none_or(|f| f == Format::Tyrex) {
        if detected == Some(Format::Tyrex) {
            return Ok(vec![source.to_path_buf()]);
        }
        if let Ok(runs) = tyrex::list_sequences(source) {
            return Ok(runs);
        }
        if from == Some(Format::Tyrex) {
            return tyrex::list_sequences(source);
        }
    }
    if from == Some(Format::Ilc) && detected != Some(Format::Ilc) {
        return ilc::list_paths(source);
    }
    if detected.is_some() {
        return Ok(vec![source.to_path_buf()]);
    }
    if !source.is_dir() {
        // Say why the file is not a sequence rather than that it is not a folder.
        return detect(source).map(|_| vec![source.to_path_buf()]);
    }
    let entries = std::fs::read_dir(source).map_err(|e| DataError::io(source, e))?;
    let mut found = Vec::new();
    for entry in entries {
        let path = entry.map_err(|e| DataError::io(source, e))?.path();
        if path.is_dir() && detect(&path).is_ok_and(|f| from.is_none_or(|want| want == f)) {
            found.push(path);
        }
    }
    if found.is_empty() {
        if from.is_none()
            && let Ok(paths) = ilc::list_paths(source)
        {
            return Ok(paths);
        }
        return Err(DataError::format(
            Location::file(source),
            "no sequence found: expected a RIDI data.csv, data_plain.txt or raw folder, a Tyrex \
             folder or root, a folder of those, or Indoor Location Competition path files",
        ));
    }
    found.sort();
    Ok(found)
}

/// The person of a Tyrex run name `<Person>_<Phone>_<Dist>_<Motion>`, also for the parts
/// of a split run (`..._<Motion>_part2`).
fn tyrex_subject(name: &str) -> Option<&str> {
    let run = match name.rsplit_once("_part") {
        Some((run, n)) if !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()) => run,
        _ => name,
    };
    tyrex::motion_of(run)?;
    name.split('_').next()
}

/// Converts every sequence under `source` into `<out>/<name>/processed/data.csv` and writes
/// list files (`name,placement` per line, relative to `out`): `list_all.txt`, and for Tyrex
/// sources one `list_<person>.txt` per person. The placement of a Tyrex run is its motion name,
/// that of an Indoor Location Competition path `hand`.
pub fn convert(
    source: &Path,
    out: &Path,
    from: Option<Format>,
    opts: &ReadOptions,
) -> Result<ConvertSummary, DataError> {
    let dirs = sources(source, from)?;
    let results: Vec<Result<Written, DataError>> = dirs
        .par_iter()
        .map(|dir| {
            let loaded = read_any(dir, from.filter(|_| dirs.len() == 1), opts)?;
            let mut written = Vec::new();
            for seq in &loaded.sequences {
                let folder = out.join(seq.name()).join("processed");
                std::fs::create_dir_all(&folder).map_err(|e| DataError::io(&folder, e))?;
                let path = folder.join("data.csv");
                write_ridi_csv(seq, &path)?;
                written.push(Converted {
                    name: seq.name().to_string(),
                    placement: seq.placement().map(str::to_string),
                    path,
                    frames: seq.len(),
                });
            }
            let warnings = loaded
                .warnings
                .into_iter()
                .map(|w| format!("{}: {w}", dir.display()))
                .collect();
            Ok((written, warnings))
        })
        .collect();
    let mut summary = ConvertSummary::default();
    for r in results {
        let (written, warnings) = r?;
        summary.sequences.extend(written);
        summary.warnings.extend(warnings);
    }
    summary.sequences.sort_by(|a, b| a.name.cmp(&b.name));

    let mut lists: BTreeMap<String, Vec<&Converted>> = BTreeMap::new();
    for c in &summary.sequences {
        lists.entry("all".into()).or_default().push(c);
        if let Some(subject) = tyrex_subject(&c.name) {
            lists.entry(subject.to_string()).or_default().push(c);
        }
    }
    let mut written_lists = Vec::new();
    for (key, entries) in &lists {
        let path = out.join(format!("list_{key}.txt"));
        write_atomically(&path, |w| {
            writeln!(w, "# written by `ridi convert {}`", source.display())?;
            for c in entries {
                writeln!(w, "{},{}", c.name, c.placement.as_deref().unwrap_or(""))?;
            }
            Ok(())
        })?;
        written_lists.push(path);
    }
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
        assert_eq!(tyrex_subject("dan_body1"), None);
        assert_eq!(tyrex_subject("x_Texting_partly"), None);
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
        assert_eq!(sources(dir.path(), None).unwrap(), want);
        assert_eq!(sources(dir.path(), Some(Format::Ilc)).unwrap(), want);
        assert_eq!(sources(&want[1], Some(Format::Ilc)).unwrap(), &want[1..]);
        assert_eq!(sources(&want[1], None).unwrap(), &want[1..]);
        let e = sources(&floor.join("notes.txt"), Some(Format::Ilc)).unwrap_err();
        assert!(
            e.to_string()
                .contains("no Indoor Location Competition path file"),
            "{e}"
        );
        let e = sources(&floor.join("floor_info.json"), None).unwrap_err();
        assert!(e.to_string().contains("unknown file type"), "{e}");
    }
}
