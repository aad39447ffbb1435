//! Input checks: every series finite, of matching lengths and plottable magnitudes.

use super::*;

pub(super) fn check_size((w, h): (u32, u32)) -> Result<(), PlotError> {
    if w < MIN_SIZE.0 || h < MIN_SIZE.1 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(PlotError::InvalidOptions(format!(
            "image size {w}x{h} is outside {}x{} ..= {MAX_SIDE}x{MAX_SIDE}",
            MIN_SIZE.0, MIN_SIZE.1
        )));
    }
    Ok(())
}

pub(super) fn check_points(trajectory: &Trajectory<'_>) -> Result<(), PlotError> {
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
pub(super) fn check_finite(
    series: &str,
    what: &'static str,
    values: &[f64],
) -> Result<(), PlotError> {
    if let Some(index) = values.iter().position(|v| !v.is_finite()) {
        return Err(PlotError::NonFinite {
            series: series.to_owned(),
            what,
            index,
        });
    }
    check_magnitude(series, what, values.iter().map(|v| v.abs()))
}

pub(super) fn check_magnitude(
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

pub(super) fn check_length(
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

pub(super) fn check_track(track: &VelocityTrack<'_>) -> Result<(), PlotError> {
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

pub(super) fn check_placements(placements: &Placements<'_>) -> Result<(), PlotError> {
    const NAME: &str = "placements";
    if placements.t.is_empty() {
        return Err(PlotError::EmptySeries {
            series: NAME.to_owned(),
        });
    }
    check_length(NAME, "labels", placements.t.len(), placements.labels.len())?;
    check_finite(NAME, "time", placements.t)
}
