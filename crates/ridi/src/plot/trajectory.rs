//! The trajectory figure: ground truth and methods on the floor plan.

use super::*;

/// The trajectory figure, validated.
pub(super) struct TrajectoryFigure<'p> {
    pub(super) plot: &'p TrajectoryPlot<'p>,
    /// Bounds of the trajectories the view is fitted to.
    pub(super) bounds: Bounds,
    /// Margin around them, in metres.
    pub(super) margin: f64,
}

impl TrajectoryFigure<'_> {
    /// Ground truth first, then the estimates with their palette colour.
    pub(super) fn styled(&self) -> Vec<(Trajectory<'_>, RGBColor)> {
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
