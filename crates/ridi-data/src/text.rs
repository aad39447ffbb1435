//! Line and field parsing shared by every text reader, so that all of them turn bytes into
//! numbers the same way and report errors with the same file, line and field.

use std::path::Path;

use crate::error::{DataError, Location, Result};
use crate::sequence_error::{axis_name, beyond, jump, short};
use crate::{Channel, SequenceError, Validation};

/// Reads a whole file; the readers parse from memory because one pass over a byte slice is much
/// faster than buffered line reading with a `String` per line.
pub(crate) fn read_file(path: &Path) -> Result<Vec<u8>> {
    read_file_bounded(path, u64::MAX)
}

/// [`read_file`] of a file that is at most `max` bytes on disk, checked before reading: a list
/// or a small table has a size its format bounds. Every read refuses what is not a regular
/// file (a folder, `/dev/zero`, a pipe): a device can hand out bytes for ever.
pub(crate) fn read_file_bounded(path: &Path, max: u64) -> Result<Vec<u8>> {
    let meta = regular_file(path)?;
    if meta.len() > max {
        return Err(DataError::format(
            Location::file(path),
            format!(
                "{} bytes: larger than such a file can be ({max} bytes at most)",
                meta.len()
            ),
        ));
    }
    let bytes = std::fs::read(path).map_err(|e| DataError::io(path, e))?;
    gunzip_if_gzip(bytes, path)
}

/// The text of a small file (a list, a placement map, a report): at most `max` bytes on disk,
/// gzip-compressed or not, UTF-8 with or without a byte-order mark. What is not a regular file
/// (a folder, `/dev/zero`, a pipe) is refused before reading; errors name the file (and the
/// line that is not UTF-8).
pub fn read_text(path: impl AsRef<Path>, max: u64) -> Result<String> {
    let path = path.as_ref();
    let bytes = read_file_bounded(path, max)?;
    as_text(&bytes, path).map(str::to_owned)
}

/// How a model file of `ridi train` starts (`ridi_regress::MODEL_MAGIC`, a crate above this
/// one): a list, a list entry or a recording that is one gets an error that says so.
const MODEL_MAGIC: &[u8] = b"RIDIREG\0";

/// What a model file given where data were expected is, and where it goes (the errors of
/// detection and of list files).
pub(crate) const A_MODEL_FILE: &str =
    "a model file of `ridi train` (load it with `--model`, in Python `ridi.load`)";

/// Whether `path` is a regular file that starts as a model file does (whatever its size; only
/// a regular file is opened: a pipe would wait for a writer).
pub(crate) fn is_model_file(path: &Path) -> bool {
    use std::io::Read as _;
    let mut head = [0u8; 8];
    path.is_file()
        && std::fs::File::open(path).is_ok_and(|mut f| f.read_exact(&mut head).is_ok())
        && head == MODEL_MAGIC
}

/// Whether there is a directory entry `path`: a folder, a device or a symbolic link that leads
/// to no file counts, so that an optional file of that name is read (and the read says what
/// it is) rather than taken as absent.
pub(crate) fn present(path: &Path) -> bool {
    std::fs::symlink_metadata(path).is_ok()
}

/// [`present`], but an entry that cannot be looked at (a folder on its path that may not be
/// entered) is an error naming it: not "absent", which would blame the recording's layout.
pub(crate) fn present_or_error(path: &Path) -> Result<bool> {
    match std::fs::symlink_metadata(path) {
        Ok(_) => Ok(true),
        Err(e) if e.kind() == std::io::ErrorKind::PermissionDenied => Err(DataError::io(path, e)),
        Err(_) => Ok(false),
    }
}

/// The metadata of `path`, refused when it is not a regular file (a folder, `/dev/zero`, a
/// pipe): a device can hand out bytes for ever.
pub(crate) fn regular_file(path: &Path) -> Result<std::fs::Metadata> {
    let meta = std::fs::metadata(path).map_err(|e| DataError::io(path, e))?;
    if !meta.is_file() {
        return Err(DataError::format(
            Location::file(path),
            if meta.is_dir() {
                "is a folder: it is not a regular file"
            } else {
                "is a device, a pipe or a socket: it is not a regular file"
            },
        ));
    }
    Ok(meta)
}

/// Largest ratio of decompressed to compressed size a gzip input may have: sensor text (time
/// stamps, noisy readings) compresses 2-10 times; a file of newlines or zeros 400-1000 times (a
/// gzip bomb: 2.9 MB would expand to 3 GB before any check could look at it).
pub(crate) const MAX_GZIP_RATIO: u64 = 200;

/// Decompressed size every gzip input may reach whatever its ratio (small files of constant
/// values are fine), bytes.
const GZIP_ALLOWANCE: u64 = 64 << 20;

/// Decompresses gzip data (recognized by its magic bytes, whatever the file name), so every
/// text format can be stored compressed (`data.csv.gz`). The output is bounded by
/// [`MAX_GZIP_RATIO`] times the input (at least 64 MiB): beyond, an error, not the machine's
/// memory.
pub(crate) fn gunzip_if_gzip(bytes: Vec<u8>, path: &Path) -> Result<Vec<u8>> {
    if !bytes.starts_with(&[0x1f, 0x8b]) {
        return Ok(bytes);
    }
    let limit = gzip_limit(bytes.len() as u64);
    let mut out = Vec::with_capacity(bytes.len().saturating_mul(4));
    let decoder = flate2::read::MultiGzDecoder::new(&bytes[..]);
    std::io::Read::read_to_end(&mut std::io::Read::take(decoder, limit + 1), &mut out).map_err(
        |e| {
            DataError::format(
                Location::file(path),
                format!("corrupt or truncated gzip data, or other bytes after its end: {e}"),
            )
        },
    )?;
    if out.len() as u64 > limit {
        return Err(gzip_too_large(path, limit, bytes.len() as u64));
    }
    Ok(out)
}

/// How many bytes a gzip input of `compressed` bytes may decompress to ([`gunzip_if_gzip`]).
pub(crate) fn gzip_limit(compressed: u64) -> u64 {
    compressed
        .saturating_mul(MAX_GZIP_RATIO)
        .max(GZIP_ALLOWANCE)
}

/// The error for a gzip input of `compressed` bytes that decompresses beyond `limit`.
pub(crate) fn gzip_too_large(path: &Path, limit: u64, compressed: u64) -> DataError {
    DataError::format(
        Location::file(path),
        format!(
            "decompresses to more than {limit} bytes, over {MAX_GZIP_RATIO} times its \
             {compressed} compressed bytes: not a recording (sensor text compresses 2-10 \
             times); refused before it fills the memory"
        ),
    )
}

/// The bytes as UTF-8 text without a leading byte-order mark; the error names the first line
/// that is not valid UTF-8.
pub(crate) fn as_text<'a>(bytes: &'a [u8], path: &Path) -> Result<&'a str> {
    match std::str::from_utf8(bytes) {
        Ok(s) => Ok(s.strip_prefix('\u{feff}').unwrap_or(s)),
        Err(e) => {
            let line = bytes
                .get(..e.valid_up_to())
                .map_or(0, |b| b.iter().filter(|&&c| c == b'\n').count())
                + 1;
            Err(DataError::format(
                Location::line(path, line),
                "is not UTF-8 text",
            ))
        }
    }
}

/// Non-blank lines with their 1-based numbers, without line endings (`\n` or `\r\n`).
pub(crate) fn lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.split('\n')
        .enumerate()
        .map(|(i, l)| (i + 1, l.strip_suffix('\r').unwrap_or(l)))
        .filter(|(_, l)| !l.trim().is_empty())
}

/// Refuses a file whose last record, at `last_record` (`None`: the file ends in a header or
/// comment line, or has no record), has no line break after it (trailing spaces, tabs and `\r`
/// aside). Such a file was cut off while being written, and a value cut short still parses
/// (`1.1827383` read as `1.`). `hint` ends the message (empty, or a space and a parenthesis).
/// Data files only: small hand-written files (lists, settings) often lack the final break.
pub(crate) fn check_line_break(
    content: &str,
    last_record: Option<Location>,
    hint: &str,
) -> Result<()> {
    match last_record {
        Some(at) if !ends_in_break(content) => Err(cut_off(at, hint)),
        _ => Ok(()),
    }
}

/// Whether `content` ends in a line break, trailing spaces, tabs and `\r` aside.
pub(crate) fn ends_in_break(content: &str) -> bool {
    content.trim_end_matches([' ', '\t', '\r']).ends_with('\n')
}

/// The error of [`check_line_break`] for the record at `at`.
pub(crate) fn cut_off(at: Location, hint: &str) -> DataError {
    DataError::format(
        at,
        format!(
            "the file ends inside this record, without a line break: cut off while being \
             written?{hint}"
        ),
    )
}

/// Cells of a line separated by the ASCII byte `sep`, like `str::split` but with a plain byte
/// loop: cells are short, and `str::split`'s `memchr` set-up cost dominates on them.
pub(crate) fn cells(line: &str, sep: u8) -> Cells<'_> {
    Cells {
        rest: Some(line),
        sep,
    }
}

/// Iterator of [`cells`].
pub(crate) struct Cells<'a> {
    rest: Option<&'a str>,
    sep: u8,
}

impl<'a> Iterator for Cells<'a> {
    type Item = &'a str;

    fn next(&mut self) -> Option<&'a str> {
        let s = self.rest?;
        match s.bytes().position(|b| b == self.sep) {
            // `sep` is ASCII, so both slices fall on character boundaries.
            Some(i) => {
                self.rest = Some(&s[i + 1..]);
                Some(&s[..i])
            }
            None => {
                self.rest = None;
                Some(s)
            }
        }
    }
}

/// At most 40 characters of `s`, for error messages about cells that may be arbitrarily long.
pub(crate) fn snippet(s: &str) -> String {
    match s.char_indices().nth(40) {
        Some((end, _)) => format!("{}...", &s[..end]),
        None => s.to_owned(),
    }
}

/// Whether NaN is an accepted cell value (infinities never are).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Nan {
    Reject,
    Accept,
}

/// Parses one numeric cell. `field` is only turned into an owned name when there is an error,
/// so the hot path allocates nothing.
pub(crate) fn number(cell: &str, path: &Path, line: usize, field: &str, nan: Nan) -> Result<f64> {
    let s = cell.trim_ascii();
    let fail = |message: String| {
        Err(DataError::format(
            Location::line(path, line).with_field(field),
            message,
        ))
    };
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) if v.is_nan() && nan == Nan::Accept => Ok(v),
        Ok(_) => fail(format!("`{}` is not a finite number", snippet(s))),
        Err(_) if s.is_empty() => fail("empty cell where a number is expected".to_owned()),
        Err(_) => fail(format!("`{}` is not a number", snippet(s))),
    }
}

/// Parses a non-negative integer cell (row and column counts).
pub(crate) fn count(cell: &str, path: &Path, line: usize, field: &str) -> Result<usize> {
    let s = cell.trim();
    s.parse::<usize>().map_err(|e| {
        let message = match e.kind() {
            std::num::IntErrorKind::PosOverflow => {
                format!(
                    "`{}` is too large: a count is at most {}",
                    snippet(s),
                    usize::MAX
                )
            }
            _ => format!("`{}` is not a non-negative integer", snippet(s)),
        };
        DataError::format(Location::line(path, line).with_field(field), message)
    })
}

/// Checks that `time` (seconds, one entry per line of `lines`) strictly increases without
/// gaps longer than `max_gap_s`, naming the offending line. The file is of a
/// [`Format::keeps_gaps`](crate::Format::keeps_gaps) format: a gap's error says that `ridi
/// convert --split-at-gaps` cuts it.
pub(crate) fn check_time(
    time: &[f64],
    lines: &[usize],
    path: &Path,
    field: &str,
    max_gap_s: f64,
) -> Result<()> {
    for (i, w) in time.windows(2).enumerate() {
        let line = lines.get(i + 1).copied().unwrap_or(0);
        let prev_line = lines.get(i).copied().unwrap_or(0);
        check_step(
            (w[0], prev_line),
            (w[1], line),
            path,
            field,
            (max_gap_s, true),
        )?;
    }
    Ok(())
}

/// [`check_time`] of one step: from `prev` to `next` (each a time in seconds and its line),
/// the gap's error naming `ridi convert --split-at-gaps` if `splittable` (not for a RIDI raw
/// folder, whose pauses it cannot cut).
pub(crate) fn check_step(
    (prev, prev_line): (f64, usize),
    (next, line): (f64, usize),
    path: &Path,
    field: &str,
    (max_gap_s, splittable): (f64, bool),
) -> Result<()> {
    let at = || Location::line(path, line).with_field(field);
    if next == prev {
        return Err(DataError::format(
            at(),
            format!("duplicate timestamp (same as line {prev_line})"),
        ));
    }
    if next < prev {
        return Err(DataError::format(
            at(),
            format!(
                "timestamp goes back by {:.9} s from line {prev_line}",
                prev - next
            ),
        ));
    }
    if next - prev > max_gap_s {
        return Err(DataError::format(
            at(),
            format!(
                "gap of {:.3} s since line {prev_line} exceeds the limit of {} s: a recording \
                 paused that long is two; cut it there (the records before this line and those \
                 from it on, as recordings of their own{})",
                next - prev,
                short(max_gap_s),
                if splittable {
                    ": `ridi convert --split-at-gaps 0.1` does; in Python \
                     `ridi.read_any(path, split_at_gaps=0.1)`"
                } else {
                    ""
                }
            ),
        ));
    }
    Ok(())
}

/// How a file names the channels of a sequence, for the errors of [`sequence_error`].
pub(crate) trait Fields {
    /// The file's name of `axis` (0..3) of `channel`, or of the whole channel (`None`).
    fn field(&self, channel: Channel, axis: Option<usize>) -> String;
    /// The unit of the file's timestamps (`nanoseconds`), for the hint of a wrong time step.
    fn time_unit(&self) -> &str;
}

/// The name of `axis` among `axes`, or `first..last` for the whole channel (`None`).
pub(crate) fn axis_field(axes: [&str; 3], axis: Option<usize>) -> String {
    match axis {
        Some(a) => axes.get(a).copied().unwrap_or("?").to_owned(),
        None => format!("{}..{}", axes[0], axes[2]),
    }
}

/// The name of a channel in a [`Sequence`](crate::Sequence) (`gravity`, `gravity.x`): for the
/// channels a reader derives rather than reads.
pub(crate) fn sequence_field(channel: Channel, axis: Option<usize>) -> String {
    match axis {
        Some(a) => format!("{channel}.{}", axis_name(a)),
        None => channel.name().to_owned(),
    }
}

/// Turns a validation failure into an error naming the file, the field (`fields` says how the
/// file names it) and, when the failure is about one frame and `lines` maps frames to lines,
/// that line. Whole-channel failures (units, time step) name the file and the field.
pub(crate) fn sequence_error(
    path: &Path,
    lines: Option<&[usize]>,
    fields: &dyn Fields,
    e: SequenceError,
) -> DataError {
    sequence_error_at(path, |i| lines.and_then(|l| l.get(i)).copied(), fields, e)
}

/// [`sequence_error`] with the line of frame `i` as `line_of(i)` says (`None`: unknown).
pub(crate) fn sequence_error_at(
    path: &Path,
    line_of: impl Fn(usize) -> Option<usize>,
    fields: &dyn Fields,
    e: SequenceError,
) -> DataError {
    let whole = |channel, message: String| {
        let at = Location::file(path).with_field(fields.field(channel, None));
        DataError::format(at, message)
    };
    let (index, field, message) = match &e {
        SequenceError::NonFinite { index, what } => (*index, (*what).to_owned(), e.to_string()),
        SequenceError::TimeNotIncreasing { index, .. } | SequenceError::Gap { index, .. } => {
            (*index, "time".to_owned(), e.to_string())
        }
        &SequenceError::Implausible {
            channel,
            axis,
            index,
            value,
            limit,
        } => (
            index,
            fields.field(channel, Some(axis)),
            beyond(channel, value, limit),
        ),
        &SequenceError::GroundTruthJump {
            index,
            axis,
            distance,
            dt,
            max,
        } => (
            index,
            fields.field(Channel::Position, Some(axis)),
            jump(distance, dt, max),
        ),
        SequenceError::GyroUnits { .. }
        | SequenceError::GyroScale { .. }
        | SequenceError::GyroDirection { .. } => {
            return whole(Channel::Gyro, e.to_string());
        }
        &SequenceError::GyroAxis { axis, .. } => {
            let at = Location::file(path).with_field(fields.field(Channel::Gyro, Some(axis)));
            return DataError::format(at, e.to_string());
        }
        SequenceError::AcceScale { .. } => return whole(Channel::Acce, e.to_string()),
        SequenceError::LinacceScale { .. } => return whole(Channel::Linacce, e.to_string()),
        SequenceError::GroundTruthSpeed { .. } => return whole(Channel::Position, e.to_string()),
        &SequenceError::TimeStep { median, min, max } => {
            let unit = fields.time_unit();
            let message = crate::sequence_error::time_step_message(median, (min, max), unit);
            return whole(
                Channel::Time,
                format!("{message} (this format expects {unit})"),
            );
        }
        _ => return DataError::sequence(path, e),
    };
    match line_of(index) {
        Some(line) => DataError::format(Location::line(path, line).with_field(field), message),
        None if matches!(
            e,
            SequenceError::Implausible { .. } | SequenceError::GroundTruthJump { .. }
        ) =>
        {
            DataError::format(
                Location::file(path).with_field(field),
                format!("frame {index}: {message}"),
            )
        }
        None => DataError::sequence(path, e),
    }
}

/// Checks one stream a reader parsed from `path`, before any resampling: the median step of
/// `time` (empty: not checked), then, for a `channel`, every 3-vector of `values` against the
/// channel's limits. Errors name the file and the field, and the line of a single bad value.
pub(crate) fn check_stream<I>(
    limits: &Validation,
    path: &Path,
    lines: &[usize],
    fields: &dyn Fields,
    time: &[f64],
    channel: Option<Channel>,
    values: I,
) -> Result<()>
where
    I: IntoIterator<Item = [f64; 3]>,
    I::IntoIter: Clone,
{
    limits
        .check_time_step(time)
        .and_then(|()| channel.map_or(Ok(()), |c| limits.check_channel(c, values)))
        .map_err(|e| sequence_error(path, Some(lines), fields, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p() -> &'static Path {
        Path::new("f.csv")
    }

    #[test]
    fn numbers_parse_and_errors_name_line_and_field() {
        assert_eq!(number(" 1.5e3 ", p(), 3, "x", Nan::Reject).unwrap(), 1500.0);
        let e = number("abc", p(), 3, "gyro_x", Nan::Reject).unwrap_err();
        assert_eq!(
            e.to_string(),
            "f.csv:3: field `gyro_x`: `abc` is not a number"
        );
        let e = number("inf", p(), 4, "t", Nan::Accept).unwrap_err();
        assert!(
            e.to_string()
                .contains(":4: field `t`: `inf` is not a finite"),
            "{e}"
        );
        assert!(number("NaN", p(), 1, "x", Nan::Reject).is_err());
        assert!(number("nan", p(), 1, "x", Nan::Accept).unwrap().is_nan());
        assert!(
            number("", p(), 1, "x", Nan::Reject)
                .unwrap_err()
                .to_string()
                .contains("empty")
        );
    }

    #[test]
    fn counts_too_large_are_named_as_such() {
        assert_eq!(count(" 27 ", p(), 1, "columns").unwrap(), 27);
        let e = count("99999999999999999999999", p(), 1, "rows").unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "f.csv:1: field `rows`: `99999999999999999999999` is too large: a count is at \
                 most {}",
                usize::MAX
            )
        );
        for bad in ["-1", "2.5", "x", ""] {
            let e = count(bad, p(), 2, "rows").unwrap_err().to_string();
            assert!(e.ends_with("is not a non-negative integer"), "{bad}: {e}");
        }
    }

    #[test]
    fn a_last_record_without_a_line_break_is_refused() {
        let at = || Some(Location::line(p(), 3).with_field("x"));
        for complete in ["a\nb\n", "a\r\nb\r\n", "a\nb\n  \t", "a\nb\n\n"] {
            check_line_break(complete, at(), "").unwrap();
        }
        for cut in ["a\nb", "a\nb \t", "a\r\nb\r"] {
            let e = check_line_break(cut, at(), " (hint)")
                .unwrap_err()
                .to_string();
            assert_eq!(
                e,
                "f.csv:3: field `x`: the file ends inside this record, without a line break: \
                 cut off while being written? (hint)",
                "{cut:?}"
            );
        }
        // No record at the end (a header, a comment, nothing): nothing to check.
        check_line_break("# header", None, "").unwrap();
    }

    #[test]
    fn cells_split_like_str_split() {
        for line in ["", "a", ",", "a,b", ",a,,b,", "é,ü,,"] {
            let ours: Vec<_> = cells(line, b',').collect();
            let std: Vec<_> = line.split(',').collect();
            assert_eq!(ours, std, "{line:?}");
        }
    }

    #[test]
    fn lines_are_numbered_and_blank_ones_skipped() {
        let v: Vec<_> = lines("a\r\n\n  \nb\n").collect();
        assert_eq!(v, vec![(1, "a"), (4, "b")]);
    }

    #[test]
    fn gzip_is_decompressed_and_corrupt_gzip_named() {
        use std::io::Write;
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        enc.write_all(b"a,b\n1,2\n").unwrap();
        let gz = enc.finish().unwrap();
        assert_eq!(gunzip_if_gzip(gz.clone(), p()).unwrap(), b"a,b\n1,2\n");
        assert_eq!(gunzip_if_gzip(b"plain".to_vec(), p()).unwrap(), b"plain");
        let cut = gz[..gz.len() - 6].to_vec();
        let e = gunzip_if_gzip(cut, p()).unwrap_err().to_string();
        assert!(e.starts_with("f.csv: corrupt or truncated gzip"), "{e}");
    }

    #[test]
    fn invalid_utf8_names_its_line() {
        let e = as_text(b"ok\nok\n\xff", p()).unwrap_err();
        assert_eq!(e.to_string(), "f.csv:3: is not UTF-8 text");
        assert_eq!(as_text("\u{feff}x".as_bytes(), p()).unwrap(), "x");
    }

    #[test]
    fn snippet_cuts_long_cells_on_char_boundaries() {
        let long = "é".repeat(100);
        assert_eq!(snippet(&long).chars().count(), 43);
        assert_eq!(snippet("short"), "short");
    }

    #[test]
    fn time_checks_name_the_later_line() {
        let lines = [2, 3, 5];
        let e = check_time(&[0.0, 0.1, 0.1], &lines, p(), "time", 1.0).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("f.csv:5: field `time`: duplicate"),
            "{e}"
        );
        let e = check_time(&[0.0, 0.1, 0.05], &lines, p(), "time", 1.0).unwrap_err();
        assert!(e.to_string().contains("goes back"), "{e}");
        let e = check_time(&[0.0, 2.0, 3.0], &lines, p(), "time", 1.0).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("f.csv:3: field `time`: gap of 2.000 s"),
            "{e}"
        );
        check_time(&[0.0, 0.5, 1.0], &lines, p(), "time", 1.0).unwrap();
    }
}
