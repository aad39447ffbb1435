//! Reader of RIDI `data_plain.txt`, the input of the original C++ tools: a first line `N 27`,
//! then `N` rows of the 27 [`PROCESSED_COLUMNS`], tab-separated, without an index column. Any
//! run of spaces or tabs is accepted as a separator.
//! Magnet and ground truth follow the `data.csv` conventions (all zeros and all NaN mean absent).
//! A last row without a line break after it is refused, as a file cut off while being written.

use std::path::Path;

use crate::Sequence;
use crate::error::{DataError, Location, Result};
use crate::options::ReadOptions;
use crate::processed::{self, PROCESSED_COLUMNS, Table};
use crate::{sidecar, text};

/// Reads a `data_plain.txt`, and its device and orientation source from the optional sidecar
/// beside it ([`sidecar_path`](crate::sidecar_path)).
pub fn read(path: impl AsRef<Path>, opts: &ReadOptions) -> Result<Sequence> {
    let path = path.as_ref();
    let mut seq = parse(&text::read_file(path)?, path, opts)?;
    sidecar::read(path)?.apply(&mut seq);
    Ok(seq)
}

/// Parses the content of a `data_plain.txt`; `path` names the source in errors and gives the
/// name. The sidecar is not read: the sequence has no device.
pub fn parse(bytes: &[u8], path: &Path, opts: &ReadOptions) -> Result<Sequence> {
    let table = parse_table(text::as_text(bytes, path)?, path)?;
    processed::assemble(table, path, opts)
}

/// The first line of a `data_plain.txt`: the rows it announces, on `line`.
pub(crate) struct Header {
    pub(crate) line: usize,
    pub(crate) rows: usize,
}

/// The error for a file without its `N 27` line.
pub(crate) fn empty_file(path: &Path) -> DataError {
    DataError::format(
        Location::file(path),
        "file is empty: expected a `N 27` line and N rows",
    )
}

/// Parses the `N 27` line `header`, line `header_line`.
pub(crate) fn parse_header(header_line: usize, header: &str, path: &Path) -> Result<Header> {
    let mut cells = header.split_ascii_whitespace();
    let (Some(n), Some(width), None) = (cells.next(), cells.next(), cells.next()) else {
        return Err(DataError::format(
            Location::line(path, header_line),
            format!(
                "expected `N 27` (row and column counts), found `{}`{}",
                text::snippet(header),
                // What else a `.txt` of commas or comments may be.
                if header.split(',').any(|c| c.trim() == "gyro_x") {
                    ": this is the header of a RIDI `data.csv`; name the file `.csv` (or \
                     `.csv.gz`) for it to be read as one"
                } else if header.starts_with('#') || header.contains(',') {
                    ": if this is a list file (`path,placement` lines), it goes to `--list` of \
                     ridi train and ridi eval (`ridi.read_list` in Python, `Listed::read` in \
                     Rust)"
                } else {
                    ""
                }
            ),
        ));
    };
    let n = text::count(n, path, header_line, "rows")?;
    let width = text::count(width, path, header_line, "columns")?;
    if width != PROCESSED_COLUMNS.len() {
        return Err(DataError::format(
            Location::line(path, header_line).with_field("columns"),
            format!("{width} columns announced, the RIDI layout has 27"),
        ));
    }
    if n == 0 {
        return Err(DataError::format(
            Location::line(path, header_line).with_field("rows"),
            "announces no rows",
        ));
    }
    Ok(Header {
        line: header_line,
        rows: n,
    })
}

impl Header {
    /// The error for row `read + 1`, on `line`, beyond the announced count.
    pub(crate) fn too_many(&self, path: &Path, line: usize) -> DataError {
        DataError::format(
            Location::line(path, line),
            format!(
                "more rows than the {} announced on line {}",
                self.rows, self.line
            ),
        )
    }

    /// The error for a file that ends, after line `last_line`, with `read` rows of fewer than
    /// announced (`None`: as many as announced).
    pub(crate) fn too_few(&self, path: &Path, read: usize, last_line: usize) -> Option<DataError> {
        (read < self.rows).then(|| {
            DataError::format(
                Location::line(path, last_line),
                format!(
                    "file ends after {read} of the {} rows announced on line {}",
                    self.rows, self.line
                ),
            )
        })
    }

    /// Parses data line `line` (`content`, without its line ending).
    pub(crate) fn parse_row(&self, line: usize, content: &str, path: &Path) -> Result<[f64; 27]> {
        let width = PROCESSED_COLUMNS.len();
        let width_error = |fields: usize| {
            DataError::format(
                Location::line(path, line),
                format!(
                    "{fields} fields, expected {width}{}",
                    if fields < width {
                        " (truncated line?)"
                    } else {
                        ""
                    }
                ),
            )
        };
        processed::parse_row(
            || content.split_ascii_whitespace(),
            |k| (k < PROCESSED_COLUMNS.len()).then_some(k),
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
    let n = header.rows;
    // The count comes from the file: cap the reservation so a bogus count cannot exhaust memory.
    let mut rows = Vec::with_capacity(n.min(1 << 20));
    let mut row_lines = Vec::with_capacity(n.min(1 << 20));
    let mut last_line = header_line;
    for (line, content) in lines {
        if rows.len() == n {
            return Err(header.too_many(path, line));
        }
        rows.push(header.parse_row(line, content, path)?);
        row_lines.push(line);
        last_line = line;
    }
    if let Some(e) = header.too_few(path, rows.len(), last_line) {
        return Err(e);
    }
    let last_row = row_lines.last().map(|&l| Location::line(path, l));
    text::check_line_break(text, last_row, "")?;
    Ok(Table {
        rows,
        lines: row_lines,
        has_magnet: true,
        has_ground_truth: true,
        has_orientation: true,
    })
}
