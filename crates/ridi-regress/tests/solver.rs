//! Solver correctness: closed-form two-point problems, KKT conditions at the solution, and
//! agreement with linfa-svm (libsvm semantics) on small problems.

use std::collections::HashMap;

use linfa::prelude::*;
use linfa_svm::Svm;
use ndarray::{Array1, Array2};
use ridi_features::FeatureMatrixRef;
use ridi_regress::{Precompute, SmoSettings, SolverConfig, Svc, SvcParams, Svr, SvrParams};
use ridi_test_support::{blob_data, regression_data};

fn tight() -> SolverConfig {
    SolverConfig {
        smo: SmoSettings {
            tol: 1e-7,
            ..SmoSettings::default()
        },
        ..SolverConfig::default()
    }
}

fn rbf(a: &[f32], b: &[f32], gamma: f32) -> f64 {
    let d2: f64 = a.iter().zip(b).map(|(x, y)| ((x - y) as f64).powi(2)).sum();
    (-(gamma as f64) * d2).exp()
}

#[test]
fn two_point_classifier_matches_closed_form() {
    // One sample per class: alpha = min(C, 2 / (K11 + K22 - 2 K12)) = min(C, 1 / (1 - k)),
    // rho = 0 by symmetry, decision values ±alpha (1 - k).
    let x = [0.0f32, 0.5, 1.0, 1.0, 0.0, 0.2];
    let gamma = 0.4;
    let k = rbf(&x[..3], &x[3..], gamma);
    for c in [0.1, 1.0, 100.0] {
        let mut p = SvcParams::new(c, gamma);
        p.solver_config = tight();
        let m = Svc::fit(FeatureMatrixRef::new(&x, 3).unwrap(), &[7, 3], &p).unwrap();
        assert_eq!(m.labels(), &[3, 7]);
        let alpha = (1.0 / (1.0 - k)).min(c);
        let d = m
            .decision_function(FeatureMatrixRef::new(&x, 3).unwrap())
            .unwrap();
        // Class index 0 is label 3 (second row), positive side of the only pair.
        assert!((d[1] - alpha * (1.0 - k)).abs() < 1e-5, "C={c}: {d:?}");
        assert!((d[0] + alpha * (1.0 - k)).abs() < 1e-5, "C={c}: {d:?}");
        assert!(m.rho()[0].abs() < 1e-6);
        assert_eq!(
            m.predict(FeatureMatrixRef::new(&x, 3).unwrap()).unwrap(),
            vec![7, 3]
        );
    }
}

#[test]
fn machines_read_back_by_serde_are_checked() {
    let cfg = bincode::config::standard();
    fn round<T: serde::de::DeserializeOwned>(bytes: &[u8]) -> Option<T> {
        let cfg = bincode::config::standard();
        bincode::serde::decode_from_slice(bytes, cfg)
            .ok()
            .map(|(m, _)| m)
    }
    let x = [0.0f32, 0.5, 1.0, 1.0, 0.0, 0.2, 0.3, 0.3, 0.9];
    let xm = FeatureMatrixRef::new(&x, 3).unwrap();
    let svr = Svr::fit(xm, &[0.5, -0.5, 0.1], &SvrParams::new(1.0, 0.01, 0.4)).unwrap();
    let svc = Svc::fit(xm, &[7, 3, 9], &SvcParams::new(1.0, 0.4)).unwrap();
    let svr_bytes = bincode::serde::encode_to_vec(&svr, cfg).unwrap();
    let svc_bytes = bincode::serde::encode_to_vec(&svc, cfg).unwrap();
    let svr_back: Svr = round(&svr_bytes).unwrap();
    let svc_back: Svc = round(&svc_bytes).unwrap();
    assert_eq!(svr_back, svr);
    assert_eq!(svc_back, svc);
    assert_eq!(svc_back.predict(xm).unwrap(), svc.predict(xm).unwrap());
    // Any one byte changed is refused or still predicts: never a panic, never a NaN.
    for (bytes, is_svr) in [(&svr_bytes, true), (&svc_bytes, false)] {
        for at in 0..bytes.len() {
            for v in [0u8, 1, 0x7f, 0xff] {
                let mut b = bytes.clone();
                b[at] = v;
                if is_svr {
                    if let Some(m) = round::<Svr>(&b) {
                        assert!(m.predict(xm).is_ok_and(|p| p.iter().all(|v| v.is_finite())));
                    }
                } else if let Some(m) = round::<Svc>(&b) {
                    m.predict(xm).unwrap();
                }
            }
        }
    }
}

#[test]
fn a_label_per_row_beyond_the_class_bound_is_refused_before_any_fit() {
    // 100,000 distinct labels would be 5e9 one-vs-one machines: refused, not an abort.
    let n = 100_000;
    let x = vec![0.0f32; n];
    let y: Vec<usize> = (0..n).collect();
    let e = Svc::fit(
        FeatureMatrixRef::new(&x, 1).unwrap(),
        &y,
        &SvcParams::new(1.0, 1.0),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("100000 classes") && e.contains("at most 1000"),
        "{e}"
    );
}

#[test]
fn two_point_regressor_matches_closed_form() {
    // Targets ±t: coefficients ±beta with beta = min(C, (t - eps) / (1 - k)), rho = 0, and the
    // fit reaches the tube edge t - eps when beta is not clipped.
    let x = [0.0f32, 1.0, 0.3, -0.2];
    let gamma = 0.7;
    let k = rbf(&x[..2], &x[2..], gamma);
    let t = 1.0;
    for (c, eps) in [(100.0, 0.1), (0.5, 0.1), (10.0, 0.0)] {
        let mut p = SvrParams::new(c, eps, gamma);
        p.solver_config = tight();
        let m = Svr::fit(FeatureMatrixRef::new(&x, 2).unwrap(), &[t, -t], &p).unwrap();
        let beta = ((t - eps) / (1.0 - k)).min(c);
        let f = m.predict(FeatureMatrixRef::new(&x, 2).unwrap()).unwrap();
        assert!((f[0] - beta * (1.0 - k)).abs() < 1e-5, "C={c}: {f:?}");
        assert!((f[1] + beta * (1.0 - k)).abs() < 1e-5);
        assert!(m.rho().abs() < 1e-6);
        let mut coef = m.dual_coef().to_vec();
        coef.sort_by(f64::total_cmp);
        assert!((coef[0] + beta).abs() < 1e-6 && (coef[1] - beta).abs() < 1e-6);
    }
}

fn coef_by_row(sv: FeatureMatrixRef<'_>, coef: &[f64]) -> HashMap<Vec<u32>, f64> {
    (0..sv.rows())
        .map(|i| (sv.row(i).iter().map(|v| v.to_bits()).collect(), coef[i]))
        .collect()
}

#[test]
fn regressor_satisfies_kkt_conditions() {
    let (x, y) = regression_data(120, 10, 11);
    let xm = FeatureMatrixRef::new(&x, 10).unwrap();
    let (c, eps) = (3.0, 0.05);
    let mut p = SvrParams::new(c, eps, 0.2);
    p.solver_config = tight();
    let m = Svr::fit(xm, &y, &p).unwrap();
    assert!(m.info().converged);
    let coef = coef_by_row(m.support_vectors(), m.dual_coef());
    let f = m.predict(xm).unwrap();
    let sum: f64 = m.dual_coef().iter().sum();
    assert!(sum.abs() < 1e-9, "sum of coefficients {sum}");
    let tol = 1e-4;
    let (mut free, mut bounded) = (0, 0);
    for i in 0..120 {
        let a = coef
            .get(&xm.row(i).iter().map(|v| v.to_bits()).collect::<Vec<_>>())
            .copied()
            .unwrap_or(0.0);
        let r = y[i] - f[i];
        assert!(a.abs() <= c + 1e-12);
        if a == 0.0 {
            assert!(
                r.abs() <= eps + tol,
                "sample {i}: zero coef but residual {r}"
            );
        } else if a.abs() >= c {
            bounded += 1;
            assert!(
                r.abs() >= eps - tol && r.signum() == a.signum(),
                "sample {i}: {a} {r}"
            );
        } else {
            free += 1;
            assert!(
                (r.abs() - eps).abs() <= tol,
                "sample {i}: free but residual {r}"
            );
            assert_eq!(r.signum(), a.signum());
        }
    }
    assert!(free > 0, "degenerate test problem");
    let _ = bounded;
}

#[test]
fn classifier_satisfies_kkt_conditions() {
    let (x, y) = blob_data(40, 6, &[0, 1], 1.2, 5);
    let xm = FeatureMatrixRef::new(&x, 6).unwrap();
    let c = 2.0;
    let mut p = SvcParams::new(c, 0.3);
    p.solver_config = tight();
    let m = Svc::fit(xm, &y, &p).unwrap();
    let d = m.decision_function(xm).unwrap();
    let coef = coef_by_row(m.support_vectors(), m.dual_coef());
    let tol = 1e-4;
    let mut sum = 0.0;
    for i in 0..80 {
        let yi = if y[i] == 0 { 1.0 } else { -1.0 };
        let a = coef
            .get(&xm.row(i).iter().map(|v| v.to_bits()).collect::<Vec<_>>())
            .copied()
            .unwrap_or(0.0);
        sum += a;
        let margin = yi * d[i];
        if a == 0.0 {
            assert!(margin >= 1.0 - tol, "sample {i}: margin {margin}");
        } else if a.abs() >= c {
            assert!(
                margin <= 1.0 + tol,
                "sample {i}: bounded with margin {margin}"
            );
        } else {
            assert!(
                (margin - 1.0).abs() <= tol,
                "sample {i}: free with margin {margin}"
            );
        }
    }
    assert!(sum.abs() < 1e-9);
}

#[test]
fn regressor_matches_linfa_svm() {
    let (x, y) = regression_data(80, 8, 3);
    let xm = FeatureMatrixRef::new(&x, 8).unwrap();
    let (xt, _) = regression_data(30, 8, 4);
    let gamma = 0.25f32;
    for (c, eps) in [(1.0, 0.01), (10.0, 0.1), (0.1, 0.001)] {
        let mut p = SvrParams::new(c, eps, gamma);
        p.solver_config = tight();
        let ours = Svr::fit(xm, &y, &p).unwrap();
        let records = Array2::from_shape_fn((80, 8), |(i, j)| x[i * 8 + j] as f64);
        let targets = Array1::from_iter(y.iter().copied());
        let oracle = Svm::<f64, f64>::params()
            .c_svr(c, Some(eps))
            .eps(1e-9)
            .gaussian_kernel(1.0 / gamma as f64)
            .fit(&Dataset::new(records, targets))
            .unwrap();
        assert!(
            (ours.rho() - oracle.rho).abs() < 1e-4,
            "rho {} vs {}",
            ours.rho(),
            oracle.rho
        );
        let test = Array2::from_shape_fn((30, 8), |(i, j)| xt[i * 8 + j] as f64);
        let theirs = oracle.predict(&test);
        let mine = ours
            .predict(FeatureMatrixRef::new(&xt, 8).unwrap())
            .unwrap();
        for (a, b) in mine.iter().zip(theirs.iter()) {
            assert!((a - b).abs() < 2e-4, "C={c} eps={eps}: {a} vs {b}");
        }
    }
}

#[test]
fn classifier_matches_linfa_svm() {
    let (x, y) = blob_data(30, 5, &[0, 1], 1.0, 9);
    let xm = FeatureMatrixRef::new(&x, 5).unwrap();
    let gamma = 0.5f32;
    for c in [0.5, 10.0] {
        let mut p = SvcParams::new(c, gamma);
        p.solver_config = tight();
        let ours = Svc::fit(xm, &y, &p).unwrap();
        let records = Array2::from_shape_fn((60, 5), |(i, j)| x[i * 5 + j] as f64);
        // Class index 0 is the positive side, as in libsvm's first label.
        let targets = Array1::from_iter(y.iter().map(|&l| l == 0));
        let oracle = Svm::<f64, bool>::params()
            .pos_neg_weights(c, c)
            .eps(1e-9)
            .gaussian_kernel(1.0 / gamma as f64)
            .fit(&Dataset::new(records.clone(), targets))
            .unwrap();
        assert!((ours.rho()[0] - oracle.rho).abs() < 1e-4);
        let d = ours.decision_function(xm).unwrap();
        for (i, di) in d.iter().enumerate() {
            let theirs = oracle.weighted_sum(&records.row(i)) - oracle.rho;
            assert!(
                (di - theirs).abs() < 2e-4,
                "C={c} sample {i}: {di} vs {theirs}"
            );
        }
    }
}

#[test]
fn multiclass_separates_blobs_with_arbitrary_labels() {
    let labels = [5usize, 2, 9, 4];
    let (x, y) = blob_data(25, 8, &labels, 0.3, 21);
    let xm = FeatureMatrixRef::new(&x, 8).unwrap();
    let m = Svc::fit(xm, &y, &SvcParams::new(10.0, 0.5)).unwrap();
    assert_eq!(m.labels(), &[2, 4, 5, 9]);
    assert_eq!(m.predict(xm).unwrap(), y);
    let (xt, yt) = blob_data(10, 8, &labels, 0.3, 22);
    assert_eq!(
        m.predict(FeatureMatrixRef::new(&xt, 8).unwrap()).unwrap(),
        yt
    );
}

#[test]
fn cached_rows_and_full_kernel_give_the_same_model() {
    let (x, y) = regression_data(150, 12, 8);
    let xm = FeatureMatrixRef::new(&x, 12).unwrap();
    let mut full = SvrParams::new(5.0, 0.01, 0.1);
    full.solver_config = tight();
    let mut cached = full;
    cached.solver_config.regressor_kernel = Precompute::Never;
    // A cache of 20 rows forces evictions and batched recomputation.
    cached.solver_config.kernel_memory = 20 * 150 * 4;
    let a = Svr::fit(xm, &y, &full).unwrap();
    let b = Svr::fit(xm, &y, &cached).unwrap();
    let (pa, pb) = (a.predict(xm).unwrap(), b.predict(xm).unwrap());
    for (u, v) in pa.iter().zip(&pb) {
        assert!((u - v).abs() < 1e-4);
    }
    let mut p = SvcParams::new(1.0, 0.3);
    p.solver_config = tight();
    let (xc, yc) = blob_data(50, 6, &[1, 2, 3], 1.0, 2);
    let xcm = FeatureMatrixRef::new(&xc, 6).unwrap();
    let a = Svc::fit(xcm, &yc, &p).unwrap();
    p.solver_config.classifier_kernel = Precompute::Auto;
    let b = Svc::fit(xcm, &yc, &p).unwrap();
    let (da, db) = (
        a.decision_function(xcm).unwrap(),
        b.decision_function(xcm).unwrap(),
    );
    for (u, v) in da.iter().zip(&db) {
        assert!((u - v).abs() < 1e-4);
    }
}

#[test]
fn invalid_inputs_are_errors_not_panics() {
    let x = [0.0f32, 1.0, 2.0, 3.0];
    let xm = FeatureMatrixRef::new(&x, 2).unwrap();
    assert!(FeatureMatrixRef::new(&x, 3).is_err());
    assert!(FeatureMatrixRef::new(&[f32::NAN, 1.0], 2).is_err());
    assert!(Svr::fit(xm, &[1.0], &SvrParams::new(1.0, 0.1, 0.5)).is_err());
    assert!(Svr::fit(xm, &[1.0, 2.0], &SvrParams::new(-1.0, 0.1, 0.5)).is_err());
    assert!(Svr::fit(xm, &[1.0, 2.0], &SvrParams::new(1.0, -0.1, 0.5)).is_err());
    assert!(Svr::fit(xm, &[1.0, f64::INFINITY], &SvrParams::new(1.0, 0.1, 0.5)).is_err());
    assert!(Svc::fit(xm, &[1, 1], &SvcParams::new(1.0, 0.5)).is_err());
    let m = Svr::fit(xm, &[1.0, 2.0], &SvrParams::new(1.0, 0.1, 0.5)).unwrap();
    assert!(
        m.predict(FeatureMatrixRef::new(&[1.0, 2.0, 3.0], 3).unwrap())
            .is_err()
    );
}
