//! Reading a RIDI recording row by row, in memory that does not grow with its length.
//!
//! [`RowReader`] reads a `data.csv` or `data_plain.txt` (either gzip-compressed) line by line
//! with the parsers of [`ridi_csv`](crate::ridi_csv) and [`ridi_plain`](crate::ridi_plain),
//! checks each row as it comes (numbers, time order and gaps, rotations, ground truth; a
//! `data.csv` without orientation columns gets the whole-file reader's estimate, its rows held
//! for the estimate's first 2 s) and
//! keeps running sums for what needs the whole recording (the median interval, the units of
//! every channel, gravity, the ground truth's speed). [`RowReader::finish`] then refuses what
//! [`Sequence::new`](crate::Sequence::new) would refuse, with the error the whole-file reader
//! gives: a recording with one fault gets the same file, line and field either way. A median
//! is judged exactly from counts; only when one is out of range is the file read again, in a
//! few passes of bounded memory, to name it.
//!
//! A RIDI raw folder streams too: a first pass over each of its files makes the checks the
//! whole-folder reader makes on that file and finds the span every sensor covers, a second
//! reads the files side by side and interpolates them onto the pose timeline
//! ([`ridi_raw`](crate::ridi_raw)'s module `stream`); the rows so made go through the same
//! checks as a processed file's. The other formats cannot stream: a Tyrex run and an Indoor
//! Location Competition path file interpolate streams whose clocks must first be aligned (and
//! a Tyrex run splits at gaps), RoNIN and MAT files are read by random access, so their
//! readers take the whole recording ([`Format::streams`]).

use std::collections::VecDeque;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

use ridi_frames::{DeviceVec, OrientationFilter, WorldFromDevice, WorldVec};

use crate::error::{DataError, Location, Result};
use crate::options::ReadOptions;
use crate::processed::{
    self, ACCE, GRAV, GYRO, LINACCE, MAGNET, ORI, POS, PROCESSED_COLUMNS, ProcessedFields, RV, TIME,
};
use crate::sequence::norm;
use crate::sequence_error::SequenceError;
use crate::{Channel, DeviceInfo, Format, OrientationSource, Validation, sidecar, text};
use crate::{ridi_csv, ridi_plain, ridi_raw};

impl Format {
    /// Whether [`RowReader`] reads this format as a stream: RIDI `data.csv`, `data_plain.txt`
    /// and raw folders. The others are read whole.
    pub fn streams(self) -> bool {
        matches!(self, Format::RidiCsv | Format::RidiPlain | Format::RidiRaw)
    }
}

/// One row of a recording read by [`RowReader`]: a frame of a
/// [`Sequence`](crate::Sequence), with the same values the whole-file reader gives it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    /// Seconds (absolute).
    pub time: f64,
    /// Angular rate, device frame, rad/s.
    pub gyro: DeviceVec,
    /// Accelerometer, device frame, m/s^2.
    pub acce: DeviceVec,
    /// Linear acceleration, device frame, m/s^2.
    pub linacce: DeviceVec,
    /// Gravity, device frame, m/s^2.
    pub gravity: DeviceVec,
    /// Magnetometer, device frame, microtesla, when the file has its columns (a recording
    /// whose magnetometer is zero on every row has none: [`RowReader::has_magnet`]).
    pub magnet: Option<DeviceVec>,
    /// World-from-device orientation (the game rotation vector).
    pub orientation: WorldFromDevice,
    /// Ground-truth position and orientation, when the recording has ground truth.
    pub ground_truth: Option<(WorldVec, WorldFromDevice)>,
    /// The step counter (steps since start), when the recording has one (a raw folder's
    /// `step.txt`).
    pub steps: Option<f64>,
}

/// Whether the median of a stream of values has a property, decided exactly from two counts
/// instead of the values: `low` for a property that holds for every value below one that has
/// it (`v < a`, `1 / v > a`), `high` for one that holds above (`v > a`). The median is the
/// middle value, the upper one of an even count, as everywhere in ridi-rs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MedianTest {
    values: usize,
    low: usize,
    high: usize,
}

impl MedianTest {
    /// Counts one value: whether it has the `low` and the `high` property.
    pub fn push(&mut self, low: bool, high: bool) {
        self.values += 1;
        self.low += usize::from(low);
        self.high += usize::from(high);
    }

    /// Uncounts one value counted before with these properties (for a sliding window of
    /// values).
    ///
    /// Uncounting what was not counted leaves the counts at 0 (no caller that pushed it first
    /// does; release builds do not check overflow, so this does).
    pub fn pop(&mut self, low: bool, high: bool) {
        self.values = self.values.saturating_sub(1);
        self.low = self.low.saturating_sub(usize::from(low));
        self.high = self.high.saturating_sub(usize::from(high));
    }

    /// Values counted.
    pub fn len(&self) -> usize {
        self.values
    }

    /// Whether no value was counted.
    pub fn is_empty(&self) -> bool {
        self.values == 0
    }

    /// Whether the median has the `low` property (`false` without values).
    pub fn median_low(&self) -> bool {
        // The values with it are the first ones in sorted order: the median at index n / 2
        // has it when more than n / 2 of them do.
        self.values > 0 && self.low > self.values / 2
    }

    /// Whether the median has the `high` property (`false` without values).
    pub fn median_high(&self) -> bool {
        self.values > 0 && self.high >= self.values - self.values / 2
    }
}

/// A quantity of consecutive rows whose median [`RowReader`] may have to name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Quantity {
    /// The interval from the previous row, seconds.
    Interval,
    /// |gyro|, rad/s.
    GyroNorm,
    /// The ground truth's speed from the previous row, m/s.
    Speed,
    /// The angle between gravity and the orientation's up axis, degrees.
    UpAngle,
}

impl Quantity {
    fn of(self, previous: Option<&Row>, row: &Row) -> Option<f64> {
        match self {
            Quantity::GyroNorm => Some(norm(row.gyro.to_array())),
            Quantity::UpAngle => crate::validation::up_angle_deg(row.orientation, row.gravity),
            Quantity::Interval => previous.map(|p| row.time - p.time),
            Quantity::Speed => {
                let (p, r) = (previous?.ground_truth?.0, row.ground_truth?.0);
                Some(Validation::step_speed(r - p, row.time - previous?.time))
            }
        }
    }
}

/// The `k`-th smallest (from 0) of the values `pass` hands out, which must be the same in
/// every call, non-negative and not NaN: a radix selection on their bits, 16 at a time, in at
/// most four passes of 512 KiB.
pub(crate) fn select(
    k: usize,
    mut pass: impl FnMut(&mut dyn FnMut(f64)) -> Result<()>,
) -> Result<f64> {
    let (mut prefix, mut k) = (0u64, k);
    for level in 0..4u32 {
        let shift = 48 - 16 * level;
        let known = if level == 0 { 0 } else { !0u64 << (shift + 16) };
        let mut counts = vec![0usize; 1 << 16];
        pass(&mut |v: f64| {
            let bits = v.to_bits();
            if bits & known == prefix {
                counts[((bits >> shift) & 0xffff) as usize] += 1;
            }
        })?;
        let mut digit = 0xffff;
        for (d, &c) in counts.iter().enumerate() {
            if k < c {
                digit = d;
                break;
            }
            k -= c;
        }
        prefix |= (digit as u64) << shift;
    }
    Ok(f64::from_bits(prefix))
}

/// A byte source with its decompressed size bounded as [`text::gunzip_if_gzip`] bounds it.
struct Bounded<R> {
    inner: R,
    read: u64,
    limit: u64,
}

/// The error [`Bounded`] stops with.
#[derive(Debug)]
struct TooLarge;

impl std::fmt::Display for TooLarge {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("decompressed size limit")
    }
}

impl std::error::Error for TooLarge {}

impl<R: Read> Read for Bounded<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.read += n as u64;
        if self.read > self.limit {
            return Err(std::io::Error::other(TooLarge));
        }
        Ok(n)
    }
}

/// The non-blank lines of a file, numbered as [`text::lines`] numbers them.
pub(crate) struct Lines {
    input: Box<dyn BufRead>,
    path: PathBuf,
    /// `(limit, compressed size)` of a gzip file.
    gzip: Option<(u64, u64)>,
    buf: Vec<u8>,
    /// Number of the last line read.
    line: usize,
    /// Whether the file so far ends in a line break (trailing spaces, tabs and `\r` aside).
    pub(crate) ends_in_break: bool,
}

impl Lines {
    /// Opens the file at `path`, gzip-compressed or not.
    pub(crate) fn open(path: &Path) -> Result<Self> {
        let meta = text::regular_file(path)?;
        let file = std::fs::File::open(path).map_err(|e| DataError::io(path, e))?;
        let mut raw = BufReader::with_capacity(1 << 16, file);
        let head = raw.fill_buf().map_err(|e| DataError::io(path, e))?;
        let (input, gzip): (Box<dyn BufRead>, _) = if head.starts_with(&[0x1f, 0x8b]) {
            let limit = text::gzip_limit(meta.len());
            let decoder = flate2::bufread::MultiGzDecoder::new(raw);
            let bounded = Bounded {
                inner: decoder,
                read: 0,
                limit,
            };
            (
                Box::new(BufReader::with_capacity(1 << 16, bounded)),
                Some((limit, meta.len())),
            )
        } else {
            (Box::new(raw), None)
        };
        Ok(Self {
            input,
            path: path.to_path_buf(),
            gzip,
            buf: Vec::new(),
            line: 0,
            ends_in_break: false,
        })
    }

    fn read_error(&self, e: std::io::Error) -> DataError {
        match self.gzip {
            Some((limit, compressed)) => {
                if e.get_ref().is_some_and(|inner| inner.is::<TooLarge>()) {
                    text::gzip_too_large(&self.path, limit, compressed)
                } else {
                    DataError::format(
                        Location::file(&self.path),
                        format!(
                            "corrupt or truncated gzip data, or other bytes after its end: {e}"
                        ),
                    )
                }
            }
            None => DataError::io(&self.path, e),
        }
    }

    /// The next non-blank line and its number, without its line ending.
    pub(crate) fn next(&mut self) -> Result<Option<(usize, &str)>> {
        match self.next_text()? {
            Some((line, text)) => Ok(Some((line, text?))),
            None => Ok(None),
        }
    }

    /// [`Self::next`], with a line that is not UTF-8 text as an error of its own (the inner
    /// one), after which the lines can be read on; the outer error is a failed read.
    pub(crate) fn next_text(&mut self) -> Result<Option<(usize, Result<&str>)>> {
        let (start, end) = loop {
            self.buf.clear();
            let n = match self.input.read_until(b'\n', &mut self.buf) {
                Ok(n) => n,
                Err(e) => return Err(self.read_error(e)),
            };
            if n == 0 {
                return Ok(None);
            }
            self.line += 1;
            let mut end = self.buf.len();
            if self.buf.ends_with(b"\n") {
                self.ends_in_break = true;
                end -= 1;
            } else {
                self.ends_in_break &= self.buf.iter().all(|b| b" \t\r".contains(b));
            }
            if self.buf[..end].ends_with(b"\r") {
                end -= 1;
            }
            let Ok(text) = std::str::from_utf8(&self.buf[..end]) else {
                return Ok(Some((
                    self.line,
                    Err(DataError::format(
                        Location::line(&self.path, self.line),
                        "is not UTF-8 text",
                    )),
                )));
            };
            let start = if self.line == 1 && text.starts_with('\u{feff}') {
                '\u{feff}'.len_utf8()
            } else {
                0
            };
            if !text[start..].trim().is_empty() {
                break (start, end);
            }
        };
        // Valid UTF-8 from `start`, a character boundary: checked above.
        let text = std::str::from_utf8(&self.buf[start..end]).unwrap_or_default();
        Ok(Some((self.line, Ok(text))))
    }
}

/// The layout's header: which parser reads the rows.
enum Header {
    Csv(ridi_csv::Header),
    Plain(ridi_plain::Header),
}

impl Header {
    /// A `data.csv`'s header, which says which column groups the file has (a
    /// `data_plain.txt` has every column).
    fn csv(&self) -> Option<&ridi_csv::Header> {
        match self {
            Header::Csv(h) => Some(h),
            Header::Plain(_) => None,
        }
    }
}

/// The ground truth's state while streaming: all NaN means none, and then on every row.
#[derive(Debug, Clone, Copy, Default)]
struct GroundTruthState {
    /// The first row with a NaN in it, and its line.
    first_nan: Option<([f64; 27], usize)>,
    /// Whether a row had ground truth.
    given: bool,
}

/// A processed file read line by line.
struct Processed {
    lines: Lines,
    header: Header,
    ground_truth: GroundTruthState,
    /// Time and line of the previous row parsed.
    last: Option<(f64, usize)>,
    /// The orientation being estimated, for a `data.csv` without orientation columns.
    estimating: Option<Box<Estimating>>,
}

/// The orientation of a file without orientation columns, estimated as its rows come: the
/// whole-file reader's estimate ([`SequenceParts::estimate_orientation`](crate::SequenceParts::estimate_orientation)), which
/// [`OrientationFilter`] gives one sample at a time once it has the first seconds' tilt. Rows
/// wait here until their orientation is known (2 s with the default filter;
/// [`processed::MAX_ESTIMATE_WAIT`] at most).
struct Estimating {
    filter: OrientationFilter,
    /// Rows parsed, with their lines, waiting for the orientations in `known` (the first
    /// `known.len()` of them have one).
    held: VecDeque<(Row, usize)>,
    known: VecDeque<WorldFromDevice>,
    /// The filter's output, reused.
    out: Vec<WorldFromDevice>,
    /// The file's rows are all parsed and the filter finished.
    finished: bool,
}

/// Where the rows come from (each boxed: a raw folder's readers take a few kilobytes).
enum Source {
    Processed(Box<Processed>),
    /// A raw folder, its files merged onto one timeline.
    Raw(Box<ridi_raw::stream::Rows>),
}

impl Source {
    /// A validation failure of the recording read from `path`, naming the file and the
    /// field; when it is about frame `index` of the pair `at`, on that frame's line (if it has
    /// one).
    fn error(
        &self,
        path: &Path,
        e: SequenceError,
        at: Option<(usize, Option<usize>)>,
    ) -> DataError {
        let line_of = |i: usize| at.and_then(|(index, line)| line.filter(|_| i == index));
        match self {
            Source::Processed(_) => text::sequence_error_at(path, line_of, &ProcessedFields, e),
            Source::Raw(raw) => raw.error(e, line_of),
        }
    }
}

/// The first error of each kind [`Sequence::new`](crate::Sequence::new) checks one frame at a
/// time, kept until the end so that the whole-recording checks it makes first come first.
#[derive(Debug, Default)]
struct Deferred {
    gyro: Option<DataError>,
    acce: Option<DataError>,
    linacce: Option<DataError>,
    gravity: Option<DataError>,
    magnet: Option<DataError>,
    position: Option<DataError>,
    /// A step count that is not finite (a raw folder's, interpolated; the other channels are
    /// parsed finite, or interpolated between values their files' checks bound).
    steps: Option<DataError>,
}

/// What [`RowReader::finish`] needs of the whole recording, summed as the rows come.
#[derive(Debug, Default)]
struct Sums {
    rows: usize,
    /// Interval below and above [`Validation::time_step_range`].
    interval: MedianTest,
    /// |gyro| above [`Validation::max_median_gyro`].
    gyro: MedianTest,
    /// Ground-truth speed above [`Validation::max_median_speed`].
    speed: MedianTest,
    /// Angle of gravity from the orientation's up axis above
    /// [`Validation::max_orientation_gravity_deg`].
    up: MedianTest,
    /// The first too fast ground-truth step: its index, vector and interval; and whether a
    /// later step (from frame 2 on) is too fast.
    jump: Option<(usize, [f64; 3], f64)>,
    later_jump: bool,
    /// Lines of frame 0 and of the first too fast step, when rows have lines.
    first_line: Option<usize>,
    jump_line: Option<usize>,
    gravity_norms: f64,
    acce_norms: f64,
    /// Gyro scale sums of every step and of the steps that are no orientation jump.
    gyro_steps: crate::validation::GyroSteps,
    /// Linear acceleration scale sums.
    linacce: (f64, f64, f64, usize),
    magnet_seen: bool,
}

/// Reads a RIDI `data.csv` or `data_plain.txt` (either gzip-compressed), or a RIDI raw
/// folder, row by row, in memory that does not grow with its length: iterate it for the rows,
/// then [`finish`](Self::finish) it for the checks that need the whole recording.
///
/// Each row of a processed file is parsed by the whole-file readers' parsers and checked as it
/// comes (numbers, time order and gaps, rotations, ground truth). A raw folder is read twice:
/// [`open`](Self::open) reads each file once for the checks the whole-folder reader makes on
/// it (numbers, time order and gaps, its median time step and values, rotations) and for the
/// span every sensor covers, then the rows are made by reading the files side by side and
/// interpolating them onto the pose timeline, with the whole reader's arithmetic. What needs
/// the whole recording (the median interval, the units of every channel, gravity, the ground
/// truth's speed) is summed as the rows come and judged by `finish`, which refuses what
/// [`Sequence::new`](crate::Sequence::new) would refuse: a recording with one fault gets the
/// error the whole-file reader gives (file, line, field, message). A median is judged exactly
/// from counts ([`MedianTest`]); only one out of range is named after reading the file (or
/// folder) again, in a few passes of bounded memory. Formats whose streams must be aligned
/// before they can be interpolated, or that are read by random access, do not stream
/// ([`Format::streams`]).
///
/// After an error the iteration ends. A row refused by a check of the whole recording's
/// channels (a value beyond its channel's bound) is still handed out, so that the checks can
/// go on; [`refused`](Self::refused) says when the recording will be refused.
///
/// ```
/// use ridi_data::ridi_frames::{DeviceVec, WorldFromDevice};
/// use ridi_data::{ReadOptions, RowReader, Sequence, SequenceParts, write_ridi_csv};
///
/// let n = 50;
/// let seq = Sequence::new(SequenceParts {
///     name: "walk".into(),
///     time: (0..n).map(|i| (1_000_000_000 + 5_000_000 * i) as f64 / 1e9).collect(),
///     gyro: vec![DeviceVec::new(0.01, -0.02, 0.03); n],
///     // Lying flat: gravity along the device's z axis, the orientation's up.
///     acce: vec![DeviceVec::new(0.1, 0.1, 10.0); n],
///     linacce: vec![DeviceVec::new(0.1, 0.1, 0.2); n],
///     gravity: vec![DeviceVec::new(0.0, 0.0, 9.8); n],
///     orientation: vec![WorldFromDevice::identity(); n],
///     ..Default::default()
/// })?;
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("walk.csv");
/// write_ridi_csv(&seq, &path)?;
///
/// let mut rows = RowReader::open(&path, &ReadOptions::default())?;
/// let mut time = Vec::new();
/// for row in rows.by_ref() {
///     time.push(row?.time);
/// }
/// rows.finish()?;
/// assert_eq!(time, seq.time());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct RowReader {
    path: PathBuf,
    format: Format,
    opts: ReadOptions,
    name: String,
    device: Option<DeviceInfo>,
    orientation_source: Option<OrientationSource>,
    source: Source,
    /// Whether the whole-recording checks run (not while re-reading for a median).
    checked: bool,
    previous: Option<Row>,
    deferred: Deferred,
    sums: Sums,
    done: bool,
}

impl std::fmt::Debug for RowReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RowReader")
            .field("path", &self.path)
            .field("format", &self.format)
            .field("rows", &self.sums.rows)
            .finish_non_exhaustive()
    }
}

impl RowReader {
    /// Opens the recording at `path` (a file, or a folder holding one, as
    /// [`detect`](crate::detect) finds it) and reads its header and its sidecar; a raw folder
    /// is read once through (see above).
    ///
    /// # Errors
    /// A source of a format that does not stream ([`Format::streams`]), and what the
    /// whole-file reader refuses in the header, the sidecar or the file itself; for a raw
    /// folder, what the whole-folder reader refuses before it synchronizes the files.
    pub fn open(path: impl AsRef<Path>, opts: &ReadOptions) -> Result<Self> {
        Self::open_checked(path.as_ref(), opts, true)
    }

    fn open_checked(path: &Path, opts: &ReadOptions, checked: bool) -> Result<Self> {
        let (format, file) = crate::detect::locate(path)?;
        if !format.streams() {
            return Err(DataError::format(
                Location::file(path),
                format!(
                    "{format} cannot be read as a stream of rows (only a RIDI data.csv, \
                     data_plain.txt or raw folder can)"
                ),
            ));
        }
        let (name, device, orientation_source, source) = if format == Format::RidiRaw {
            let raw = ridi_raw::stream::Rows::open(&file, opts)?;
            let name = raw.name();
            let source = Some(OrientationSource::GameRotationVector);
            (name, None, source, Source::Raw(Box::new(raw)))
        } else {
            let (processed, side) = Self::open_processed(format, &file)?;
            let source = match processed.estimating {
                Some(_) => Some(OrientationSource::Estimated),
                None => side
                    .orientation_source
                    .or(Some(OrientationSource::GameRotationVector)),
            };
            let name = processed::name_from_path(&file);
            (
                name,
                side.device,
                source,
                Source::Processed(Box::new(processed)),
            )
        };
        Ok(Self {
            name,
            path: file,
            format,
            opts: opts.clone(),
            device,
            orientation_source,
            source,
            checked,
            previous: None,
            deferred: Deferred::default(),
            sums: Sums::default(),
            done: false,
        })
    }

    /// The processed `file` of `format`, its header read, and its sidecar.
    fn open_processed(format: Format, file: &Path) -> Result<(Processed, sidecar::Sidecar)> {
        let mut lines = Lines::open(file)?;
        let header = match (format, lines.next()?) {
            (Format::RidiPlain, Some((line, content))) => {
                Header::Plain(ridi_plain::parse_header(line, content, file)?)
            }
            (Format::RidiPlain, None) => return Err(ridi_plain::empty_file(file)),
            (_, Some((line, content))) => Header::Csv(ridi_csv::parse_header(line, content, file)?),
            (_, None) => return Err(ridi_csv::empty_file(file)),
        };
        let side = sidecar::read(file)?;
        let estimating = match header.csv() {
            Some(h) if !h.has_orientation => {
                side.check_estimated(file)?;
                Some(Box::new(Estimating {
                    filter: processed::estimate_filter(),
                    held: VecDeque::new(),
                    known: VecDeque::new(),
                    out: Vec::new(),
                    finished: false,
                }))
            }
            _ => None,
        };
        let processed = Processed {
            lines,
            header,
            ground_truth: GroundTruthState::default(),
            last: None,
            estimating,
        };
        Ok((processed, side))
    }

    /// The options the rows are read with.
    pub fn options(&self) -> &ReadOptions {
        &self.opts
    }

    /// The file read (a folder's `processed/data.csv`, say), or the raw folder.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The format: [`Format::RidiCsv`], [`Format::RidiPlain`] or [`Format::RidiRaw`].
    pub fn format(&self) -> Format {
        self.format
    }

    /// The sequence's name, as the whole-file reader names it.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The phone, when the sidecar names it.
    pub fn device(&self) -> Option<&DeviceInfo> {
        self.device.as_ref()
    }

    /// Where the orientation comes from: the sidecar's, else RIDI's game rotation vector; the
    /// estimate for a `data.csv` without orientation columns.
    pub fn orientation_source(&self) -> Option<OrientationSource> {
        self.orientation_source
    }

    /// Rows read so far.
    pub fn rows(&self) -> usize {
        self.sums.rows
    }

    /// Whether a magnetometer was recorded: in a processed file, a row so far had a
    /// magnetometer reading other than zero (all zeros mean none); in a raw folder,
    /// `magnet.txt` has records.
    pub fn has_magnet(&self) -> bool {
        match &self.source {
            Source::Processed(_) => self.sums.magnet_seen,
            Source::Raw(raw) => raw.has_magnet(),
        }
    }

    /// Whether a step counter was recorded (a raw folder's `step.txt` has records): the rows
    /// then have [`Row::steps`].
    pub fn has_steps(&self) -> bool {
        match &self.source {
            Source::Processed(_) => false,
            Source::Raw(raw) => raw.has_steps(),
        }
    }

    /// Whether a row so far refused a check that [`finish`](Self::finish) reports (a value
    /// beyond its channel's bound): the recording will be refused.
    pub fn refused(&self) -> bool {
        let d = &self.deferred;
        d.gyro.is_some()
            || d.acce.is_some()
            || d.linacce.is_some()
            || d.gravity.is_some()
            || d.position.is_some()
            || d.magnet.is_some()
            || d.steps.is_some()
    }

    /// Reads the rest of the file, then checks what needs the whole recording, in the order
    /// and with the errors of the whole-file reader.
    ///
    /// # Errors
    /// What reading the rest refuses; a file without rows, one cut off inside its last row
    /// or, for `data_plain.txt`, with fewer rows than announced; and what
    /// [`Sequence::new`](crate::Sequence::new) refuses of the whole recording.
    pub fn finish(mut self) -> Result<()> {
        for row in self.by_ref() {
            row?;
        }
        if let Source::Processed(p) = &self.source {
            p.check_end(&self.path, self.sums.rows)?;
        }
        if self.checked {
            self.check_whole()?;
        }
        Ok(())
    }

    /// The checks of [`Sequence::with_validation`](crate::Sequence::with_validation) that need
    /// every frame, in its order.
    fn check_whole(&mut self) -> Result<()> {
        if let Some(e) = self.deferred.steps.take() {
            return Err(e);
        }
        let limits = self.opts.validation.clone();
        let s = &self.sums;
        let (min, max) = limits.time_step_range;
        if s.interval.median_low() || s.interval.median_high() {
            let median = self.median(Quantity::Interval, s.interval.len())?;
            return Err(self.error(SequenceError::TimeStep { median, min, max }));
        }
        if s.gyro.median_high() {
            let median = self.median(Quantity::GyroNorm, s.gyro.len())?;
            if let Some(e) = limits.gyro_units_error(median) {
                return Err(self.error(e));
            }
        }
        let d = std::mem::take(&mut self.deferred);
        let has_magnet = self.has_magnet();
        let has_ground_truth = self.ground_truth_given();
        let first = [
            d.gyro,
            d.acce,
            d.linacce,
            d.gravity,
            d.magnet.filter(|_| has_magnet),
            d.position.filter(|_| has_ground_truth),
        ]
        .into_iter()
        .flatten()
        .next();
        if let Some(e) = first {
            return Err(e);
        }
        let s = &self.sums;
        if has_ground_truth {
            if s.speed.median_high() {
                let median = self.median(Quantity::Speed, s.speed.len())?;
                return Err(self.error(SequenceError::GroundTruthSpeed {
                    median,
                    max: limits.max_median_speed,
                }));
            }
            if let Some((later, step, dt)) = s.jump {
                let first_only = later == 1 && !s.later_jump;
                let (index, line) = if first_only {
                    (0, s.first_line)
                } else {
                    (later, s.jump_line)
                };
                let e = limits.jump(index, step, dt);
                return Err(self.error_at(e, index, line));
            }
        }
        let n = s.rows as f64;
        let mean = s.gravity_norms / n;
        let (gmin, gmax) = limits.gravity_range;
        if !(gmin..=gmax).contains(&mean) {
            return Err(self.error(SequenceError::Gravity {
                mean,
                min: gmin,
                max: gmax,
            }));
        }
        if s.up.median_high() {
            let median_deg = self.median(Quantity::UpAngle, s.up.len())?;
            return Err(self.error(SequenceError::OrientationGravity {
                median_deg,
                max_deg: limits.max_orientation_gravity_deg,
            }));
        }
        let s = &self.sums;
        let checks = limits
            .check_acce_scale(s.acce_norms / n, mean)
            .and_then(|()| limits.gyro_verdict(s.gyro_steps.fit()))
            .and_then(|()| {
                let (dl, ll, dd, k) = s.linacce;
                limits.linacce_scale_verdict(dl, ll, dd, k)
            });
        checks.map_err(|e| self.error(e))
    }

    /// Whether the recording has ground truth (a row so far had it).
    fn ground_truth_given(&self) -> bool {
        match &self.source {
            Source::Processed(p) => p.ground_truth.given,
            Source::Raw(raw) => raw.has_ground_truth(),
        }
    }

    /// A whole-recording error, naming the file and the field.
    fn error(&self, e: SequenceError) -> DataError {
        self.source.error(&self.path, e, None)
    }

    /// An error about frame `index`, on `line` when it has one.
    fn error_at(&self, e: SequenceError, index: usize, line: Option<usize>) -> DataError {
        self.source.error(&self.path, e, Some((index, line)))
    }

    /// The median of `quantity` over the `count` values of the file, read again in a few
    /// passes ([`select`]); a raw folder's through its second pass only ([`Self::again`]).
    fn median(&self, quantity: Quantity, count: usize) -> Result<f64> {
        select(count / 2, |f| {
            let mut again = self.again()?;
            let mut previous: Option<Row> = None;
            for row in again.by_ref() {
                let row = row?;
                if let Some(v) = quantity.of(previous.as_ref(), &row) {
                    f(v);
                }
                previous = Some(row);
            }
            Ok(())
        })
    }

    /// The recording read again from its first row, without the whole-recording checks: a
    /// processed file opened again, a raw folder's files opened for the rows as its first
    /// pass found them, without that pass ([`Rows::again`](ridi_raw::stream::Rows::again)).
    fn again(&self) -> Result<Self> {
        let raw = match &self.source {
            Source::Processed(_) => return Self::open_checked(&self.path, &self.opts, false),
            Source::Raw(raw) => raw.again(&self.opts)?,
        };
        Ok(Self {
            path: self.path.clone(),
            format: self.format,
            opts: self.opts.clone(),
            name: self.name.clone(),
            device: self.device.clone(),
            orientation_source: self.orientation_source,
            source: Source::Raw(Box::new(raw)),
            checked: false,
            previous: None,
            deferred: Deferred::default(),
            sums: Sums::default(),
            done: false,
        })
    }

    /// Reads and checks the next row.
    fn read_row(&mut self) -> Result<Option<Row>> {
        let next = match &mut self.source {
            Source::Processed(p) => {
                let max_gap_s = self.opts.validation.max_gap_s;
                let rows = self.sums.rows;
                p.read_row(&self.path, max_gap_s, rows)?
                    .map(|(row, line)| (row, Some(line)))
            }
            Source::Raw(raw) => raw.next_row(self.sums.rows, self.previous.as_ref())?,
        };
        let Some((row, line)) = next else {
            return Ok(None);
        };
        if self.checked {
            self.sum(&row, line);
        }
        self.sums.rows += 1;
        self.previous = Some(row);
        Ok(Some(row))
    }

    /// Adds `row`, read from `line` (when it has one), to the whole-recording checks.
    fn sum(&mut self, row: &Row, line: Option<usize>) {
        let limits = &self.opts.validation;
        let index = self.sums.rows;
        let previous = self.previous.as_ref();
        let s = &mut self.sums;
        let d = &mut self.deferred;
        if index == 0 {
            s.first_line = line;
        }
        if let Some(p) = previous {
            let dt = row.time - p.time;
            let (min, max) = limits.time_step_range;
            s.interval.push(dt < min, dt > max);
            let (time, gyro) = ([p.time, row.time], [p.gyro, row.gyro]);
            let orientation = [p.orientation, row.orientation];
            for step in crate::validation::step_rates(&time, &gyro, &orientation) {
                s.gyro_steps.add(&step);
            }
            if let (Some((pp, _)), Some((rp, _))) = (p.ground_truth, row.ground_truth) {
                let speed = Validation::step_speed(rp - pp, dt);
                s.speed.push(false, speed > limits.max_median_speed);
                if limits.too_fast(speed) {
                    match s.jump {
                        None => {
                            s.jump = Some((index, (rp - pp).to_array(), dt));
                            s.jump_line = line;
                        }
                        Some(_) => s.later_jump |= index >= 2,
                    }
                }
            }
        }
        let gyro = row.gyro.to_array();
        s.gyro.push(false, norm(gyro) > limits.max_median_gyro);
        let (source, path) = (&self.source, &self.path);
        let at = Some((index, line));
        let first = |slot: &mut Option<DataError>, channel: Channel, v: [f64; 3]| {
            if slot.is_none()
                && let Err(e) = limits.check_value(channel, index, v)
            {
                *slot = Some(source.error(path, e, at));
            }
        };
        first(&mut d.gyro, Channel::Gyro, gyro);
        first(&mut d.acce, Channel::Acce, row.acce.to_array());
        first(&mut d.linacce, Channel::Linacce, row.linacce.to_array());
        first(&mut d.gravity, Channel::Gravity, row.gravity.to_array());
        if let Some(m) = row.magnet {
            first(&mut d.magnet, Channel::Magnet, m.to_array());
            s.magnet_seen |= m != DeviceVec::ZERO;
        }
        if let Some((p, _)) = row.ground_truth {
            first(&mut d.position, Channel::Position, p.to_array());
        }
        if let Some(steps) = row.steps
            && !steps.is_finite()
            && d.steps.is_none()
        {
            let e = SequenceError::NonFinite {
                what: "steps",
                index,
            };
            d.steps = Some(source.error(path, e, at));
        }
        s.gravity_norms += norm(row.gravity.to_array());
        if let Some(angle) = crate::validation::up_angle_deg(row.orientation, row.gravity) {
            s.up.push(false, angle > limits.max_orientation_gravity_deg);
        }
        s.acce_norms += norm(row.acce.to_array());
        let (a, g, l) = (
            row.acce.to_array(),
            row.gravity.to_array(),
            row.linacce.to_array(),
        );
        let (dl, ll, dd, n) = &mut s.linacce;
        for k in 0..3 {
            let diff = a[k] - g[k];
            *dl += diff * l[k];
            *ll += l[k] * l[k];
            *dd += diff * diff;
        }
        *n += 1;
    }
}

impl Processed {
    /// The next row of the file at `path`, the `rows`-th, with its line: parsed and checked,
    /// with its orientation estimated when the file has none.
    fn read_row(
        &mut self,
        path: &Path,
        max_gap_s: f64,
        rows: usize,
    ) -> Result<Option<(Row, usize)>> {
        let Some(mut e) = self.estimating.take() else {
            return self.parse_row(path, max_gap_s, rows);
        };
        // Put back also after an error, so that the reader's state stays whole.
        let next = self.next_estimated(&mut e, path, max_gap_s, rows);
        self.estimating = Some(e);
        next
    }

    /// [`Self::read_row`] of a file without orientation columns: rows parsed and pushed
    /// through the filter until the next one's orientation is known.
    fn next_estimated(
        &mut self,
        e: &mut Estimating,
        path: &Path,
        max_gap_s: f64,
        rows: usize,
    ) -> Result<Option<(Row, usize)>> {
        loop {
            if let Some(q) = e.known.pop_front() {
                let (mut row, line) = e.held.pop_front().expect("a held row per orientation");
                (row.gravity, row.linacce) = ridi_frames::gravity_and_linacce(q, row.acce);
                row.orientation = q;
                return Ok(Some((row, line)));
            }
            if e.finished {
                return Ok(None);
            }
            match self.parse_row(path, max_gap_s, rows + e.held.len())? {
                Some((row, line)) => {
                    // Nothing has left `held` before the filter starts.
                    let first = e.held.front().map_or(row.time, |(r, _)| r.time);
                    if processed::estimate_waited_too_long(&e.filter, e.held.len(), first, row.time)
                    {
                        return Err(processed::estimate_wait_error(path, line));
                    }
                    e.filter
                        .push(row.time, row.gyro, row.acce, &mut e.out)
                        .map_err(|error| processed::estimate_error(path, error))?;
                    e.held.push_back((row, line));
                }
                None => {
                    e.filter
                        .finish(&mut e.out)
                        .map_err(|error| processed::estimate_error(path, error))?;
                    e.finished = true;
                }
            }
            e.known.extend(e.out.drain(..));
        }
    }

    /// Parses and checks the next line of the file at `path`, the `rows`-th row; with its
    /// line. Without orientation columns, the row's orientation, gravity and linear
    /// acceleration are placeholders ([`Self::read_row`] estimates them).
    fn parse_row(
        &mut self,
        path: &Path,
        max_gap_s: f64,
        rows: usize,
    ) -> Result<Option<(Row, usize)>> {
        let Some((line, content)) = self.lines.next()? else {
            return Ok(None);
        };
        let r = match &self.header {
            Header::Csv(h) => h.parse_row(line, content, path)?,
            Header::Plain(h) => {
                if rows == h.rows {
                    return Err(h.too_many(path, line));
                }
                h.parse_row(line, content, path)?
            }
        };
        let time = r[TIME] / 1e9;
        if let Some(previous) = self.last {
            text::check_step(
                previous,
                (time, line),
                path,
                PROCESSED_COLUMNS[TIME],
                (max_gap_s, true),
            )?;
        }
        let has_orientation = self.header.csv().is_none_or(|h| h.has_orientation);
        let orientation = match has_orientation {
            true => processed::rotation_at(&r, RV, path, line)?,
            false => WorldFromDevice::identity(),
        };
        let has_ground_truth = self.header.csv().is_none_or(|h| h.has_ground_truth);
        let mut ground_truth = None;
        if has_ground_truth {
            let gt = processed::gt(&r);
            let state = &mut self.ground_truth;
            let any_nan = gt.iter().any(|v| v.is_nan());
            if any_nan && state.first_nan.is_none() {
                state.first_nan = Some((r, line));
            }
            state.given |= !gt.iter().all(|v| v.is_nan());
            if state.given
                && let Some((first, at)) = &state.first_nan
                && let Some(e) = processed::ground_truth_nan(first, path, *at)
            {
                return Err(e);
            }
            if !any_nan {
                let position = WorldVec::new(r[POS], r[POS + 1], r[POS + 2]);
                ground_truth = Some((position, processed::rotation_at(&r, ORI, path, line)?));
            }
        }
        let has_magnet = self.header.csv().is_none_or(|h| h.has_magnet);
        let v = |at: usize| DeviceVec::new(r[at], r[at + 1], r[at + 2]);
        let row = Row {
            time,
            gyro: v(GYRO),
            acce: v(ACCE),
            linacce: v(LINACCE),
            gravity: v(GRAV),
            magnet: has_magnet.then(|| v(MAGNET)),
            orientation,
            ground_truth,
            steps: None,
        };
        self.last = Some((time, line));
        Ok(Some((row, line)))
    }

    /// What the end of the file at `path`, after `rows` rows, refuses: no rows, fewer than a
    /// `data_plain.txt` announces, or a last row without a line break.
    fn check_end(&self, path: &Path, rows: usize) -> Result<()> {
        match &self.header {
            Header::Csv(h) if rows == 0 => return Err(ridi_csv::no_rows(path, h.line)),
            Header::Plain(h) => {
                let last = self.last.map_or(h.line, |(_, line)| line);
                if let Some(e) = h.too_few(path, rows, last) {
                    return Err(e);
                }
            }
            Header::Csv(_) => {}
        }
        match self.last {
            Some((_, line)) if !self.lines.ends_in_break => {
                Err(text::cut_off(Location::line(path, line), ""))
            }
            _ => Ok(()),
        }
    }
}

impl Iterator for RowReader {
    type Item = Result<Row>;

    fn next(&mut self) -> Option<Result<Row>> {
        if self.done {
            return None;
        }
        let row = self.read_row().transpose();
        if !matches!(row, Some(Ok(_))) {
            self.done = true;
        }
        row
    }
}

/// The median interval between the rows of the recording at `path` (seconds; NaN with fewer
/// than two rows), read as a stream in a few passes: what
/// [`Sequence::median_rate_hz`](crate::Sequence::median_rate_hz) inverts, for a recording
/// too long to hold.
///
/// # Errors
/// As [`RowReader::open`] and its rows (the checks of [`RowReader::finish`] are not made).
pub fn median_interval(path: impl AsRef<Path>, opts: &ReadOptions) -> Result<f64> {
    let mut reader = RowReader::open_checked(path.as_ref(), opts, false)?;
    let mut count = 0usize;
    let mut previous = None;
    for row in reader.by_ref() {
        let row = row?;
        if previous.is_some() {
            count += 1;
        }
        previous = Some(row);
    }
    if count == 0 {
        return Ok(f64::NAN);
    }
    reader.median(Quantity::Interval, count)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn selection_finds_every_rank() {
        let values: Vec<f64> = (0..1000)
            .map(|i| ((i * 7919) % 1000) as f64 * 0.001 + if i % 3 == 0 { 5.0 } else { 0.0 })
            .collect();
        let mut sorted = values.clone();
        sorted.sort_by(f64::total_cmp);
        for k in [0, 1, 499, 500, 998, 999] {
            let got = select(k, |f| {
                values.iter().for_each(|&v| f(v));
                Ok(())
            })
            .unwrap();
            assert_eq!(got, sorted[k], "rank {k}");
        }
    }

    #[test]
    fn median_tests_agree_with_the_median() {
        for values in [
            vec![1.0],
            vec![1.0, 3.0],
            vec![3.0, 1.0, 2.0],
            vec![5.0, 1.0, 2.0, 9.0],
        ] {
            let mut sorted = values.clone();
            sorted.sort_by(f64::total_cmp);
            let median = sorted[sorted.len() / 2];
            for a in [0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 6.0, 10.0] {
                let mut t = MedianTest::default();
                values.iter().for_each(|&v| t.push(v < a, v > a));
                assert_eq!(t.median_low(), median < a, "{values:?} < {a}");
                assert_eq!(t.median_high(), median > a, "{values:?} > {a}");
            }
        }
    }
}
