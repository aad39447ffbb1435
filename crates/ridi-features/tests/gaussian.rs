//! Gaussian smoothing against hand-derived values of scipy's definition.

use ridi_features::{gaussian_filter1d, gaussian_kernel};
use ridi_test_support::naive_smooth;

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

#[test]
fn sigma_two_kernel_by_hand() {
    let k = gaussian_kernel(2.0, 4.0).unwrap();
    assert_eq!(k.len(), 17);
    // exp(-x^2 / 8) for x = -8..=8, normalized.
    let raw: Vec<f64> = (-8..=8)
        .map(|x: i32| (-(x * x) as f64 / 8.0).exp())
        .collect();
    let s: f64 = raw.iter().sum();
    for (a, b) in k.iter().zip(&raw) {
        assert!(close(*a, b / s, 1e-15), "{a} vs {}", b / s);
    }
    // The centre tap of sigma 2 is about 1 / (sigma sqrt(2 pi)) = 0.19947 (truncation adds a
    // little mass back through the normalization).
    assert!((k[8] - 0.199_471).abs() < 1e-4, "{}", k[8]);
    assert!((k.iter().sum::<f64>() - 1.0).abs() < 1e-15);
}

#[test]
fn impulse_reproduces_the_kernel() {
    let k = gaussian_kernel(2.0, 4.0).unwrap();
    let mut x = vec![0.0; 41];
    x[20] = 1.0;
    let y = gaussian_filter1d(&x, 2.0, 4.0).unwrap();
    for (i, v) in y.iter().enumerate() {
        let expected = if (12..=28).contains(&i) {
            k[i - 12]
        } else {
            0.0
        };
        assert!(close(*v, expected, 1e-15), "{i}: {v} vs {expected}");
    }
}

#[test]
fn constant_stays_constant() {
    for n in [1, 2, 3, 7, 16, 17, 100] {
        let x = vec![3.25; n];
        let y = gaussian_filter1d(&x, 2.0, 4.0).unwrap();
        assert!(y.iter().all(|v| close(*v, 3.25, 1e-14)), "n {n}: {y:?}");
    }
}

#[test]
fn ramp_is_preserved_in_the_interior() {
    // A symmetric kernel maps a linear function to itself wherever no border is involved.
    let x: Vec<f64> = (0..60).map(|i| 0.5 * i as f64 - 3.0).collect();
    let y = gaussian_filter1d(&x, 2.0, 4.0).unwrap();
    for i in 8..52 {
        assert!(close(y[i], x[i], 1e-13), "{i}: {} vs {}", y[i], x[i]);
    }
    // At the border the reflection bends the ramp: y[0] > x[0] because the mirrored values
    // x[-1] = x[0], x[-2] = x[1], ... are all >= x[0].
    assert!(y[0] > x[0] + 0.1);
}

#[test]
fn border_values_by_the_reflect_rule() {
    // x = [1, 2, 3, ...]; 'reflect' gives x[-j] = x[j - 1]. With a ramp x[i] = i + 1:
    // y[0] = sum_j w_j x[reflect(j)] = sum_{j>=0} w_j (j + 1) + sum_{j<0} w_j (-j).
    let k = gaussian_kernel(2.0, 4.0).unwrap();
    let x: Vec<f64> = (1..=30).map(f64::from).collect();
    let y = gaussian_filter1d(&x, 2.0, 4.0).unwrap();
    let mut y0 = 0.0;
    for (idx, w) in k.iter().enumerate() {
        let j = idx as i64 - 8;
        y0 += w * if j >= 0 { (j + 1) as f64 } else { (-j) as f64 };
    }
    assert!(close(y[0], y0, 1e-14), "{} vs {y0}", y[0]);
    // Last sample: x[n - 1 + j] = x[n - j] for j >= 1, i.e. value n - j + 1 with x[i] = i + 1.
    let n = 30i64;
    let mut yl = 0.0;
    for (idx, w) in k.iter().enumerate() {
        let j = idx as i64 - 8;
        yl += w * if j <= 0 {
            (n + j) as f64
        } else {
            (n - j + 1) as f64
        };
    }
    assert!(close(y[29], yl, 1e-14), "{} vs {yl}", y[29]);
}

#[test]
fn short_signals_use_repeated_reflection() {
    // n = 3 with radius 8: the extension of [a b c] is periodic with period 6:
    // ... c b a | a b c | c b a | a b c ...
    let x = [1.0, 10.0, 100.0];
    let k = gaussian_kernel(2.0, 4.0).unwrap();
    let y = gaussian_filter1d(&x, 2.0, 4.0).unwrap();
    let period = [1.0, 10.0, 100.0, 100.0, 10.0, 1.0];
    for i in 0..3i64 {
        let mut e = 0.0;
        for (idx, w) in k.iter().enumerate() {
            let p = (i + idx as i64 - 8).rem_euclid(6) as usize;
            e += w * period[p];
        }
        assert!(
            close(y[i as usize], e, 1e-14),
            "{i}: {} vs {e}",
            y[i as usize]
        );
    }
    assert!(gaussian_filter1d(&[], 2.0, 4.0).unwrap().is_empty());
    assert!(close(
        gaussian_filter1d(&[5.0], 2.0, 4.0).unwrap()[0],
        5.0,
        1e-15
    ));
}

#[test]
fn agrees_with_the_padded_reference() {
    let x: Vec<f64> = (0..500)
        .map(|i| ((i * 37 % 101) as f64 * 0.37).sin() * 3.0)
        .collect();
    for (sigma, n) in [(2.0, 500), (30.0, 500), (30.0, 100), (0.7, 9), (5.0, 2)] {
        let y = gaussian_filter1d(&x[..n], sigma, 4.0).unwrap();
        let r = naive_smooth(&x[..n], sigma, 4.0);
        for (a, b) in y.iter().zip(&r) {
            assert!(close(*a, *b, 1e-13), "sigma {sigma} n {n}: {a} vs {b}");
        }
    }
}
