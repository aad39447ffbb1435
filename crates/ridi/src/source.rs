//! Reading sequences from any supported layout, including those that yield several sequences.

use std::path::Path;

use ridi_data::tyrex::{self, TyrexOptions};
use ridi_data::{DataError, Format, ReadOptions, Sequence, detect, read_sequence};

/// Sequences read from one source, with the format they came in.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// Format of the source.
    pub format: Format,
    /// The sequences (a Tyrex recording split at a long mocap loss gives several).
    pub sequences: Vec<Sequence>,
    /// Things a user should know (splits, dropped parts).
    pub warnings: Vec<String>,
}

/// Reads the sequence(s) at `path`: a RIDI `data.csv`, `data_plain.txt`, RIDI raw folder,
/// Tyrex sequence folder or Indoor Location Competition path file. `from` forces a format
/// instead of detecting it.
pub fn read_any(
    path: &Path,
    from: Option<Format>,
    opts: &ReadOptions,
) -> Result<Loaded, DataError> {
    let format = match from {
        Some(f) => f,
        None => detect(path)?,
    };
    match format {
        Format::Tyrex => {
            let read = tyrex::read(path, &TyrexOptions::from(opts))?;
            Ok(Loaded {
                format,
                sequences: read.sequences,
                warnings: read.warnings,
            })
        }
        _ => {
            // A forced format must match what is there; a detected one does by construction.
            if from.is_some() {
                let found = detect(path)?;
                if found != format {
                    return Err(DataError::format(
                        ridi_data::Location::file(path),
                        format!("expected a {format}, found a {found}"),
                    ));
                }
            }
            Ok(Loaded {
                format,
                sequences: vec![read_sequence(path, opts)?],
                warnings: Vec::new(),
            })
        }
    }
}
