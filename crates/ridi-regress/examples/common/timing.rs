//! One-query timing helpers shared by the timing examples (`svr_timing` here, and
//! `query_timing` of the `ridi` crate, which includes this file by path).

use std::time::Instant;

use ridi_features::FeatureMatrixRef;
use ridi_regress::Cascade;

/// Peak resident memory of the process, MB (`VmHWM`).
pub(crate) fn peak_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

/// CPU time of the calling thread, seconds (`/proc/thread-self/schedstat`).
pub(crate) fn thread_cpu_s() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(f64::NAN, |ns| ns * 1e-9)
}

/// Times `predict_one` over `rows` (in that order) on the calling thread: (wall, CPU) seconds
/// per query.
pub(crate) fn time_one(
    model: &Cascade,
    q: FeatureMatrixRef<'_>,
    rows: &[usize],
) -> Result<(f64, f64), String> {
    let (t, c) = (Instant::now(), thread_cpu_s());
    for &i in rows {
        std::hint::black_box(model.predict_one(q.row(i)).map_err(|e| e.to_string())?);
    }
    let n = rows.len() as f64;
    Ok((t.elapsed().as_secs_f64() / n, (thread_cpu_s() - c) / n))
}

/// `0..n` in a fixed pseudo-random order (xorshift Fisher-Yates: the same order every run).
pub(crate) fn shuffled(n: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..n).collect();
    let mut s = 0x2545_f491_4f6c_dd1du64;
    for i in (1..n).rev() {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        order.swap(i, (s % (i as u64 + 1)) as usize);
    }
    order
}
