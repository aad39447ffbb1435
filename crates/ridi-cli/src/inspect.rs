//! `ridi inspect`: describe a recording or a model file.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Result;

use ridi::data::{ReadOptions, shown};
use ridi::regress::MODEL_MAGIC;

#[derive(clap::Args)]
pub(crate) struct Args {
    /// A RIDI data.csv, data_plain.txt, RIDI raw folder, Tyrex sequence folder, Indoor
    /// Location Competition path file, RoNIN sequence folder (data.hdf5, info.json), or a
    /// model file of `ridi train`.
    sequence: PathBuf,
    /// Print JSON instead of text: one object, or an array of the parts of a recording
    /// split at its gaps (each with the reader's warnings).
    #[arg(long)]
    json: bool,
}

pub(crate) fn run(Args { sequence, json }: Args) -> Result<()> {
    if is_model_file(&sequence) {
        let model = crate::load_model(&sequence)?;
        let report = ridi::inspect_model(&model);
        return crate::print_result(&if json {
            json_text(&report)?
        } else {
            report.to_string()
        });
    }
    // A recording that streams is summed up as it is read, in memory that does not grow with
    // its length.
    // A recording paused for longer than the readers' limit is described (its longest gap
    // among the warnings) where its format keeps the pause as a gap.
    let format = ridi::source_format(&sequence, None);
    let opts = match &format {
        Ok(format) => ReadOptions::default().reading_pauses(*format),
        Err(_) => ReadOptions::default(),
    };
    if format.as_ref().is_ok_and(|f| f.streams()) {
        let rows = ridi::data::RowReader::open(&sequence, &opts)?;
        let report = ridi::inspect_stream(rows)?;
        return crate::print_result(&if json {
            json_text(&report)?
        } else {
            report.to_string()
        });
    }
    let loaded = ridi::read_any(&sequence, None, &opts)?;
    let mut reports = Vec::new();
    for seq in &loaded.sequences {
        let mut report = ridi::inspect(seq, loaded.format);
        if json {
            // The reader's warnings (gaps, splits, dropped parts) belong to every part.
            report
                .warnings
                .splice(0..0, loaded.warnings.iter().cloned());
        }
        reports.push(report);
    }
    if json {
        // One object, or an array of the parts of a recording split at its gaps.
        crate::print_result(&match &reports[..] {
            [one] => json_text(one)?,
            parts => json_text(&parts)?,
        })
    } else {
        let mut text = String::new();
        for (i, report) in reports.iter().enumerate() {
            if i > 0 {
                text.push('\n');
            }
            let _ = write!(text, "{report}");
        }
        // Once for the recording, not once per part.
        for w in &loaded.warnings {
            let _ = writeln!(text, "warning:      {}", shown(w));
        }
        crate::print_result(&text)
    }
}

/// `true` for a `.ridi` file, or a file that starts like a model file or is a model file's
/// first bytes cut short (recordings never are): loading it then says what is wrong with it.
/// Only a regular file is opened, as every reader does: opening a FIFO waits for a writer for
/// ever, and a device can hand out bytes for ever. What is none is left to the readers, which
/// refuse it.
fn is_model_file(path: &Path) -> bool {
    use std::io::Read;
    // `metadata` does not open the file.
    if !std::fs::metadata(path).is_ok_and(|m| m.is_file()) {
        return false;
    }
    // A `.ridi` file is meant as a model: if it is none, say so, not which data it is not.
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ridi"))
    {
        return true;
    }
    let Ok(file) = std::fs::File::open(path) else {
        return false;
    };
    let mut head = Vec::new();
    let magic = &MODEL_MAGIC;
    file.take(magic.len() as u64).read_to_end(&mut head).is_ok()
        && !head.is_empty()
        && magic.starts_with(&head)
}

/// `value` as the JSON `--json` prints: pretty, [`escaped`], a line of its own.
pub(crate) fn json_text(value: &impl serde::Serialize) -> Result<String> {
    Ok(escaped(serde_json::to_string_pretty(value)?) + "\n")
}

/// serde_json's `json` with DEL and the C1 controls (U+007F-U+009F) escaped too (`\u009b`), as
/// it escapes U+0000-U+001F: they are valid JSON raw, but a terminal may obey them (U+009B
/// starts an escape sequence on some). They can only be inside strings (JSON's own syntax is
/// ASCII), where the escape stands for the same character.
fn escaped(json: String) -> String {
    let raw = |c: char| ('\u{7f}'..='\u{9f}').contains(&c);
    if !json.contains(raw) {
        return json;
    }
    let mut out = String::with_capacity(json.len() + 16);
    for c in json.chars() {
        if raw(c) {
            let _ = write!(out, "\\u{:04x}", u32::from(c));
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::escaped;

    #[test]
    fn json_escapes_del_and_c1_as_it_escapes_c0() {
        let json = serde_json::to_string(&["a\u{1b}b\u{7f}c\u{9b}d\u{a0}é"]).unwrap();
        let text = escaped(json);
        assert_eq!(text, "[\"a\\u001bb\\u007fc\\u009bd\u{a0}é\"]");
        assert!(!text.chars().any(char::is_control), "{text:?}");
        // The same strings, read back.
        let back: Vec<String> = serde_json::from_str(&text).unwrap();
        assert_eq!(back, ["a\u{1b}b\u{7f}c\u{9b}d\u{a0}é"]);
        assert_eq!(escaped("{\"a\": 1}".into()), "{\"a\": 1}");
    }
}
