//! Plots of one sequence: 2D trajectories and regressed velocities, as SVG or PNG.
//!
//! The functions take plain data (points as `[f64; 2]` in metres, times in
//! seconds, names as `&str`) so the pipeline, `ridi track --plot` and
//! `ridi eval` can call them with whatever they hold.
//!
//! * [`plot_trajectories`]: ground truth and estimates (RIDI, RAW, PDR, …) in
//!   the horizontal plane, equal aspect ratio. The view is fitted to the
//!   ground truth plus a margin, and estimates that leave it are clipped and
//!   marked "(clipped)" in the legend: a RAW double integration that drifts
//!   hundreds of metres away must not shrink everything else to a dot.
//! * [`plot_velocity`]: regressed against true velocity in the stabilised-IMU
//!   frame, one panel per channel (S-x, S-z), with an optional strip showing
//!   the device placement over time.
//!
//! The format follows the extension of the output path (`.svg` or `.png`,
//! see [`PlotFormat`]). Text in PNG files is rendered with DejaVu Sans,
//! embedded in the binary, so no system font is needed. Files are written
//! atomically: the plot is rendered to a temporary file in the target folder
//! and renamed over the target, so a failed or interrupted plot never leaves
//! a partial file behind.
//!
//! # Example
//!
//! ```
//! use ridi::plot::{
//!     Placements, Trajectory, TrajectoryOptions, TrajectoryPlot, VelocityOptions, VelocityPlot,
//!     VelocityTrack, plot_trajectories, plot_velocity,
//! };
//!
//! let dir = tempfile::tempdir()?;
//!
//! // A 10 m square walked by the ground truth, a slightly rotated estimate,
//! // and a drifting naive double integration.
//! let truth = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0], [0.0, 0.0]];
//! let ridi = [[0.0, 0.0], [10.0, 0.4], [9.5, 10.3], [-0.4, 9.8], [0.2, 0.3]];
//! let raw = [[0.0, 0.0], [15.0, 5.0], [60.0, 40.0], [200.0, 150.0], [500.0, 420.0]];
//! let plot = TrajectoryPlot {
//!     title: "a000_1",
//!     ground_truth: Some(Trajectory { name: "ground truth", points: &truth }),
//!     estimates: &[
//!         Trajectory { name: "RIDI", points: &ridi },
//!         Trajectory { name: "RAW", points: &raw },
//!     ],
//! };
//! let view = plot_trajectories(dir.path().join("traj.svg"), &plot, &TrajectoryOptions::default())?;
//! assert_eq!(view.clipped, ["RAW"]);
//!
//! let t: Vec<f64> = (0..200).map(|i| f64::from(i) * 0.05).collect();
//! let vx: Vec<f64> = t.iter().map(|t| (1.7 * t).sin()).collect();
//! let vz: Vec<f64> = t.iter().map(|t| (1.7 * t).cos()).collect();
//! let vx_hat: Vec<f64> = vx.iter().map(|v| 0.9 * v).collect();
//! let labels: Vec<&str> = t.iter().map(|&t| if t < 5.0 { "leg" } else { "bag" }).collect();
//! let plot = VelocityPlot {
//!     title: "a000_1",
//!     regressed: VelocityTrack { name: "regressed", t: &t, x: &vx_hat, z: &vz },
//!     truth: Some(VelocityTrack { name: "ground truth", t: &t, x: &vx, z: &vz }),
//!     placements: Some(Placements { t: &t, labels: &labels }),
//! };
//! plot_velocity(dir.path().join("velocity.png"), &plot, &VelocityOptions::default())?;
//! assert!(dir.path().join("velocity.png").exists());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{FontStyle, register_font};

/// DejaVu Sans 2.37 (licence in `assets/DejaVuSans-LICENSE.txt`). Embedded
/// because plotters' bitmap backend rasterises text itself and system fonts
/// are missing on fresh machines and CI runners.
static FONT_BYTES: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// The family every text style here uses; the embedded font is registered
/// under it.
const FONT: &str = "sans-serif";

/// Smallest accepted image: below this the axis label areas leave no room
/// for the data.
const MIN_SIZE: (u32, u32) = (320, 240);

/// Largest accepted image side: a PNG is rendered in an RGB buffer of
/// `3 * width * height` bytes, so an unchecked size could exhaust memory.
const MAX_SIDE: u32 = 10_000;

/// Largest magnitude accepted on a plotted axis. Beyond it a value is corrupt
/// (1e15 m or m/s, or 30 million years of recording), and the ranges derived
/// from it could overflow to infinity, on which plotters' tick search never
/// ends.
pub const MAX_MAGNITUDE: f64 = 1e15;

/// Colour of the ground truth, drawn on top of the estimates.
const TRUTH_COLOUR: RGBColor = RGBColor(0, 0, 0);

/// Tableau 10: distinguishable, and readable for most colour-blind viewers.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Light tints for the placement strip, so its text stays readable.
const STRIP_PALETTE: [RGBColor; 8] = [
    RGBColor(174, 199, 232),
    RGBColor(255, 187, 120),
    RGBColor(152, 223, 138),
    RGBColor(255, 152, 150),
    RGBColor(197, 176, 213),
    RGBColor(196, 156, 148),
    RGBColor(247, 182, 210),
    RGBColor(219, 219, 141),
];

/// The four placements of the RIDI dataset keep the same strip colour in
/// every plot, whatever subset a sequence contains, so plots compare at a
/// glance.
const KNOWN_PLACEMENTS: [&str; 4] = ["leg", "bag", "hand", "body"];

/// Errors of the plotting functions.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlotError {
    /// The output path does not end in `.svg` or `.png`.
    #[error("cannot plot to {}: unsupported file extension, expected .svg or .png", path.display())]
    UnsupportedFormat {
        /// The rejected output path.
        path: PathBuf,
    },
    /// A trajectory plot was asked for without any trajectory.
    #[error("nothing to plot: no trajectory given")]
    NoSeries,
    /// A series has no samples.
    #[error("series \"{series}\" is empty")]
    EmptySeries {
        /// Name of the series.
        series: String,
    },
    /// A series holds a NaN or an infinity.
    #[error("series \"{series}\" has a non-finite {what} at index {index}")]
    NonFinite {
        /// Name of the series.
        series: String,
        /// Which value is non-finite: "point", "time", "S-x velocity", …
        what: &'static str,
        /// Index of the first offending sample.
        index: usize,
    },
    /// A value is finite but so large it can only be corrupt, and the ranges
    /// derived from it would overflow.
    #[error(
        "series \"{series}\": {what} of magnitude {magnitude:e} at index {index} is beyond \
         the plottable {MAX_MAGNITUDE:e}"
    )]
    OutOfRange {
        /// Name of the series.
        series: String,
        /// Which value is out of range: "point", "time", "S-x velocity", …
        what: &'static str,
        /// Index of the first offending sample.
        index: usize,
        /// Its magnitude.
        magnitude: f64,
    },
    /// The channels of a series do not have one value per time stamp.
    #[error("series \"{series}\": {what} has {found} values but there are {expected} time stamps")]
    LengthMismatch {
        /// Name of the series.
        series: String,
        /// The mismatched channel.
        what: &'static str,
        /// Number of time stamps.
        expected: usize,
        /// Number of values in the channel.
        found: usize,
    },
    /// Options out of range (image size, margins).
    #[error("invalid plot options: {0}")]
    InvalidOptions(String),
    /// Creating, writing or renaming the output file failed.
    #[error("cannot write plot {}: {source}", path.display())]
    Io {
        /// The output path.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The drawing library failed.
    #[error("cannot render plot {}: {message}", path.display())]
    Render {
        /// The output path.
        path: PathBuf,
        /// The drawing library's message.
        message: String,
    },
    /// The embedded font was rejected by the text renderer.
    #[error("the embedded plot font could not be loaded")]
    Font,
}

/// Output format of a plot, chosen by the file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlotFormat {
    /// Scalable vector graphics (`.svg`).
    Svg,
    /// Portable network graphics (`.png`).
    Png,
}

impl PlotFormat {
    /// The format for `path`, from its extension (case-insensitive).
    ///
    /// Callers can use it to reject a bad `--plot` path before running a
    /// long pipeline.
    ///
    /// # Errors
    ///
    /// [`PlotError::UnsupportedFormat`] for any extension other than `svg`
    /// or `png`, or none.
    pub fn from_path(path: impl AsRef<Path>) -> Result<Self, PlotError> {
        let path = path.as_ref();
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("svg") => Ok(Self::Svg),
            Some("png") => Ok(Self::Png),
            _ => Err(PlotError::UnsupportedFormat {
                path: path.to_path_buf(),
            }),
        }
    }

    fn suffix(self) -> &'static str {
        match self {
            Self::Svg => ".svg",
            Self::Png => ".png",
        }
    }
}

/// A named 2D trajectory, in metres, already aligned with the others.
#[derive(Debug, Clone, Copy)]
pub struct Trajectory<'a> {
    /// Legend name, e.g. "RIDI" or "RAW".
    pub name: &'a str,
    /// Positions in the horizontal plane, in metres, in time order.
    pub points: &'a [[f64; 2]],
}

/// What a trajectory plot shows.
#[derive(Debug, Clone, Copy)]
pub struct TrajectoryPlot<'a> {
    /// Title, typically the sequence name.
    pub title: &'a str,
    /// The ground truth, drawn in black on top; the view is fitted to it.
    pub ground_truth: Option<Trajectory<'a>>,
    /// Estimates (RIDI, baselines), drawn in palette order. Without ground
    /// truth the view is fitted to the first one, so put the most trusted
    /// estimate first.
    pub estimates: &'a [Trajectory<'a>],
}

/// Which trajectories the view of a trajectory plot is fitted to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ViewFit {
    /// The ground truth, or the first estimate without ground truth; other
    /// trajectories are clipped to that view.
    #[default]
    Reference,
    /// Every trajectory: nothing is clipped.
    All,
}

/// Options of [`plot_trajectories`].
#[derive(Debug, Clone, PartialEq)]
pub struct TrajectoryOptions {
    /// Image size in pixels (width, height); for SVG, the view box.
    pub size: (u32, u32),
    /// What the view is fitted to.
    pub fit: ViewFit,
    /// Margin around the fitted trajectories, as a fraction of their
    /// largest extent.
    pub margin_fraction: f64,
    /// Smallest margin, in metres; keeps a short or still trajectory from
    /// filling the whole view.
    pub min_margin_m: f64,
}

impl Default for TrajectoryOptions {
    fn default() -> Self {
        Self {
            size: (1000, 800),
            fit: ViewFit::Reference,
            margin_fraction: 0.1,
            min_margin_m: 2.0,
        }
    }
}

/// The view a trajectory plot was drawn with.
#[derive(Debug, Clone, PartialEq)]
pub struct TrajectoryView {
    /// Range of x shown, in metres.
    pub x: [f64; 2],
    /// Range of y shown, in metres.
    pub y: [f64; 2],
    /// Names of the trajectories that leave the view, in input order.
    pub clipped: Vec<String>,
}

/// A velocity time series in the stabilised-IMU frame.
#[derive(Debug, Clone, Copy)]
pub struct VelocityTrack<'a> {
    /// Legend name, e.g. "regressed".
    pub name: &'a str,
    /// Time stamps in seconds.
    pub t: &'a [f64],
    /// S-x channel, in m/s, one value per time stamp.
    pub x: &'a [f64],
    /// S-z channel, in m/s, one value per time stamp.
    pub z: &'a [f64],
}

/// Device placement over time, e.g. the classifier's output.
#[derive(Debug, Clone, Copy)]
pub struct Placements<'a> {
    /// Time stamps in seconds, increasing.
    pub t: &'a [f64],
    /// Placement at each time stamp, e.g. "leg", "bag", "hand", "body".
    /// A label holds until the next time stamp with another label.
    pub labels: &'a [&'a str],
}

/// What a velocity plot shows.
#[derive(Debug, Clone, Copy)]
pub struct VelocityPlot<'a> {
    /// Title, typically the sequence name.
    pub title: &'a str,
    /// The regressed velocity.
    pub regressed: VelocityTrack<'a>,
    /// The ground-truth velocity, drawn in black beneath the regressed one.
    pub truth: Option<VelocityTrack<'a>>,
    /// Placements, shown as a coloured strip above the panels.
    pub placements: Option<Placements<'a>>,
}

/// Options of [`plot_velocity`].
#[derive(Debug, Clone, PartialEq)]
pub struct VelocityOptions {
    /// Image size in pixels (width, height); for SVG, the view box.
    pub size: (u32, u32),
}

impl Default for VelocityOptions {
    fn default() -> Self {
        Self { size: (1200, 700) }
    }
}

/// Draws trajectories in the horizontal plane to `path` (`.svg` or `.png`).
///
/// Equal aspect ratio, axes in metres, a legend, and a circle at the start
/// and a cross at the end of each trajectory. The view is chosen by
/// [`TrajectoryOptions::fit`]; trajectories leaving it are clipped and
/// marked "(clipped)" in the legend.
///
/// # Errors
///
/// Bad extension, no trajectory, an empty trajectory, a non-finite point
/// (naming the trajectory and index), a point of a trajectory the view is
/// fitted to beyond [`MAX_MAGNITUDE`], invalid options, or a write failure.
/// Nothing is written to `path` on error.
pub fn plot_trajectories(
    path: impl AsRef<Path>,
    plot: &TrajectoryPlot<'_>,
    options: &TrajectoryOptions,
) -> Result<TrajectoryView, PlotError> {
    let path = path.as_ref();
    let format = PlotFormat::from_path(path)?;
    check_size(options.size)?;
    if !(options.margin_fraction.is_finite() && options.margin_fraction >= 0.0) {
        return Err(PlotError::InvalidOptions(format!(
            "margin_fraction must be finite and non-negative, got {}",
            options.margin_fraction
        )));
    }
    if !(options.min_margin_m.is_finite() && options.min_margin_m > 0.0) {
        return Err(PlotError::InvalidOptions(format!(
            "min_margin_m must be finite and positive, got {}",
            options.min_margin_m
        )));
    }
    let all: Vec<Trajectory<'_>> = plot
        .ground_truth
        .iter()
        .chain(plot.estimates)
        .copied()
        .collect();
    if all.is_empty() {
        return Err(PlotError::NoSeries);
    }
    for trajectory in &all {
        check_points(trajectory)?;
    }
    let fitted: &[Trajectory<'_>] = match options.fit {
        ViewFit::Reference => &all[..1],
        ViewFit::All => &all,
    };
    for trajectory in fitted {
        let magnitudes = trajectory.points.iter().map(|p| p[0].abs().max(p[1].abs()));
        check_magnitude(trajectory.name, "point", magnitudes)?;
    }
    let bounds = fitted
        .iter()
        .map(|t| Bounds::of_points(t.points))
        .reduce(Bounds::union)
        .expect("at least one trajectory was checked above");
    let margin =
        (options.margin_fraction * bounds.x.span().max(bounds.y.span())).max(options.min_margin_m);
    let figure = TrajectoryFigure {
        plot,
        bounds,
        margin,
    };
    write_figure(path, format, options.size, &figure)
}

/// Draws regressed against true velocity to `path` (`.svg` or `.png`).
///
/// Two stacked panels, S-x and S-z in m/s against time in seconds, sharing
/// the time axis; placements, when given, as a coloured strip above them
/// with the placement names.
///
/// # Errors
///
/// Bad extension, an empty track, channels whose length differs from the
/// time stamps', a non-finite value or one beyond [`MAX_MAGNITUDE`] (naming
/// the track and index), invalid options, or a write failure. Nothing is
/// written to `path` on error.
pub fn plot_velocity(
    path: impl AsRef<Path>,
    plot: &VelocityPlot<'_>,
    options: &VelocityOptions,
) -> Result<(), PlotError> {
    let path = path.as_ref();
    let format = PlotFormat::from_path(path)?;
    check_size(options.size)?;
    let tracks: Vec<VelocityTrack<'_>> = plot
        .truth
        .iter()
        .chain([&plot.regressed])
        .copied()
        .collect();
    for track in &tracks {
        check_track(track)?;
    }
    if let Some(placements) = &plot.placements {
        check_placements(placements)?;
    }
    let mut t_bounds = tracks
        .iter()
        .map(|tr| Range1::of(tr.t))
        .reduce(Range1::union)
        .expect("two tracks at most, one at least");
    if let Some(placements) = &plot.placements {
        t_bounds = t_bounds.union(Range1::of(placements.t));
    }
    let figure = VelocityFigure {
        plot,
        tracks,
        t_range: t_bounds.padded_if_flat(0.5),
    };
    write_figure(path, format, options.size, &figure)
}

fn check_size((w, h): (u32, u32)) -> Result<(), PlotError> {
    if w < MIN_SIZE.0 || h < MIN_SIZE.1 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(PlotError::InvalidOptions(format!(
            "image size {w}x{h} is outside {}x{} ..= {MAX_SIDE}x{MAX_SIDE}",
            MIN_SIZE.0, MIN_SIZE.1
        )));
    }
    Ok(())
}

fn check_points(trajectory: &Trajectory<'_>) -> Result<(), PlotError> {
    if trajectory.points.is_empty() {
        return Err(PlotError::EmptySeries {
            series: trajectory.name.to_owned(),
        });
    }
    if let Some(index) = trajectory
        .points
        .iter()
        .position(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return Err(PlotError::NonFinite {
            series: trajectory.name.to_owned(),
            what: "point",
            index,
        });
    }
    Ok(())
}

/// Checks that values are finite and within [`MAX_MAGNITUDE`].
fn check_finite(series: &str, what: &'static str, values: &[f64]) -> Result<(), PlotError> {
    if let Some(index) = values.iter().position(|v| !v.is_finite()) {
        return Err(PlotError::NonFinite {
            series: series.to_owned(),
            what,
            index,
        });
    }
    check_magnitude(series, what, values.iter().map(|v| v.abs()))
}

fn check_magnitude(
    series: &str,
    what: &'static str,
    magnitudes: impl Iterator<Item = f64>,
) -> Result<(), PlotError> {
    match magnitudes.enumerate().find(|&(_, m)| m > MAX_MAGNITUDE) {
        Some((index, magnitude)) => Err(PlotError::OutOfRange {
            series: series.to_owned(),
            what,
            index,
            magnitude,
        }),
        None => Ok(()),
    }
}

fn check_length(
    series: &str,
    what: &'static str,
    expected: usize,
    found: usize,
) -> Result<(), PlotError> {
    if expected == found {
        Ok(())
    } else {
        Err(PlotError::LengthMismatch {
            series: series.to_owned(),
            what,
            expected,
            found,
        })
    }
}

fn check_track(track: &VelocityTrack<'_>) -> Result<(), PlotError> {
    if track.t.is_empty() {
        return Err(PlotError::EmptySeries {
            series: track.name.to_owned(),
        });
    }
    check_length(track.name, "S-x velocity", track.t.len(), track.x.len())?;
    check_length(track.name, "S-z velocity", track.t.len(), track.z.len())?;
    check_finite(track.name, "time", track.t)?;
    check_finite(track.name, "S-x velocity", track.x)?;
    check_finite(track.name, "S-z velocity", track.z)
}

fn check_placements(placements: &Placements<'_>) -> Result<(), PlotError> {
    const NAME: &str = "placements";
    if placements.t.is_empty() {
        return Err(PlotError::EmptySeries {
            series: NAME.to_owned(),
        });
    }
    check_length(NAME, "labels", placements.t.len(), placements.labels.len())?;
    check_finite(NAME, "time", placements.t)
}

/// Registers the embedded font once per process; plotters keeps it in a
/// global table.
fn ensure_font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| register_font(FONT, FontStyle::Normal, FONT_BYTES).is_ok());
    if ok { Ok(()) } else { Err(PlotError::Font) }
}

/// A drawing that can be rendered on any plotters backend.
trait Figure {
    type Output;
    /// `raster` tells a bitmap backend, whose wide lines need care (see
    /// [`draw_polyline`]).
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        raster: bool,
    ) -> Result<Self::Output, String>;
}

/// The coordinates of every chart here: metres or seconds against metres or
/// metres per second.
type Plane<DB> = DrawingArea<DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Draws a polyline on a chart.
///
/// Plotters' bitmap rasteriser turns a wide polyline into one polygon with
/// mitred joins: where the line doubles back (sensor noise, min-max
/// decimation) the inner miter shoots far out of the chart, and two
/// vertices on the same pixel give a NaN vertex, drawn as a line to the
/// image's edge. So for bitmaps the segments are drawn one by one (no
/// joins) after merging vertices that fall on the same pixel. SVG keeps one
/// polyline: viewers join it properly and the file stays small.
fn draw_polyline<DB: DrawingBackend>(
    area: &Plane<DB>,
    points: Vec<(f64, f64)>,
    style: ShapeStyle,
    raster: bool,
) -> Result<(), String> {
    if !raster {
        return area.draw(&PathElement::new(points, style)).map_err(msg);
    }
    let mut kept: Vec<((f64, f64), (i32, i32))> = Vec::with_capacity(points.len());
    for p in points {
        let pixel = area.map_coordinate(&p);
        if kept.last().is_none_or(|&(_, last)| last != pixel) {
            kept.push((p, pixel));
        }
    }
    for pair in kept.windows(2) {
        area.draw(&PathElement::new(vec![pair[0].0, pair[1].0], style))
            .map_err(msg)?;
    }
    Ok(())
}

/// Plotters' errors are generic over the backend; keeping only their message
/// lets the figures share one error path.
fn msg<E: std::fmt::Display>(error: E) -> String {
    error.to_string()
}

fn write_figure<F: Figure>(
    path: &Path,
    format: PlotFormat,
    size: (u32, u32),
    figure: &F,
) -> Result<F::Output, PlotError> {
    ensure_font()?;
    let io_error = |source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    };
    let render_error = |message| PlotError::Render {
        path: path.to_path_buf(),
        message,
    };
    // Same folder as the target, so the final rename stays on one file
    // system and is atomic.
    let dir = match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".ridi-plot-").suffix(format.suffix());
    // Temporary files are private (0600) by default; a plot is an ordinary
    // output file, so ask for what `File::create` gives (0666 less umask).
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut file = builder.tempfile_in(dir).map_err(io_error)?;
    let output = match format {
        PlotFormat::Svg => {
            let mut svg = String::new();
            let output = {
                let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
                let output = figure.draw(&root, false).map_err(render_error)?;
                root.present().map_err(|e| render_error(msg(e)))?;
                output
            };
            file.write_all(svg.as_bytes()).map_err(io_error)?;
            output
        }
        PlotFormat::Png => {
            // The image encoder writes the file itself, by path; the suffix
            // tells it the format.
            let root = BitMapBackend::new(file.path(), size).into_drawing_area();
            let output = figure.draw(&root, true).map_err(render_error)?;
            root.present().map_err(|e| render_error(msg(e)))?;
            output
        }
    };
    file.as_file().sync_all().map_err(io_error)?;
    file.persist(path).map_err(|e| io_error(e.error))?;
    Ok(output)
}

/// Axis-aligned bounding box of points, in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Bounds {
    x: Range1,
    y: Range1,
}

impl Bounds {
    /// `points` must be non-empty and finite.
    fn of_points(points: &[[f64; 2]]) -> Self {
        let x = points.iter().map(|p| p[0]);
        let y = points.iter().map(|p| p[1]);
        Self {
            x: Range1::of_iter(x),
            y: Range1::of_iter(y),
        }
    }

    fn union(self, other: Self) -> Self {
        Self {
            x: self.x.union(other.x),
            y: self.y.union(other.y),
        }
    }

    fn contains(&self, p: [f64; 2]) -> bool {
        self.x.lo <= p[0] && p[0] <= self.x.hi && self.y.lo <= p[1] && p[1] <= self.y.hi
    }

    /// Grows the box by `margin` on every side, then the shorter side so
    /// that one metre spans as many pixels on both axes of a `width` x
    /// `height` plotting area.
    fn equal_aspect(self, margin: f64, (width, height): (u32, u32)) -> Self {
        let x = self.x.grown(margin);
        let y = self.y.grown(margin);
        let (width, height) = (f64::from(width.max(1)), f64::from(height.max(1)));
        let metres_per_pixel = (x.span() / width).max(y.span() / height);
        Self {
            x: x.with_span(metres_per_pixel * width),
            y: y.with_span(metres_per_pixel * height),
        }
    }
}

/// A closed interval.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Range1 {
    lo: f64,
    hi: f64,
}

impl Range1 {
    /// `values` must be non-empty and finite.
    fn of(values: &[f64]) -> Self {
        Self::of_iter(values.iter().copied())
    }

    fn of_iter(values: impl Iterator<Item = f64>) -> Self {
        values.fold(
            Self {
                lo: f64::INFINITY,
                hi: f64::NEG_INFINITY,
            },
            |r, v| Self {
                lo: r.lo.min(v),
                hi: r.hi.max(v),
            },
        )
    }

    fn union(self, other: Self) -> Self {
        Self {
            lo: self.lo.min(other.lo),
            hi: self.hi.max(other.hi),
        }
    }

    fn span(self) -> f64 {
        self.hi - self.lo
    }

    fn grown(self, by: f64) -> Self {
        Self {
            lo: self.lo - by,
            hi: self.hi + by,
        }
    }

    fn with_span(self, span: f64) -> Self {
        let mid = 0.5 * (self.lo + self.hi);
        Self {
            lo: mid - 0.5 * span,
            hi: mid + 0.5 * span,
        }
    }

    /// Plotters cannot map an empty range: a constant series gets `pad` on
    /// each side.
    fn padded_if_flat(self, pad: f64) -> Self {
        if self.span() > 0.0 {
            self
        } else {
            self.grown(pad)
        }
    }

    /// Adds 5% headroom so extreme values do not sit on the frame.
    fn with_headroom(self) -> Self {
        let padded = self.padded_if_flat(0.5);
        padded.grown(0.05 * padded.span())
    }

    fn as_range(self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

/// Clips the segment `a`-`b` to `view` (Liang–Barsky); `None` when it lies
/// wholly outside.
fn clip_segment(a: [f64; 2], b: [f64; 2], view: &Bounds) -> Option<([f64; 2], [f64; 2])> {
    let d = [b[0] - a[0], b[1] - a[1]];
    let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
    let edges = [
        (-d[0], a[0] - view.x.lo),
        (d[0], view.x.hi - a[0]),
        (-d[1], a[1] - view.y.lo),
        (d[1], view.y.hi - a[1]),
    ];
    for (p, q) in edges {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
            if t0 > t1 {
                return None;
            }
        }
    }
    let at = |t: f64| [a[0] + t * d[0], a[1] + t * d[1]];
    Some((
        if t0 > 0.0 { at(t0) } else { a },
        if t1 < 1.0 { at(t1) } else { b },
    ))
}

/// Splits a polyline into the runs visible in `view`, dropping points closer
/// than `min_step` to the previous kept one: thousands of samples per pixel
/// would bloat the SVG without changing a pixel.
fn visible_runs(points: &[[f64; 2]], view: &Bounds, min_step: f64) -> Vec<Vec<(f64, f64)>> {
    struct Run {
        points: Vec<(f64, f64)>,
        skipped: Option<[f64; 2]>,
    }
    impl Run {
        fn push(&mut self, p: [f64; 2], min_step: f64) {
            match self.points.last() {
                Some(&(x, y)) if (p[0] - x).hypot(p[1] - y) < min_step => self.skipped = Some(p),
                _ => {
                    self.points.push((p[0], p[1]));
                    self.skipped = None;
                }
            }
        }
        fn finish(mut self, runs: &mut Vec<Vec<(f64, f64)>>) {
            // The last point of a run is kept even when close, so the line
            // ends where the data does (at the view edge or the end marker).
            if let Some(p) = self.skipped.take() {
                self.points.push((p[0], p[1]));
            }
            if self.points.len() >= 2 {
                runs.push(self.points);
            }
        }
    }

    let mut runs = Vec::new();
    let mut current: Option<Run> = None;
    for pair in points.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        match clip_segment(a, b, view) {
            Some((start, end)) => {
                let run = current.get_or_insert_with(|| Run {
                    points: Vec::new(),
                    skipped: None,
                });
                if run.points.is_empty() {
                    run.push(start, 0.0);
                }
                run.push(end, min_step);
                if end != b {
                    // The segment leaves the view: the next visible part
                    // starts a new run.
                    if let Some(run) = current.take() {
                        run.finish(&mut runs);
                    }
                }
            }
            None => {
                if let Some(run) = current.take() {
                    run.finish(&mut runs);
                }
            }
        }
    }
    if let Some(run) = current.take() {
        run.finish(&mut runs);
    }
    runs
}

/// Per-pixel-column reduction of a time series: the first, lowest, highest
/// and last sample of each column, in time order. Lines drawn from it are
/// indistinguishable from the full series while the file stays small.
fn decimate_columns(t: &[f64], v: &[f64], t_range: Range1, columns: u32) -> Vec<(f64, f64)> {
    let scale = f64::from(columns.max(1)) / t_range.span();
    let column = |t: f64| ((t - t_range.lo) * scale).floor() as i64;
    let mut out = Vec::new();
    let mut start = 0;
    while start < t.len() {
        let col = column(t[start]);
        let mut end = start + 1;
        while end < t.len() && column(t[end]) == col {
            end += 1;
        }
        let bucket = start..end;
        let lowest = bucket
            .clone()
            .min_by(|&i, &j| v[i].total_cmp(&v[j]))
            .unwrap_or(start);
        let highest = bucket
            .clone()
            .max_by(|&i, &j| v[i].total_cmp(&v[j]))
            .unwrap_or(start);
        let mut keep = [start, lowest, highest, end - 1];
        keep.sort_unstable();
        let mut previous = None;
        for i in keep {
            if previous != Some(i) {
                out.push((t[i], v[i]));
                previous = Some(i);
            }
        }
        start = end;
    }
    out
}

fn estimate_width<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    style: &TextStyle<'_>,
) -> Result<i32, String> {
    let (w, _) = area.estimate_text_size(text, style).map_err(msg)?;
    Ok(i32::try_from(w).unwrap_or(i32::MAX))
}

fn pixels(n: u32) -> i32 {
    i32::try_from(n).unwrap_or(i32::MAX)
}

/// How a legend entry is drawn before its text.
#[derive(Debug, Clone, Copy)]
enum Swatch {
    Line(RGBColor),
    StartMarker,
    EndMarker,
    Block(RGBColor),
}

const SWATCH_WIDTH: i32 = 28;

fn draw_swatch<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    swatch: Swatch,
    (x, y): (i32, i32),
) -> Result<(), String> {
    let mid = x + SWATCH_WIDTH / 2;
    match swatch {
        Swatch::Line(colour) => area.draw(&PathElement::new(
            vec![(x, y), (x + SWATCH_WIDTH, y)],
            colour.stroke_width(3),
        )),
        Swatch::StartMarker => area.draw(&Circle::new((mid, y), 5, BLACK.stroke_width(2))),
        Swatch::EndMarker => area.draw(&Cross::new((mid, y), 5, BLACK.stroke_width(2))),
        Swatch::Block(colour) => area.draw(&Rectangle::new(
            [(x + 4, y - 7), (x + SWATCH_WIDTH - 4, y + 7)],
            colour.filled(),
        )),
    }
    .map_err(msg)
}

/// The trajectory figure, validated.
struct TrajectoryFigure<'p> {
    plot: &'p TrajectoryPlot<'p>,
    /// Bounds of the trajectories the view is fitted to.
    bounds: Bounds,
    /// Margin around them, in metres.
    margin: f64,
}

impl TrajectoryFigure<'_> {
    /// Ground truth first, then the estimates with their palette colour.
    fn styled(&self) -> Vec<(Trajectory<'_>, RGBColor)> {
        let truth = self.plot.ground_truth.map(|t| (t, TRUTH_COLOUR));
        let estimates = self
            .plot
            .estimates
            .iter()
            .zip(PALETTE.iter().cycle())
            .map(|(t, c)| (*t, *c));
        truth.into_iter().chain(estimates).collect()
    }
}

impl Figure for TrajectoryFigure<'_> {
    type Output = TrajectoryView;

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        raster: bool,
    ) -> Result<TrajectoryView, String> {
        const CLIPPED: &str = " (clipped)";
        root.fill(&WHITE).map_err(msg)?;
        let body = root.titled(self.plot.title, (FONT, 24)).map_err(msg)?;
        let legend_style =
            TextStyle::from((FONT, 16).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
        let styled = self.styled();

        // The legend is sized for the worst case, every name clipped, because
        // what is clipped depends on the view, which depends on the space the
        // legend leaves.
        let mut widest = estimate_width(&body, "start", &legend_style)?;
        for (trajectory, _) in &styled {
            widest = widest.max(estimate_width(
                &body,
                &format!("{}{CLIPPED}", trajectory.name),
                &legend_style,
            )?);
        }
        let (body_w, _) = body.dim_in_pixel();
        let legend_w = (widest + SWATCH_WIDTH + 50).clamp(120, pixels(body_w) * 2 / 5);
        let (chart_area, legend_area) = body.split_horizontally(pixels(body_w) - legend_w);

        let chart_builder = |x: std::ops::Range<f64>, y: std::ops::Range<f64>| {
            ChartBuilder::on(&chart_area)
                .margin(10)
                .margin_right(20)
                .x_label_area_size(50)
                .y_label_area_size(70)
                .build_cartesian_2d(x, y)
                .map_err(msg)
        };
        // Building a chart draws nothing: a throw-away one tells the exact
        // size of the plotting area, which equal aspect needs.
        let plot_px = chart_builder(0.0..1.0, 0.0..1.0)?
            .plotting_area()
            .dim_in_pixel();
        let view = self.bounds.equal_aspect(self.margin, plot_px);
        let mut chart = chart_builder(view.x.as_range(), view.y.as_range())?;
        let (plot_w, plot_h) = plot_px;
        chart
            .configure_mesh()
            .x_desc("x (m)")
            .y_desc("y (m)")
            .x_labels((plot_w / 70).max(3) as usize)
            .y_labels((plot_h / 70).max(3) as usize)
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 16))
            .max_light_lines(4)
            .light_line_style(RGBColor(238, 238, 238))
            .bold_line_style(RGBColor(210, 210, 210))
            .draw()
            .map_err(msg)?;

        let metres_per_pixel = view.x.span() / f64::from(plot_w.max(1));
        let is_clipped: Vec<bool> = styled
            .iter()
            .map(|(trajectory, _)| !trajectory.points.iter().all(|&p| view.contains(p)))
            .collect();
        // Estimates first so the ground truth is drawn on top of them.
        let truth_count = usize::from(self.plot.ground_truth.is_some());
        for (trajectory, colour) in styled[truth_count..].iter().chain(&styled[..truth_count]) {
            // Steps under a pixel would not change the picture.
            let runs = visible_runs(trajectory.points, &view, metres_per_pixel);
            for run in runs {
                draw_polyline(chart.plotting_area(), run, colour.stroke_width(2), raster)?;
            }
            let first = trajectory.points[0];
            let last = trajectory.points[trajectory.points.len() - 1];
            if view.contains(first) {
                chart
                    .draw_series([Circle::new((first[0], first[1]), 5, colour.stroke_width(2))])
                    .map_err(msg)?;
            }
            if view.contains(last) {
                chart
                    .draw_series([Cross::new((last[0], last[1]), 5, colour.stroke_width(2))])
                    .map_err(msg)?;
            }
        }

        let mut legend: Vec<(Swatch, String)> = styled
            .iter()
            .zip(&is_clipped)
            .map(|((trajectory, colour), &clipped)| {
                let suffix = if clipped { CLIPPED } else { "" };
                (
                    Swatch::Line(*colour),
                    format!("{}{suffix}", trajectory.name),
                )
            })
            .collect();
        legend.push((Swatch::StartMarker, "start".to_owned()));
        legend.push((Swatch::EndMarker, "end".to_owned()));
        // Legend top aligned with the plotting area (chart margin of 10).
        let mut y = 22;
        for (swatch, label) in &legend {
            draw_swatch(&legend_area, *swatch, (4, y))?;
            legend_area
                .draw_text(label, &legend_style, (SWATCH_WIDTH + 12, y))
                .map_err(msg)?;
            y += 26;
        }
        Ok(TrajectoryView {
            x: [view.x.lo, view.x.hi],
            y: [view.y.lo, view.y.hi],
            clipped: styled
                .iter()
                .zip(&is_clipped)
                .filter(|(_, clipped)| **clipped)
                .map(|((trajectory, _), _)| trajectory.name.to_owned())
                .collect(),
        })
    }
}

/// A velocity channel of the stabilised-IMU frame.
#[derive(Debug, Clone, Copy)]
enum Channel {
    X,
    Z,
}

impl Channel {
    fn of<'a>(self, track: &VelocityTrack<'a>) -> &'a [f64] {
        match self {
            Self::X => track.x,
            Self::Z => track.z,
        }
    }
}

/// The velocity figure, validated.
struct VelocityFigure<'p> {
    plot: &'p VelocityPlot<'p>,
    /// Truth (if any) first, then the regressed track: drawing order.
    tracks: Vec<VelocityTrack<'p>>,
    t_range: Range1,
}

/// A run of one placement label over time.
#[derive(Debug, Clone, PartialEq)]
struct PlacementRun<'a> {
    label: &'a str,
    start: f64,
    end: f64,
}

/// Consecutive equal labels merged into runs; a run ends where the next one
/// starts, the last at the last time stamp.
fn placement_runs<'a>(placements: &Placements<'a>) -> Vec<PlacementRun<'a>> {
    let mut runs: Vec<PlacementRun<'a>> = Vec::new();
    for (&t, &label) in placements.t.iter().zip(placements.labels) {
        match runs.last_mut() {
            Some(run) if run.label == label => run.end = t,
            Some(run) => {
                run.end = t;
                runs.push(PlacementRun {
                    label,
                    start: t,
                    end: t,
                });
            }
            None => runs.push(PlacementRun {
                label,
                start: t,
                end: t,
            }),
        }
    }
    runs
}

/// Strip colours: fixed for the RIDI placements, then the remaining tints
/// in order of first appearance.
fn placement_colours<'a>(runs: &[PlacementRun<'a>]) -> Vec<(&'a str, RGBColor)> {
    let mut colours: Vec<(&'a str, RGBColor)> = Vec::new();
    let mut spare = STRIP_PALETTE[KNOWN_PLACEMENTS.len()..].iter().cycle();
    for run in runs {
        if colours.iter().any(|(label, _)| *label == run.label) {
            continue;
        }
        let known = KNOWN_PLACEMENTS
            .iter()
            .position(|k| k.eq_ignore_ascii_case(run.label));
        let colour = match known {
            Some(i) => STRIP_PALETTE[i],
            None => *spare.next().expect("cycle over a non-empty palette"),
        };
        colours.push((run.label, colour));
    }
    colours
}

impl Figure for VelocityFigure<'_> {
    type Output = ();

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        raster: bool,
    ) -> Result<(), String> {
        // Shared by the strip and both panels so their time axes line up.
        const LEFT_LABELS: u32 = 75;
        const MARGIN: u32 = 10;
        const MARGIN_RIGHT: u32 = 25;
        root.fill(&WHITE).map_err(msg)?;
        let body = root.titled(self.plot.title, (FONT, 24)).map_err(msg)?;
        let legend_style =
            TextStyle::from((FONT, 16).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
        let runs = self
            .plot
            .placements
            .as_ref()
            .map(placement_runs)
            .unwrap_or_default();
        let colours = placement_colours(&runs);
        let track_colour = |i: usize| {
            if self.plot.truth.is_some() && i == 0 {
                TRUTH_COLOUR
            } else {
                PALETTE[3]
            }
        };

        let (legend_row, rest) = body.split_vertically(30);
        let mut x = pixels(LEFT_LABELS + MARGIN);
        let mut entries: Vec<(Swatch, String)> = self
            .tracks
            .iter()
            .enumerate()
            .map(|(i, tr)| (Swatch::Line(track_colour(i)), tr.name.to_owned()))
            .collect();
        entries.extend(
            colours
                .iter()
                .map(|(label, colour)| (Swatch::Block(*colour), (*label).to_owned())),
        );
        for (i, (swatch, label)) in entries.iter().enumerate() {
            if i == self.tracks.len() {
                // A gap between the velocity lines and the placement keys.
                x += 20;
                legend_row
                    .draw_text("placement:", &legend_style, (x, 15))
                    .map_err(msg)?;
                x += estimate_width(&legend_row, "placement:", &legend_style)? + 6;
            }
            draw_swatch(&legend_row, *swatch, (x, 15))?;
            x += SWATCH_WIDTH + 8;
            legend_row
                .draw_text(label, &legend_style, (x, 15))
                .map_err(msg)?;
            x += estimate_width(&legend_row, label, &legend_style)? + 24;
        }

        let panels_area = if runs.is_empty() {
            rest
        } else {
            let (strip_area, panels_area) = rest.split_vertically(36);
            let strip = ChartBuilder::on(&strip_area)
                .margin_left(MARGIN)
                .margin_right(MARGIN_RIGHT)
                .margin_top(6)
                .margin_bottom(6)
                .y_label_area_size(LEFT_LABELS)
                .build_cartesian_2d(self.t_range.as_range(), 0.0..1.0)
                .map_err(msg)?;
            let strip_px = f64::from(strip.plotting_area().dim_in_pixel().0.max(1));
            let label_style =
                TextStyle::from((FONT, 14).into_font()).pos(Pos::new(HPos::Center, VPos::Center));
            for run in &runs {
                let colour = colours
                    .iter()
                    .find(|(label, _)| *label == run.label)
                    .map_or(STRIP_PALETTE[0], |(_, c)| *c);
                strip
                    .plotting_area()
                    .draw(&Rectangle::new(
                        [(run.start, 0.0), (run.end, 1.0)],
                        colour.filled(),
                    ))
                    .map_err(msg)?;
                // Names only where they fit; the legend row names the colours.
                let run_px = (run.end - run.start) / self.t_range.span() * strip_px;
                let text_px = f64::from(estimate_width(&strip_area, run.label, &label_style)?);
                if run_px > text_px + 8.0 {
                    strip
                        .plotting_area()
                        .draw(&Text::new(
                            run.label.to_owned(),
                            (0.5 * (run.start + run.end), 0.5),
                            label_style.clone(),
                        ))
                        .map_err(msg)?;
                }
            }
            strip_area
                .draw_text(
                    "placement",
                    &TextStyle::from((FONT, 14).into_font())
                        .pos(Pos::new(HPos::Right, VPos::Center)),
                    (pixels(MARGIN + LEFT_LABELS) - 8, 18),
                )
                .map_err(msg)?;
            panels_area
        };

        let (_, panels_h) = panels_area.dim_in_pixel();
        let (top, bottom) = panels_area.split_vertically(panels_h * 47 / 100);
        let channels = [
            (&top, "S-x (m/s)", Channel::X),
            (&bottom, "S-z (m/s)", Channel::Z),
        ];
        for (panel_index, (area, desc, channel)) in channels.into_iter().enumerate() {
            let is_bottom = panel_index == 1;
            let v_range = self
                .tracks
                .iter()
                .map(|tr| Range1::of(channel.of(tr)))
                .reduce(Range1::union)
                .expect("at least one track")
                .with_headroom();
            let mut chart = ChartBuilder::on(area)
                .margin_left(MARGIN)
                .margin_right(MARGIN_RIGHT)
                .margin_top(MARGIN)
                .margin_bottom(if is_bottom { MARGIN } else { 0 })
                .x_label_area_size(if is_bottom { 50 } else { 28 })
                .y_label_area_size(LEFT_LABELS)
                .build_cartesian_2d(self.t_range.as_range(), v_range.as_range())
                .map_err(msg)?;
            let mut mesh = chart.configure_mesh();
            mesh.y_desc(desc)
                .label_style((FONT, 14))
                .axis_desc_style((FONT, 16))
                .max_light_lines(4)
                .light_line_style(RGBColor(238, 238, 238))
                .bold_line_style(RGBColor(210, 210, 210));
            if is_bottom {
                mesh.x_desc("time (s)");
            }
            mesh.draw().map_err(msg)?;
            let columns = chart.plotting_area().dim_in_pixel().0;
            for (i, track) in self.tracks.iter().enumerate() {
                let points = decimate_columns(track.t, channel.of(track), self.t_range, columns);
                let style = track_colour(i).stroke_width(2);
                draw_polyline(chart.plotting_area(), points, style, raster)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Bounds {
        Bounds {
            x: Range1 { lo: 0.0, hi: 10.0 },
            y: Range1 { lo: 0.0, hi: 10.0 },
        }
    }

    #[test]
    fn segment_inside_is_untouched_and_outside_is_dropped() {
        let view = square();
        assert_eq!(
            clip_segment([1.0, 1.0], [9.0, 2.0], &view),
            Some(([1.0, 1.0], [9.0, 2.0]))
        );
        assert_eq!(clip_segment([11.0, 1.0], [20.0, 2.0], &view), None);
        assert_eq!(clip_segment([-5.0, 20.0], [20.0, 20.0], &view), None);
    }

    #[test]
    fn segment_crossing_the_view_is_cut_at_both_edges() {
        let (a, b) = clip_segment([-10.0, 5.0], [20.0, 5.0], &square()).expect("crosses the view");
        assert_eq!((a, b), ([0.0, 5.0], [10.0, 5.0]));
    }

    #[test]
    fn polyline_leaving_and_reentering_gives_two_runs() {
        let points = [
            [1.0, 1.0],
            [5.0, 1.0],
            [50.0, 1.0],
            [50.0, 8.0],
            [5.0, 8.0],
            [1.0, 8.0],
        ];
        let runs = visible_runs(&points, &square(), 0.0);
        assert_eq!(
            runs,
            vec![
                vec![(1.0, 1.0), (5.0, 1.0), (10.0, 1.0)],
                vec![(10.0, 8.0), (5.0, 8.0), (1.0, 8.0)]
            ]
        );
    }

    #[test]
    fn dense_polyline_is_thinned_but_keeps_its_ends() {
        let points: Vec<[f64; 2]> = (0..=1000).map(|i| [f64::from(i) * 0.001, 5.0]).collect();
        let runs = visible_runs(&points, &square(), 0.1);
        assert_eq!(runs.len(), 1);
        let run = &runs[0];
        assert!(run.len() <= 12, "{} points kept", run.len());
        assert_eq!(run.first(), Some(&(0.0, 5.0)));
        assert_eq!(run.last(), Some(&(1.0, 5.0)));
    }

    #[test]
    fn equal_aspect_matches_the_pixel_ratio_and_keeps_the_box() {
        let bounds = Bounds {
            x: Range1 { lo: 0.0, hi: 40.0 },
            y: Range1 { lo: -5.0, hi: 5.0 },
        };
        let view = bounds.equal_aspect(1.0, (800, 600));
        assert!((view.x.span() / view.y.span() - 800.0 / 600.0).abs() < 1e-12);
        assert_eq!((view.x.lo, view.x.hi), (-1.0, 41.0));
        assert!(view.y.lo < -6.0 && view.y.hi > 6.0);
    }

    #[test]
    fn column_decimation_keeps_extremes_in_time_order() {
        let t: Vec<f64> = (0..1000).map(|i| f64::from(i) / 1000.0).collect();
        let v: Vec<f64> = (0..1000)
            .map(|i| {
                if i == 421 {
                    7.0
                } else if i == 422 {
                    -7.0
                } else {
                    0.0
                }
            })
            .collect();
        let out = decimate_columns(&t, &v, Range1 { lo: 0.0, hi: 1.0 }, 10);
        assert!(out.len() <= 40);
        assert!(out.contains(&(0.421, 7.0)) && out.contains(&(0.422, -7.0)));
        assert!(out.windows(2).all(|w| w[0].0 <= w[1].0));
        assert_eq!(out.last(), Some(&(0.999, 0.0)));
    }

    #[test]
    fn placement_runs_merge_equal_labels() {
        let t = [0.0, 1.0, 2.0, 3.0, 4.0];
        let labels = ["leg", "leg", "bag", "bag", "leg"];
        let runs = placement_runs(&Placements {
            t: &t,
            labels: &labels,
        });
        assert_eq!(
            runs,
            vec![
                PlacementRun {
                    label: "leg",
                    start: 0.0,
                    end: 2.0
                },
                PlacementRun {
                    label: "bag",
                    start: 2.0,
                    end: 4.0
                },
                PlacementRun {
                    label: "leg",
                    start: 4.0,
                    end: 4.0
                },
            ]
        );
        let colours = placement_colours(&runs);
        assert_eq!(
            colours,
            vec![("leg", STRIP_PALETTE[0]), ("bag", STRIP_PALETTE[1])]
        );
    }
}
