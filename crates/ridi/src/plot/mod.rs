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
//! embedded in the binary, so no system font is needed. A plot is rendered in
//! memory and written through [`ridi_data::write_atomically`], as every output
//! file of ridi-rs is: a failed or interrupted plot never leaves a partial file
//! behind.
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

mod check;
mod draw;
mod geometry;
mod trajectory;
mod velocity;

use check::*;
pub use draw::MAX_MAGNITUDE;
use draw::*;
use geometry::*;
use trajectory::*;
use velocity::*;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{FontStyle, register_font};

/// Errors of the plotting functions.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlotError {
    /// The output path does not end in `.svg` or `.png`.
    #[error(
        "cannot plot to {}: unsupported file extension, expected .svg or .png",
        ridi_data::shown(path)
    )]
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
    #[error("cannot write plot {}: {error}", ridi_data::shown(path))]
    Io {
        /// The output path.
        path: PathBuf,
        /// The underlying error (printed, not chained).
        error: std::io::Error,
    },
    /// The drawing library failed.
    #[error("cannot render plot {}: {message}", ridi_data::shown(path))]
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
