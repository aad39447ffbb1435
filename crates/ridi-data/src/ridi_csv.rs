//! Reader of RIDI processed `data.csv` files.
//!
//! Columns are selected by header name, so the leading unnamed pandas index column, extra
//! columns of later versions and any column order are all accepted. Required: `time`, `gyro_*`,
//! `acce_*`. Optional: `linacce_*`, `grav_*` and `rv_*` together, the phone's own orientation
//! (without them, as a recorder that logs only the gyro and the accelerometer writes the file,
//! the orientation is estimated from those two:
//! [`SequenceParts::estimate_orientation`](crate::SequenceParts::estimate_orientation), the
//! source [`Estimated`](crate::OrientationSource::Estimated)); `magnet_*` (all zeros also means
//! "not recorded"); and `pos_*` with `ori_*` together (NaN on every row also means "no ground
//! truth"). Time is in nanoseconds and becomes absolute seconds. A last row without a line break
//! after it is refused: the file was cut off while being written, maybe inside a value. The
//! device and the orientation source, which the layout has no column for, come from the
//! optional sidecar ridi-rs writes beside the file ([`sidecar_path`](crate::sidecar_path)).

use std::path::Path;

use crate::error::{DataError, Location, Result};
use crate::options::ReadOptions;
use crate::processed::{self, LINACCE, MAGNET, POS, PROCESSED_COLUMNS, RV, Table};
use crate::{OrientationSource, Sequence};
use crate::{sidecar, text};

/// Reads a RIDI processed `data.csv`. The sequence is named after its capture folder (see
/// [`read_sequence`](crate::read_sequence)); its device and orientation source are those the
/// optional sidecar beside the file names ([`sidecar_path`](crate::sidecar_path)), else none and
/// RIDI's game rotation vector (or, without orientation columns, the estimate: the sidecar may
/// then name no other source).
pub fn read(path: impl AsRef<Path>, opts: &ReadOptions) -> Result<Sequence> {
    let path = path.as_ref();
    let mut seq = parse(&text::read_file(path)?, path, opts)?;
    let side = sidecar::read(path)?;
    if seq.orientation_source() == Some(OrientationSource::Estimated) {
        side.check_estimated(path)?;
    }
    side.apply(&mut seq);
    Ok(seq)
}

/// Parses the content of a `data.csv`; `path` names the source in errors and gives the name.
/// The sidecar is not read: the sequence has no device.
pub fn parse(bytes: &[u8], path: &Path, opts: &ReadOptions) -> Result<Sequence> {
    let table = parse_table(text::as_text(bytes, path)?, path)?;
    processed::assemble(table, path, opts)
}

/// Header cell as a plain name: pandas writes bare names, other tools may quote them.
fn header_name(cell: &str) -> &str {
    let c = cell.trim();
    c.strip_prefix('"')
        .and_then(|c| c.strip_suffix('"'))
        .unwrap_or(c)
        .trim()
}

/// The [`PROCESSED_COLUMNS`] index fed by each file column (`None` for the index and unknown
/// columns).
pub(crate) struct Header {
    pub(crate) line: usize,
    slots: Vec<Option<usize>>,
    pub(crate) has_magnet: bool,
    pub(crate) has_ground_truth: bool,
    /// `linacce_*`, `grav_*` and `rv_*` are in the file (else the orientation is estimated).
    pub(crate) has_orientation: bool,
}

pub(crate) fn parse_header(line: usize, content: &str, path: &Path) -> Result<Header> {
    let at = |field: &str| Location::line(path, line).with_field(field);
    // A line break is `\n` or `\r\n`: a `\r` left inside is a file of `\r` alone, read as
    // one line.
    if content.trim_end().contains('\r') {
        return Err(DataError::format(
            Location::line(path, line),
            "the header runs on past a carriage return: the file's lines end in a carriage \
             return alone (classic Mac OS line endings); convert them to line feeds (`tr '\\r' \
             '\\n'`)",
        ));
    }
    let mut slots = Vec::new();
    let mut found = [false; 27];
    // Names of no column of the layout, for the error about a missing one (a typo, `gyroy`).
    let mut unknown = Vec::new();
    for cell in text::cells(content, b',') {
        let name = header_name(cell);
        let slot = PROCESSED_COLUMNS.iter().position(|&c| c == name);
        if let Some(k) = slot {
            if found[k] {
                return Err(DataError::format(at(name), "column appears twice"));
            }
            found[k] = true;
        } else if !name.is_empty() {
            unknown.push(format!("`{}`", text::snippet(name)));
        }
        slots.push(slot);
    }
    if slots.len() == 1
        && let Some(sep) = [';', '\t', ' ']
            .into_iter()
            .find(|&c| content.trim().contains(c))
    {
        return Err(DataError::format(
            Location::line(path, line),
            format!("the header is one column holding {sep:?}: a data.csv is separated by commas"),
        ));
    }
    let unknown = match unknown.len() {
        0 => String::new(),
        _ => format!(
            "; unknown columns in the header: {}",
            crate::first_few(unknown.into_iter(), 5)
        ),
    };
    let at = |k: usize| at(PROCESSED_COLUMNS[k]);
    group(&found, 0..LINACCE, true, "required", at, &unknown)?;
    let has_orientation = group(
        &found,
        (LINACCE..MAGNET).chain(RV..27),
        false,
        "linacce_*, grav_* and rv_* come together: give all of them, or none to have the \
         orientation estimated from gyro_* and acce_*",
        at,
        &unknown,
    )?;
    let has_magnet = group(
        &found,
        MAGNET..POS,
        false,
        "the magnet columns come as a set",
        at,
        &unknown,
    )?;
    let has_ground_truth = group(
        &found,
        POS..RV,
        false,
        "ground truth needs all of pos_* and ori_*",
        at,
        &unknown,
    )?;
    Ok(Header {
        line,
        slots,
        has_magnet,
        has_ground_truth,
        has_orientation,
    })
}

/// Whether the group of `columns` is in the file (`found`): when any of its columns is, all of
/// them must be (else an error at `at` of the first missing one, ending in `unknown`, the
/// header's names of no column); `required`, always.
fn group(
    found: &[bool; 27],
    mut columns: impl Iterator<Item = usize> + Clone,
    required: bool,
    what: &str,
    at: impl Fn(usize) -> Location,
    unknown: &str,
) -> Result<bool> {
    if !required && !columns.clone().any(|k| found[k]) {
        return Ok(false);
    }
    match columns.find(|&k| !found[k]) {
        Some(k) => Err(DataError::format(
            at(k),
            format!(
                "missing column `{}` ({what}){unknown}",
                PROCESSED_COLUMNS[k]
            ),
        )),
        None => Ok(true),
    }
}

/// The error for a file without a header line.
pub(crate) fn empty_file(path: &Path) -> DataError {
    DataError::format(
        Location::file(path),
        "file is empty: expected a header line and data rows",
    )
}

/// The error for a file with a header line on `line` and no data rows.
pub(crate) fn no_rows(path: &Path, line: usize) -> DataError {
    DataError::format(
        Location::line(path, line),
        "only a header line, no data rows",
    )
}

impl Header {
    /// Parses data line `line` (`content`, without its line ending) into the
    /// [`PROCESSED_COLUMNS`]; columns that are not in the file stay NaN (assembling never
    /// reads them).
    pub(crate) fn parse_row(&self, line: usize, content: &str, path: &Path) -> Result<[f64; 27]> {
        let width = self.slots.len();
        let width_error = |fields: usize| {
            DataError::format(
                Location::line(path, line),
                format!(
                    "{fields} fields where the header on line {} has {width}{}",
                    self.line,
                    if fields < width {
                        " (truncated line?)"
                    } else {
                        ""
                    }
                ),
            )
        };
        processed::parse_row(
            || text::cells(content, b','),
            |c| self.slots.get(c).copied().flatten(),
            width,
            width_error,
            path,
            line,
        )
    }
}

fn parse_table(text: &str, path: &Path) -> Result<Table> {
    let mut lines = text::lines(text);
    let Some((header_line, header)) = lines.next() else {
        return Err(empty_file(path));
    };
    let header = parse_header(header_line, header, path)?;
    let mut rows = Vec::new();
    let mut row_lines = Vec::new();
    for (line, content) in lines {
        rows.push(header.parse_row(line, content, path)?);
        row_lines.push(line);
    }
    if rows.is_empty() {
        return Err(no_rows(path, header.line));
    }
    let last_row = row_lines.last().map(|&l| Location::line(path, l));
    text::check_line_break(text, last_row, "")?;
    Ok(Table {
        rows,
        lines: row_lines,
        has_magnet: header.has_magnet,
        has_ground_truth: header.has_ground_truth,
        has_orientation: header.has_orientation,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_groups_are_all_or_nothing() {
        let p = Path::new("h.csv");
        let full = format!(",{}", PROCESSED_COLUMNS.join(","));
        let h = parse_header(1, &full, p).unwrap();
        assert!(h.has_magnet && h.has_ground_truth);
        assert_eq!(h.slots[0], None);
        assert_eq!(h.slots[1], Some(0));
        let no_gt: Vec<_> = PROCESSED_COLUMNS
            .iter()
            .filter(|c| !c.starts_with("pos") && !c.starts_with("ori"))
            .copied()
            .collect();
        let h = parse_header(1, &no_gt.join(","), p).unwrap();
        assert!(h.has_magnet && !h.has_ground_truth && h.has_orientation);
        // A typo is named beside the column it misses; another separator is named alone.
        let e = parse_header(1, "time,gyro_x,gyroy,gyro_z,acce_x,acce_y,acce_z", p)
            .err()
            .unwrap();
        assert_eq!(
            e.to_string(),
            "h.csv:1: field `gyro_y`: missing column `gyro_y` (required); unknown columns in \
             the header: `gyroy`"
        );
        let e = parse_header(1, "time;gyro_x;gyro_y;gyro_z;acce_x;acce_y;acce_z", p)
            .err()
            .unwrap();
        assert_eq!(
            e.to_string(),
            "h.csv:1: the header is one column holding ';': a data.csv is separated by commas"
        );
        let bare = "time,gyro_x,gyro_y,gyro_z,acce_x,acce_y,acce_z";
        let h = parse_header(1, bare, p).unwrap();
        assert!(!h.has_magnet && !h.has_ground_truth && !h.has_orientation);
        let e = parse_header(1, &format!("{bare},rv_w,rv_x,rv_y,rv_z"), p)
            .err()
            .unwrap();
        assert!(
            e.to_string()
                .starts_with("h.csv:1: field `linacce_x`: missing column"),
            "{e}"
        );
        let partial: Vec<_> = PROCESSED_COLUMNS
            .iter()
            .filter(|&&c| c != "ori_z")
            .copied()
            .collect();
        let e = parse_header(1, &partial.join(","), p).err().unwrap();
        assert!(
            e.to_string()
                .starts_with("h.csv:1: field `ori_z`: missing column"),
            "{e}"
        );
        let e = parse_header(1, &format!("{full},gyro_x"), p).err().unwrap();
        assert!(
            e.to_string().contains("`gyro_x`: column appears twice"),
            "{e}"
        );
    }
}
