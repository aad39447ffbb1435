//! Trajectory and velocity plots written to disk, as SVG and PNG.
#![cfg(feature = "plot")]

use ridi::plot::{
    Placements, PlotError, PlotFormat, Trajectory, TrajectoryOptions, TrajectoryPlot,
    VelocityOptions, VelocityPlot, VelocityTrack, ViewFit, plot_trajectories, plot_velocity,
};
use ridi_test_support::file_names;

/// A 20 m x 10 m loop sampled at 50 points per metre, like a walk at 200 Hz.
fn walk() -> Vec<[f64; 2]> {
    let n = 3000;
    (0..=n)
        .map(|i| {
            let a = std::f64::consts::TAU * f64::from(i) / f64::from(n);
            [10.0 * (1.0 - a.cos()), 5.0 * a.sin()]
        })
        .collect()
}

/// The walk with a small rotation and scale error, as a good estimate has.
fn estimate(truth: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let (s, c) = 0.03_f64.sin_cos();
    truth
        .iter()
        .map(|p| [1.02 * (c * p[0] - s * p[1]), 1.02 * (s * p[0] + c * p[1])])
        .collect()
}

/// A naive double integration drifting quadratically to hundreds of metres.
fn drifting(truth: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let n = truth.len() as f64;
    truth
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let k = i as f64 / n;
            [p[0] + 400.0 * k * k, p[1] - 250.0 * k * k]
        })
        .collect()
}

/// Width and height from a PNG's signature and IHDR chunk.
fn png_dimensions(bytes: &[u8]) -> (u32, u32) {
    assert!(bytes.len() > 33, "PNG too short: {} bytes", bytes.len());
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
    assert_eq!(&bytes[12..16], b"IHDR", "first chunk must be IHDR");
    let be = |i: usize| u32::from_be_bytes(bytes[i..i + 4].try_into().expect("four bytes"));
    (be(16), be(20))
}

#[test]
fn trajectories_svg_and_png_clip_the_drifting_estimate() {
    let dir = tempfile::tempdir().expect("temp dir");
    let truth = walk();
    let ridi = estimate(&truth);
    let raw = drifting(&truth);
    let estimates = [
        Trajectory {
            name: "RIDI",
            points: &ridi,
        },
        Trajectory {
            name: "RAW",
            points: &raw,
        },
    ];
    let plot = TrajectoryPlot {
        title: "hang_leg1",
        ground_truth: Some(Trajectory {
            name: "ground truth",
            points: &truth,
        }),
        estimates: &estimates,
    };
    let options = TrajectoryOptions::default();

    let svg_path = dir.path().join("traj.svg");
    let view = plot_trajectories(&svg_path, &plot, &options).expect("svg plot");
    assert_eq!(view.clipped, ["RAW"]);
    // Fitted to the 20 m x 10 m ground truth, not to the 400 m drift.
    assert!(
        view.x[0] < 0.0 && view.x[1] > 20.0 && view.x[1] - view.x[0] < 40.0,
        "{view:?}"
    );
    assert!(view.y[0] < -5.0 && view.y[1] > 5.0, "{view:?}");
    let svg = std::fs::read_to_string(&svg_path).expect("read svg");
    assert!(svg.starts_with("<svg"), "{}", &svg[..svg.len().min(80)]);
    assert!(svg.trim_end().ends_with("</svg>"));
    for text in [
        "hang_leg1",
        "ground truth",
        "RIDI",
        "RAW (clipped)",
        "x (m)",
        "y (m)",
        "start",
    ] {
        assert!(svg.contains(text), "SVG lacks {text:?}");
    }
    assert!(!svg.contains("RIDI (clipped)"));
    // 3001 points per trajectory thinned to about one per half pixel, not
    // one element per sample.
    assert!(svg.len() < 400_000, "SVG is {} bytes", svg.len());

    let png_path = dir.path().join("traj.png");
    let png_view = plot_trajectories(&png_path, &plot, &options).expect("png plot");
    assert_eq!(png_view, view, "both backends lay out the same view");
    let png = std::fs::read(&png_path).expect("read png");
    assert_eq!(png_dimensions(&png), options.size);
    assert!(png.len() > 10_000, "PNG is only {} bytes", png.len());

    assert_eq!(file_names(dir.path()), ["traj.png", "traj.svg"]);
}

#[test]
fn trajectory_view_has_equal_aspect_and_fits_everything_on_request() {
    let dir = tempfile::tempdir().expect("temp dir");
    let truth = walk();
    let raw = drifting(&truth);
    let estimates = [Trajectory {
        name: "RAW",
        points: &raw,
    }];
    let plot = TrajectoryPlot {
        title: "all",
        ground_truth: Some(Trajectory {
            name: "ground truth",
            points: &truth,
        }),
        estimates: &estimates,
    };
    let options = TrajectoryOptions {
        fit: ViewFit::All,
        size: (900, 900),
        ..Default::default()
    };
    let view = plot_trajectories(dir.path().join("all.svg"), &plot, &options).expect("plot");
    assert!(view.clipped.is_empty(), "{view:?}");
    assert!(view.x[1] > 400.0 && view.y[0] < -250.0, "{view:?}");
    // The legend column makes the plotting area taller than wide, so with
    // equal aspect x keeps exactly the fitted range plus margins and the y
    // range grows.
    let all = truth.iter().chain(&raw);
    let (x_lo, x_hi) = all
        .clone()
        .fold((f64::MAX, f64::MIN), |(l, h), p| (l.min(p[0]), h.max(p[0])));
    let (y_lo, y_hi) = all.fold((f64::MAX, f64::MIN), |(l, h), p| (l.min(p[1]), h.max(p[1])));
    let margin = options.margin_fraction * (x_hi - x_lo).max(y_hi - y_lo);
    assert!((view.x[0] - (x_lo - margin)).abs() < 1e-9, "{view:?}");
    assert!((view.x[1] - (x_hi + margin)).abs() < 1e-9, "{view:?}");
    assert!(
        view.y[0] < y_lo - margin && view.y[1] > y_hi + margin,
        "{view:?}"
    );
    let (w, h) = (view.x[1] - view.x[0], view.y[1] - view.y[0]);
    assert!(h > w, "{w} m x {h} m");
}

#[test]
fn without_ground_truth_the_first_estimate_sets_the_view() {
    let dir = tempfile::tempdir().expect("temp dir");
    let truth = walk();
    let ridi = estimate(&truth);
    let raw = drifting(&truth);
    let estimates = [
        Trajectory {
            name: "RIDI",
            points: &ridi,
        },
        Trajectory {
            name: "RAW",
            points: &raw,
        },
    ];
    let plot = TrajectoryPlot {
        title: "no gt",
        ground_truth: None,
        estimates: &estimates,
    };
    let path = dir.path().join("track.png");
    let view = plot_trajectories(&path, &plot, &TrajectoryOptions::default()).expect("plot");
    assert_eq!(view.clipped, ["RAW"]);
    assert!(view.x[1] - view.x[0] < 40.0, "{view:?}");
    assert!(std::fs::metadata(&path).expect("written").len() > 10_000);
}

#[test]
fn a_single_still_point_still_gets_a_view() {
    let dir = tempfile::tempdir().expect("temp dir");
    let still = [[3.0, -2.0]];
    let plot = TrajectoryPlot {
        title: "still",
        ground_truth: Some(Trajectory {
            name: "STILL",
            points: &still,
        }),
        estimates: &[],
    };
    let options = TrajectoryOptions::default();
    let view = plot_trajectories(dir.path().join("still.svg"), &plot, &options).expect("plot");
    assert!(view.x[0] <= 3.0 - options.min_margin_m && view.x[1] >= 3.0 + options.min_margin_m);
    assert!(view.y[0] <= -2.0 - options.min_margin_m && view.y[1] >= -2.0 + options.min_margin_m);
}

fn velocity_data() -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<&'static str>) {
    let t: Vec<f64> = (0..4000).map(|i| f64::from(i) * 0.005).collect();
    let vx = t.iter().map(|t| 1.2 * (2.0 * t).sin()).collect();
    let vz = t.iter().map(|t| 0.3 + 0.2 * (0.7 * t).cos()).collect();
    let labels = t
        .iter()
        .map(|&t| match t {
            t if t < 6.0 => "leg",
            t if t < 13.0 => "bag",
            t if t < 13.4 => "hand",
            _ => "body",
        })
        .collect();
    (t, vx, vz, labels)
}

#[test]
fn velocity_svg_and_png_with_placements() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (t, vx, vz, labels) = velocity_data();
    // Regressed every 10th sample with a bias, as the SVR outputs are.
    let t_hat: Vec<f64> = t.iter().step_by(10).copied().collect();
    let vx_hat: Vec<f64> = vx.iter().step_by(10).map(|v| 0.9 * v + 0.05).collect();
    let vz_hat: Vec<f64> = vz.iter().step_by(10).map(|v| v - 0.04).collect();
    let plot = VelocityPlot {
        title: "hang_bag2 velocity",
        regressed: VelocityTrack {
            name: "regressed",
            t: &t_hat,
            x: &vx_hat,
            z: &vz_hat,
        },
        truth: Some(VelocityTrack {
            name: "ground truth",
            t: &t,
            x: &vx,
            z: &vz,
        }),
        placements: Some(Placements {
            t: &t,
            labels: &labels,
        }),
    };
    let options = VelocityOptions::default();

    let svg_path = dir.path().join("velocity.svg");
    plot_velocity(&svg_path, &plot, &options).expect("svg plot");
    let svg = std::fs::read_to_string(&svg_path).expect("read svg");
    for text in [
        "hang_bag2 velocity",
        "regressed",
        "ground truth",
        "S-x (m/s)",
        "S-z (m/s)",
        "time (s)",
        "placement",
        "leg",
        "bag",
        "hand",
        "body",
    ] {
        assert!(svg.contains(text), "SVG lacks {text:?}");
    }
    assert!(svg.len() < 600_000, "SVG is {} bytes", svg.len());

    let png_path = dir.path().join("velocity.png");
    plot_velocity(&png_path, &plot, &options).expect("png plot");
    let png = std::fs::read(&png_path).expect("read png");
    assert_eq!(png_dimensions(&png), options.size);
    assert!(png.len() > 10_000, "PNG is only {} bytes", png.len());
    assert_eq!(file_names(dir.path()), ["velocity.png", "velocity.svg"]);
}

#[test]
fn velocity_without_truth_or_placements() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (t, vx, vz, _) = velocity_data();
    let plot = VelocityPlot {
        title: "track only",
        regressed: VelocityTrack {
            name: "regressed",
            t: &t,
            x: &vx,
            z: &vz,
        },
        truth: None,
        placements: None,
    };
    let path = dir.path().join("v.SVG");
    plot_velocity(&path, &plot, &VelocityOptions::default()).expect("plot");
    let svg = std::fs::read_to_string(&path).expect("read svg");
    assert!(svg.contains("regressed") && !svg.contains("placement"));
}

#[test]
fn format_follows_the_extension() {
    assert_eq!(PlotFormat::from_path("a/b.svg").ok(), Some(PlotFormat::Svg));
    assert_eq!(PlotFormat::from_path("b.PNG").ok(), Some(PlotFormat::Png));
    for bad in ["plot.pdf", "plot", "plot.svg.gz", ".png/"] {
        assert!(
            matches!(
                PlotFormat::from_path(bad),
                Err(PlotError::UnsupportedFormat { .. })
            ),
            "{bad} accepted"
        );
    }
}

#[test]
fn bad_input_is_an_error_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("temp dir");
    let good = walk();
    let mut with_nan = walk();
    with_nan[17] = [1.0, f64::NAN];
    let plot_of = |estimates: &[Trajectory<'_>], path: &str| {
        let plot = TrajectoryPlot {
            title: "bad",
            ground_truth: Some(Trajectory {
                name: "ground truth",
                points: &good,
            }),
            estimates,
        };
        plot_trajectories(dir.path().join(path), &plot, &TrajectoryOptions::default())
    };

    let err = plot_of(&[], "t.pdf").expect_err("pdf");
    assert!(matches!(err, PlotError::UnsupportedFormat { .. }), "{err}");
    assert!(err.to_string().contains("t.pdf"), "{err}");

    let err = plot_of(
        &[Trajectory {
            name: "PDR",
            points: &[],
        }],
        "t.svg",
    )
    .expect_err("empty");
    assert!(
        matches!(&err, PlotError::EmptySeries { series } if series == "PDR"),
        "{err}"
    );

    let err = plot_of(
        &[Trajectory {
            name: "RIDI-MAG",
            points: &with_nan,
        }],
        "t.png",
    )
    .expect_err("NaN");
    assert!(matches!(&err, PlotError::NonFinite { series, index: 17, .. } if series == "RIDI-MAG"));
    assert_eq!(
        err.to_string(),
        "series \"RIDI-MAG\" has a non-finite point at index 17"
    );

    let nothing = TrajectoryPlot {
        title: "none",
        ground_truth: None,
        estimates: &[],
    };
    let err = plot_trajectories(
        dir.path().join("n.svg"),
        &nothing,
        &TrajectoryOptions::default(),
    )
    .expect_err("no series");
    assert!(matches!(err, PlotError::NoSeries));

    let tiny = TrajectoryOptions {
        size: (10, 10),
        ..Default::default()
    };
    let plot = TrajectoryPlot {
        title: "tiny",
        ground_truth: Some(Trajectory {
            name: "ground truth",
            points: &good,
        }),
        estimates: &[],
    };
    let err = plot_trajectories(dir.path().join("tiny.svg"), &plot, &tiny).expect_err("tiny");
    assert!(matches!(err, PlotError::InvalidOptions(_)), "{err}");

    let (t, vx, vz, labels) = velocity_data();
    let short = &vz[..10];
    let plot = VelocityPlot {
        title: "bad",
        regressed: VelocityTrack {
            name: "regressed",
            t: &t,
            x: &vx,
            z: short,
        },
        truth: None,
        placements: None,
    };
    let err = plot_velocity(dir.path().join("v.svg"), &plot, &VelocityOptions::default())
        .expect_err("length");
    assert!(
        matches!(&err, PlotError::LengthMismatch { series, expected: 4000, found: 10, .. } if series == "regressed"),
        "{err}"
    );
    let plot = VelocityPlot {
        title: "bad",
        regressed: VelocityTrack {
            name: "regressed",
            t: &[],
            x: &[],
            z: &[],
        },
        truth: None,
        placements: None,
    };
    let err = plot_velocity(dir.path().join("v.png"), &plot, &VelocityOptions::default())
        .expect_err("empty");
    assert!(
        matches!(&err, PlotError::EmptySeries { series } if series == "regressed"),
        "{err}"
    );
    let plot = VelocityPlot {
        title: "bad",
        regressed: VelocityTrack {
            name: "regressed",
            t: &t,
            x: &vx,
            z: &vz,
        },
        truth: None,
        placements: Some(Placements {
            t: &t,
            labels: &labels[1..],
        }),
    };
    let err = plot_velocity(dir.path().join("v.png"), &plot, &VelocityOptions::default())
        .expect_err("labels");
    assert!(matches!(&err, PlotError::LengthMismatch { series, .. } if series == "placements"));

    assert!(
        file_names(dir.path()).is_empty(),
        "left behind: {:?}",
        file_names(dir.path())
    );
}

#[test]
fn a_failed_write_leaves_the_previous_plot_intact() {
    let dir = tempfile::tempdir().expect("temp dir");
    let truth = walk();
    let path = dir.path().join("keep.svg");
    std::fs::write(&path, "previous").expect("seed");
    let plot = TrajectoryPlot {
        title: "bad",
        ground_truth: Some(Trajectory {
            name: "ground truth",
            points: &truth,
        }),
        estimates: &[Trajectory {
            name: "RAW",
            points: &[[f64::INFINITY, 0.0]],
        }],
    };
    let err = plot_trajectories(&path, &plot, &TrajectoryOptions::default()).expect_err("inf");
    assert!(
        matches!(err, PlotError::NonFinite { index: 0, .. }),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&path).expect("read"), "previous");

    let missing = dir.path().join("no such folder").join("p.png");
    let plot = TrajectoryPlot {
        estimates: &[],
        ..plot
    };
    let err = plot_trajectories(&missing, &plot, &TrajectoryOptions::default())
        .expect_err("missing folder");
    assert!(matches!(err, PlotError::Io { .. }), "{err}");
    assert_eq!(file_names(dir.path()), ["keep.svg"]);
}

#[test]
fn absurd_magnitudes_are_refused_where_they_set_a_range_and_clipped_elsewhere() {
    let dir = tempfile::tempdir().expect("temp dir");
    let truth = walk();
    // A diverged baseline far beyond any sensible range: it is not fitted,
    // so it is clipped like any drift.
    let diverged: Vec<[f64; 2]> = truth
        .iter()
        .enumerate()
        .map(|(i, p)| [p[0] + 1e25 * (i as f64).powi(4), p[1]])
        .collect();
    let estimates = [Trajectory {
        name: "RAW",
        points: &diverged,
    }];
    let plot = TrajectoryPlot {
        title: "diverged",
        ground_truth: Some(Trajectory {
            name: "ground truth",
            points: &truth,
        }),
        estimates: &estimates,
    };
    let view = plot_trajectories(
        dir.path().join("d.png"),
        &plot,
        &TrajectoryOptions::default(),
    )
    .expect("clipped, not refused");
    assert_eq!(view.clipped, ["RAW"]);

    // Fitted to everything, the same trajectory would set the view: refused
    // rather than overflowing the axis ranges.
    let options = TrajectoryOptions {
        fit: ViewFit::All,
        ..Default::default()
    };
    let err =
        plot_trajectories(dir.path().join("all.png"), &plot, &options).expect_err("out of range");
    assert!(
        matches!(&err, PlotError::OutOfRange { series, index: 1, .. } if series == "RAW"),
        "{err}"
    );

    let t = [0.0, 1.0, 2.0];
    let x = [0.0, 1e300, 0.0];
    let plot = VelocityPlot {
        title: "bad",
        regressed: VelocityTrack {
            name: "regressed",
            t: &t,
            x: &x,
            z: &[0.0; 3],
        },
        truth: None,
        placements: None,
    };
    let err = plot_velocity(dir.path().join("v.svg"), &plot, &VelocityOptions::default())
        .expect_err("out of range");
    assert_eq!(
        err.to_string(),
        "series \"regressed\": S-x velocity of magnitude 1e300 at index 1 is beyond the plottable 1e15"
    );
    assert_eq!(file_names(dir.path()), ["d.png"]);
}
