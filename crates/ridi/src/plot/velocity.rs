//! The velocity figure: regressed and true S velocities over time, with placement strips.

use super::*;

/// A velocity channel of the stabilised-IMU frame.
#[derive(Debug, Clone, Copy)]
pub(super) enum Channel {
    X,
    Z,
}

impl Channel {
    pub(super) fn of<'a>(self, track: &VelocityTrack<'a>) -> &'a [f64] {
        match self {
            Self::X => track.x,
            Self::Z => track.z,
        }
    }
}

/// The velocity figure, validated.
pub(super) struct VelocityFigure<'p> {
    pub(super) plot: &'p VelocityPlot<'p>,
    /// Truth (if any) first, then the regressed track: drawing order.
    pub(super) tracks: Vec<VelocityTrack<'p>>,
    pub(super) t_range: Range1,
}

/// A run of one placement label over time.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct PlacementRun<'a> {
    pub(super) label: &'a str,
    pub(super) start: f64,
    pub(super) end: f64,
}

/// Consecutive equal labels merged into runs; a run ends where the next one
/// starts, the last at the last time stamp.
pub(super) fn placement_runs<'a>(placements: &Placements<'a>) -> Vec<PlacementRun<'a>> {
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
pub(super) fn placement_colours<'a>(runs: &[PlacementRun<'a>]) -> Vec<(&'a str, RGBColor)> {
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

    #[test]
    pub(super) fn placement_runs_merge_equal_labels() {
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
