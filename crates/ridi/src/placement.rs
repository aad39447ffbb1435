//! Placement labels: grouping fine labels (e.g. the Tyrex motion names) into the classes a model
//! is trained on.

use std::collections::BTreeMap;
use std::path::Path;

use ridi_data::Sequence;

use crate::error::{PipelineError, Result};

/// Maps placement labels to class names; labels it does not name pass through unchanged.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct PlacementMap {
    map: BTreeMap<String, String>,
}

impl PlacementMap {
    /// The four groups of the Tyrex benchmark used by the accuracy protocol: `hand` (Texting,
    /// Phoning, AR), `swing` (Swinging), `pocket` (FrontPocket, BackPocket) and `running`
    /// (RunningHand, RunningPocket).
    pub fn tyrex_groups() -> Self {
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
        }
    }

    /// Reads `label,class` lines (`#` comments and blank lines skipped).
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| PipelineError::File {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        let mut map = BTreeMap::new();
        for (i, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let (label, class) = line
                .split_once(',')
                .map(|(a, b)| (a.trim(), b.trim()))
                .filter(|(a, b)| !a.is_empty() && !b.is_empty() && !b.contains(','))
                .ok_or_else(|| PipelineError::File {
                    path: path.to_path_buf(),
                    message: format!("line {}: expected `label,class`", i + 1),
                })?;
            map.insert(label.to_string(), class.to_string());
        }
        Ok(Self { map })
    }

    /// `tyrex4` for [`Self::tyrex_groups`], otherwise a file for [`Self::read`].
    pub fn from_arg(arg: &str) -> Result<Self> {
        if arg == "tyrex4" {
            Ok(Self::tyrex_groups())
        } else {
            Self::read(Path::new(arg))
        }
    }

    /// The class of `label`.
    pub fn class_of<'a>(&'a self, label: &'a str) -> &'a str {
        self.map.get(label).map(String::as_str).unwrap_or(label)
    }

    /// Relabels every sequence.
    pub fn apply(&self, seqs: &mut [Sequence]) {
        for s in seqs {
            let class = s.placement().map(|p| self.class_of(p).to_string());
            s.set_placement(class);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tyrex_groups_cover_every_motion() {
        let m = PlacementMap::tyrex_groups();
        for motion in ridi_data::tyrex::MOTIONS {
            assert_ne!(m.class_of(motion), motion, "{motion} has no group");
        }
        assert_eq!(m.class_of("bag"), "bag");
    }

    #[test]
    fn map_files_are_parsed_and_checked() {
        let dir = tempfile::tempdir().unwrap();
        let good = dir.path().join("map.txt");
        std::fs::write(&good, "# fine to coarse\nTexting, hand\n\nSwinging,swing\n").unwrap();
        let m = PlacementMap::read(&good).unwrap();
        assert_eq!(m.class_of("Texting"), "hand");
        assert_eq!(m.class_of("Swinging"), "swing");
        let bad = dir.path().join("bad.txt");
        std::fs::write(&bad, "Texting\n").unwrap();
        let err = PlacementMap::read(&bad).unwrap_err().to_string();
        assert!(err.contains("bad.txt") && err.contains("line 1"), "{err}");
    }
}
