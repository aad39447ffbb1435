//! Drawing shared by the figures: the embedded font, colours, the figure trait and the
//! write of a finished figure (rendered in memory, then written through
//! [`ridi_data::write_atomically`]).

use image::ImageEncoder as _;

use super::*;

/// DejaVu Sans 2.37 (licence in `assets/DejaVuSans-LICENSE.txt`). Embedded
/// because plotters' bitmap backend rasterises text itself and system fonts
/// are missing on fresh machines and CI runners.
pub(super) static FONT_BYTES: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// The family every text style here uses; the embedded font is registered
/// under it.
pub(super) const FONT: &str = "sans-serif";

/// Smallest accepted image: below this the axis label areas leave no room
/// for the data.
pub(super) const MIN_SIZE: (u32, u32) = (320, 240);

/// Largest accepted image side: a PNG is rendered in an RGB buffer of
/// `3 * width * height` bytes, so an unchecked size could exhaust memory.
pub(super) const MAX_SIDE: u32 = 10_000;

/// Largest magnitude accepted on a plotted axis. Beyond it a value is corrupt
/// (1e15 m or m/s, or 30 million years of recording), and the ranges derived
/// from it could overflow to infinity, on which plotters' tick search never
/// ends.
pub const MAX_MAGNITUDE: f64 = 1e15;

/// Colour of the ground truth, drawn on top of the estimates.
pub(super) const TRUTH_COLOUR: RGBColor = RGBColor(0, 0, 0);

/// Tableau 10: distinguishable, and readable for most colour-blind viewers.
pub(super) const PALETTE: [RGBColor; 10] = [
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
pub(super) const STRIP_PALETTE: [RGBColor; 8] = [
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
pub(super) const KNOWN_PLACEMENTS: [&str; 4] = ["leg", "bag", "hand", "body"];

/// Registers the embedded font once per process; plotters keeps it in a
/// global table.
pub(super) fn ensure_font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| register_font(FONT, FontStyle::Normal, FONT_BYTES).is_ok());
    if ok { Ok(()) } else { Err(PlotError::Font) }
}

/// A drawing that can be rendered on any plotters backend.
pub(super) trait Figure {
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
pub(super) fn draw_polyline<DB: DrawingBackend>(
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
pub(super) fn msg<E: std::fmt::Display>(error: E) -> String {
    error.to_string()
}

/// Renders `figure` in memory and writes it to `path` through
/// [`ridi_data::write_atomically`], the one writer of ridi-rs: all of it or
/// nothing, with the same permissions as every other output file.
pub(super) fn write_figure<F: Figure>(
    path: &Path,
    format: PlotFormat,
    size: (u32, u32),
    figure: &F,
) -> Result<F::Output, PlotError> {
    ensure_font()?;
    let render_error = |message| PlotError::Render {
        path: path.to_path_buf(),
        message,
    };
    let (rendered, output) = match format {
        PlotFormat::Svg => {
            let mut svg = String::new();
            let backend = SVGBackend::with_string(&mut svg, size);
            let output = draw_on(backend, figure, false).map_err(render_error)?;
            (Rendered::Svg(svg), output)
        }
        PlotFormat::Png => {
            // RGB, 3 bytes a pixel: the layout `BitMapBackend::with_buffer` draws into.
            let mut rgb = vec![0; 3 * size.0 as usize * size.1 as usize];
            let backend = BitMapBackend::with_buffer(&mut rgb, size);
            let output = draw_on(backend, figure, true).map_err(render_error)?;
            (Rendered::Png(rgb), output)
        }
    };
    ridi_data::write_atomically(path, |w| match &rendered {
        Rendered::Svg(svg) => w.write_all(svg.as_bytes()),
        // The encoder (and settings) plotters' own PNG files are written with.
        Rendered::Png(rgb) => image::codecs::png::PngEncoder::new(w)
            .write_image(rgb, size.0, size.1, image::ColorType::Rgb8)
            .map_err(|e| match e {
                image::ImageError::IoError(e) => e,
                e => std::io::Error::other(e),
            }),
    })
    .map_err(|e| PlotError::Io {
        path: path.to_path_buf(),
        error: match e {
            ridi_data::DataError::Io { error, .. } => error,
            e => std::io::Error::other(e.to_string()),
        },
    })?;
    Ok(output)
}

/// Draws `figure` on `backend` and finishes the drawing.
fn draw_on<DB: DrawingBackend, F: Figure>(
    backend: DB,
    figure: &F,
    raster: bool,
) -> Result<F::Output, String> {
    let root = backend.into_drawing_area();
    let output = figure.draw(&root, raster)?;
    root.present().map_err(msg)?;
    Ok(output)
}

/// A figure rendered in memory, before it is written.
enum Rendered {
    Svg(String),
    Png(Vec<u8>),
}

pub(super) fn estimate_width<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    style: &TextStyle<'_>,
) -> Result<i32, String> {
    let (w, _) = area.estimate_text_size(text, style).map_err(msg)?;
    Ok(i32::try_from(w).unwrap_or(i32::MAX))
}

pub(super) fn pixels(n: u32) -> i32 {
    i32::try_from(n).unwrap_or(i32::MAX)
}

/// How a legend entry is drawn before its text.
#[derive(Debug, Clone, Copy)]
pub(super) enum Swatch {
    Line(RGBColor),
    StartMarker,
    EndMarker,
    Block(RGBColor),
}

pub(super) const SWATCH_WIDTH: i32 = 28;

pub(super) fn draw_swatch<DB: DrawingBackend>(
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
