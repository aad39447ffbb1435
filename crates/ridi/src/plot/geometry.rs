//! Plot geometry: data bounds and views, clipping to the view, thinning polylines and time
//! series to the pixels they cover.

/// Axis-aligned bounding box of points, in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Bounds {
    pub(super) x: Range1,
    pub(super) y: Range1,
}

impl Bounds {
    /// `points` must be non-empty and finite.
    pub(super) fn of_points(points: &[[f64; 2]]) -> Self {
        let x = points.iter().map(|p| p[0]);
        let y = points.iter().map(|p| p[1]);
        Self {
            x: Range1::of_iter(x),
            y: Range1::of_iter(y),
        }
    }

    pub(super) fn union(self, other: Self) -> Self {
        Self {
            x: self.x.union(other.x),
            y: self.y.union(other.y),
        }
    }

    pub(super) fn contains(&self, p: [f64; 2]) -> bool {
        self.x.lo <= p[0] && p[0] <= self.x.hi && self.y.lo <= p[1] && p[1] <= self.y.hi
    }

    /// Grows the box by `margin` on every side, then the shorter side so
    /// that one metre spans as many pixels on both axes of a `width` x
    /// `height` plotting area.
    pub(super) fn equal_aspect(self, margin: f64, (width, height): (u32, u32)) -> Self {
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
pub(super) struct Range1 {
    pub(super) lo: f64,
    pub(super) hi: f64,
}

impl Range1 {
    /// `values` must be non-empty and finite.
    pub(super) fn of(values: &[f64]) -> Self {
        Self::of_iter(values.iter().copied())
    }

    pub(super) fn of_iter(values: impl Iterator<Item = f64>) -> Self {
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

    pub(super) fn union(self, other: Self) -> Self {
        Self {
            lo: self.lo.min(other.lo),
            hi: self.hi.max(other.hi),
        }
    }

    pub(super) fn span(self) -> f64 {
        self.hi - self.lo
    }

    pub(super) fn grown(self, by: f64) -> Self {
        Self {
            lo: self.lo - by,
            hi: self.hi + by,
        }
    }

    pub(super) fn with_span(self, span: f64) -> Self {
        let mid = 0.5 * (self.lo + self.hi);
        Self {
            lo: mid - 0.5 * span,
            hi: mid + 0.5 * span,
        }
    }

    /// Plotters cannot map an empty range: a constant series gets `pad` on
    /// each side.
    pub(super) fn padded_if_flat(self, pad: f64) -> Self {
        if self.span() > 0.0 {
            self
        } else {
            self.grown(pad)
        }
    }

    /// Adds 5% headroom so extreme values do not sit on the frame.
    pub(super) fn with_headroom(self) -> Self {
        let padded = self.padded_if_flat(0.5);
        padded.grown(0.05 * padded.span())
    }

    pub(super) fn as_range(self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

/// Clips the segment `a`-`b` to `view` (Liang–Barsky); `None` when it lies
/// wholly outside.
pub(super) fn clip_segment(
    a: [f64; 2],
    b: [f64; 2],
    view: &Bounds,
) -> Option<([f64; 2], [f64; 2])> {
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
pub(super) fn visible_runs(
    points: &[[f64; 2]],
    view: &Bounds,
    min_step: f64,
) -> Vec<Vec<(f64, f64)>> {
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
pub(super) fn decimate_columns(
    t: &[f64],
    v: &[f64],
    t_range: Range1,
    columns: u32,
) -> Vec<(f64, f64)> {
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

#[cfg(test)]
mod tests {
    use super::*;

    pub(super) fn square() -> Bounds {
        Bounds {
            x: Range1 { lo: 0.0, hi: 10.0 },
            y: Range1 { lo: 0.0, hi: 10.0 },
        }
    }

    #[test]
    pub(super) fn segment_inside_is_untouched_and_outside_is_dropped() {
        let view = square();
        assert_eq!(
            clip_segment([1.0, 1.0], [9.0, 2.0], &view),
            Some(([1.0, 1.0], [9.0, 2.0]))
        );
        assert_eq!(clip_segment([11.0, 1.0], [20.0, 2.0], &view), None);
        assert_eq!(clip_segment([-5.0, 20.0], [20.0, 20.0], &view), None);
    }

    #[test]
    pub(super) fn segment_crossing_the_view_is_cut_at_both_edges() {
        let (a, b) = clip_segment([-10.0, 5.0], [20.0, 5.0], &square()).expect("crosses the view");
        assert_eq!((a, b), ([0.0, 5.0], [10.0, 5.0]));
    }

    #[test]
    pub(super) fn polyline_leaving_and_reentering_gives_two_runs() {
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
    pub(super) fn dense_polyline_is_thinned_but_keeps_its_ends() {
        let points: Vec<[f64; 2]> = (0..=1000).map(|i| [f64::from(i) * 0.001, 5.0]).collect();
        let runs = visible_runs(&points, &square(), 0.1);
        assert_eq!(runs.len(), 1);
        let run = &runs[0];
        assert!(run.len() <= 12, "{} points kept", run.len());
        assert_eq!(run.first(), Some(&(0.0, 5.0)));
        assert_eq!(run.last(), Some(&(1.0, 5.0)));
    }

    #[test]
    pub(super) fn equal_aspect_matches_the_pixel_ratio_and_keeps_the_box() {
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
    pub(super) fn column_decimation_keeps_extremes_in_time_order() {
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
}
