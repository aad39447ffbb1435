//! Placement labels: grouping fine labels (e.g. the Tyrex motion names) into the classes a model
//! is trained on.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use ridi_data::{DataError, Location, Sequence};

use crate::error::{PipelineError, Result};

/// Largest placement map file, bytes: a map names labels, not data.
const MAX_MAP_BYTES: u64 = 1 << 20;

/// Maps placement labels to class names. Every label in use must be in the map, or be one of
/// its classes: [`PlacementMap::class_at`] is an error for any other.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct PlacementMap {
    map: BTreeMap<String, String>,
    /// `tyrex4`, or the map file, for error messages.
    name: String,
}

impl PlacementMap {
    /// The four groups of the Tyrex benchmark used by the accuracy protocol, `--placement-map
    /// tyrex4` (Python `placement_map="tyrex4"`): `hand` (Texting, Phoning, AR), `swing`
    /// (Swinging), `pocket` (FrontPocket, BackPocket) and `running` (RunningHand,
    /// RunningPocket).
    pub fn tyrex4() -> Self {
        let pairs = [
            ("Texting", "hand"),
            ("Phoning", "hand"),
            ("AR", "hand"),
            ("Swinging", "swing"),
            ("FrontPocket", "pocket"),
            ("BackPocket", "pocket"),
            ("RunningHand", "running"),
            ("RunningPocket", "running"),
        ];
        Self {
            map: pairs
                .iter()
                .map(|(a, b)| (a.to_string(), b.to_string()))
                .collect(),
            name: "tyrex4".into(),
        }
    }

    /// Reads `label,class` lines (`#` comments and blank lines skipped). A label given two
    /// different classes, a class that is also a label mapped on (a chain), a file without any
    /// entry, and a list file (every label a path beside it, with a separator or an extension)
    /// are errors.
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        // At the file and line, as every reader's error is.
        let error = |line: Option<usize>, message: String| {
            let at = line.map_or_else(|| Location::file(path), |l| Location::line(path, l));
            PipelineError::Data(DataError::format(at, message))
        };
        let text = ridi_data::read_text(path, MAX_MAP_BYTES)?;
        let mut map: BTreeMap<String, (String, usize)> = BTreeMap::new();
        for (i, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let (label, class) = line
                .split_once(',')
                .map(|(a, b)| (a.trim(), b.trim()))
                .filter(|(a, b)| !a.is_empty() && !b.is_empty() && !b.contains(','))
                .ok_or_else(|| error(Some(i + 1), "expected `label,class`".into()))?;
            if let Some((first, at)) = map.get(label)
                && first != class
            {
                return Err(error(
                    Some(i + 1),
                    format!("`{label}` is mapped to `{class}` here but to `{first}` on line {at}"),
                ));
            }
            map.insert(label.to_string(), (class.to_string(), i + 1));
        }
        if map.is_empty() {
            return Err(error(
                None,
                "no `label,class` entry in the placement map".into(),
            ));
        }
        // Applied once, a chain maps `a` to `b` but `b` to `c`: what was meant is unclear.
        for (label, (class, at)) in &map {
            if let Some((next, next_at)) = map.get(class).filter(|(next, _)| next != class) {
                return Err(error(
                    Some(*next_at),
                    format!(
                        "`{class}` is a class (of `{label}`, line {at}) and a label mapped to \
                         `{next}` here: a map is applied once, so `{label}` would become \
                         `{class}` and `{class}` `{next}`; map each label to its final class"
                    ),
                ));
            }
        }
        // A list file given for a map: its labels are the recordings' paths (a path is told
        // by a separator or an extension: a map's labels may name folders beside it, `AR/`).
        let folder = path.parent().unwrap_or(Path::new(""));
        let a_path = |label: &String| {
            (label.contains(std::path::is_separator) || Path::new(label).extension().is_some())
                && folder.join(label).exists()
        };
        if map.keys().all(a_path) {
            return Err(error(
                None,
                "every label is the path of a file or folder beside it: a list file \
                 (`path,placement` lines, for `--list`), not a placement map (`label,class` \
                 lines)"
                    .into(),
            ));
        }
        Ok(Self {
            map: map.into_iter().map(|(l, (c, _))| (l, c)).collect(),
            name: path.display().to_string(),
        })
    }

    /// `tyrex4` for [`Self::tyrex4`], otherwise a file for [`Self::read`] (a missing
    /// one is named with the `tyrex4` alternative: a mistyped group name reads as a path).
    pub fn from_arg(arg: impl AsRef<Path>) -> Result<Self> {
        let arg = arg.as_ref();
        if arg.as_os_str() == "tyrex4" {
            return Ok(Self::tyrex4());
        }
        Self::read(arg).map_err(|e| match e {
            PipelineError::Data(DataError::Io { path, error })
                if error.kind() == std::io::ErrorKind::NotFound =>
            {
                PipelineError::File {
                    path,
                    message: format!(
                        "{error} (a placement map is `tyrex4` or a file of `label,class` lines)"
                    ),
                }
            }
            e => e,
        })
    }

    /// The classes of the map, sorted.
    fn classes(&self) -> BTreeSet<&str> {
        self.map.values().map(String::as_str).collect()
    }

    /// The class of `label`, when the map has it; a class of the map is its own class (an
    /// Indoor Location Competition path is labelled `hand`, say).
    pub fn class_of<'a>(&'a self, label: &'a str) -> Option<&'a str> {
        match self.map.get(label) {
            Some(class) => Some(class),
            None => self.classes().contains(label).then_some(label),
        }
    }

    /// The class of `label`, the placement of the sequence listed at `at`; a label the map does
    /// not have is an error naming `at`, the label and the labels and classes the map has.
    pub fn class_at<'a>(&'a self, label: &'a str, at: Location) -> Result<&'a str> {
        self.class_of(label).ok_or_else(|| {
            DataError::format(at.with_field("placement"), self.unknown(label)).into()
        })
    }

    /// Refuses a sequence whose placement label the map does not have, naming the sequence:
    /// what [`crate::load_listed`] refuses of a listed one, for sequences built otherwise
    /// (Python's `Sequence`s). Call it before [`Self::apply`].
    pub fn check(&self, seqs: &[Sequence]) -> Result<()> {
        for s in seqs {
            if let Some(label) = s.placement().filter(|l| self.class_of(l).is_none()) {
                return Err(crate::PipelineError::sequence(
                    s.name(),
                    self.unknown(label),
                ));
            }
        }
        Ok(())
    }

    /// The message for `label`, which the map does not have.
    fn unknown(&self, label: &str) -> String {
        let labels: Vec<&str> = self.map.keys().map(String::as_str).collect();
        let classes: Vec<&str> = self.classes().into_iter().collect();
        format!(
            "placement `{}` is not in the placement map {} (labels {}; classes {})",
            ridi_data::shown(label),
            self.name,
            labels.join(", "),
            classes.join(", ")
        )
    }

    /// Relabels every sequence whose label the map has; others keep theirs (load list files
    /// with [`crate::load_listed`], which refuses labels the map does not have, or
    /// [`Self::check`] the sequences first).
    pub fn apply(&self, seqs: &mut [Sequence]) {
        for s in seqs {
            if let Some(class) = s.placement().and_then(|p| self.class_of(p)) {
                let class = class.to_string();
                s.set_placement(Some(class));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tyrex4_covers_every_motion() {
        let m = PlacementMap::tyrex4();
        for motion in ridi_data::tyrex::MOTIONS {
            assert!(m.class_of(motion).is_some(), "{motion} has no group");
        }
        assert_eq!(m.class_of("bag"), None);
        assert_eq!(m.class_of("hand"), Some("hand"));
        let err = m
            .class_at("Swingin", Location::line("list.txt", 4))
            .unwrap_err()
            .to_string();
        assert_eq!(
            err,
            "list.txt:4: field `placement`: placement `Swingin` is not in the placement map \
             tyrex4 (labels AR, BackPocket, FrontPocket, Phoning, RunningHand, RunningPocket, \
             Swinging, Texting; classes hand, pocket, running, swing)"
        );
    }

    #[test]
    fn map_files_are_parsed_and_checked() {
        let dir = tempfile::tempdir().unwrap();
        let good = dir.path().join("map.txt");
        std::fs::write(
            &good,
            "# fine to coarse\nTexting, hand\n\nSwinging,swing\nTexting,hand\n",
        )
        .unwrap();
        let m = PlacementMap::read(&good).unwrap();
        assert_eq!(m.class_of("Texting"), Some("hand"));
        assert_eq!(m.class_of("Swinging"), Some("swing"));
        let err = m
            .class_at("BackPocket", Location::line("l.txt", 2))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("`BackPocket` is not in the placement map")
                && err.contains("map.txt (labels Swinging, Texting; classes hand, swing)"),
            "{err}"
        );

        let bad = dir.path().join("bad.txt");
        for (text, want) in [
            ("Texting\n", "bad.txt:1: expected `label,class`"),
            (
                "Texting,hand\nBackPocket,pocket\nTexting,pocket\n",
                "bad.txt:3: `Texting` is mapped to `pocket` here but to `hand` on line 1",
            ),
            ("", "bad.txt: no `label,class` entry"),
            ("# nothing\n\n", "bad.txt: no `label,class` entry"),
            (
                "AR,hand\nhand,swing\n",
                "bad.txt:2: `hand` is a class (of `AR`, line 1) and a label mapped to `swing` \
                 here: a map is applied once",
            ),
            // A list file given for a map: its labels are paths beside it.
            (
                "map.txt,hand\nbad.txt,swing\n",
                "bad.txt: every label is the path of a file or folder beside it: a list file",
            ),
        ] {
            std::fs::write(&bad, text).unwrap();
            let err = PlacementMap::read(&bad).unwrap_err().to_string();
            assert!(err.contains(want), "{text:?}: {err}");
        }

        // What is not a readable map file: named as the readers name it, a typo of `tyrex4`
        // with what a map may be.
        let missing = dir.path().join("tyrex5");
        for (arg, want) in [
            (
                missing.clone(),
                "tyrex5: no such file or folder (a placement map is `tyrex4` or a file of \
                 `label,class` lines)",
            ),
            (
                dir.path().to_path_buf(),
                ": is a folder: it is not a regular file",
            ),
        ] {
            let err = PlacementMap::from_arg(&arg).unwrap_err().to_string();
            assert!(err.ends_with(want), "{arg:?}: {err}");
        }
        let err = PlacementMap::read(&missing).unwrap_err().to_string();
        assert!(err.ends_with("tyrex5: no such file or folder"), "{err}");
        assert_eq!(
            PlacementMap::from_arg("tyrex4").unwrap(),
            PlacementMap::tyrex4()
        );
    }
}
