//! Kernel row providers for the solver: a precomputed full matrix, or a bounded LRU cache of
//! rows computed on demand (in batches, so that one pass over the samples serves many rows).

use std::ops::Deref;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use rayon::prelude::*;

use crate::kernel;
use ridi_features::FeatureMatrixRef;

/// One kernel row: `K(x_i, x_j)` for all `j` of the base sample set.
pub(crate) enum Row<'a> {
    Borrowed(&'a [f32]),
    Shared(Arc<[f32]>),
}

impl Deref for Row<'_> {
    type Target = [f32];
    fn deref(&self) -> &[f32] {
        match self {
            Row::Borrowed(s) => s,
            Row::Shared(a) => a,
        }
    }
}

/// Access to kernel rows of a base sample set. Solvers address variables through indices into
/// this base set, so one provider serves every fold, channel and grid point of a class.
pub(crate) trait KernelRows: Sync {
    /// Number of base samples (row length).
    fn len(&self) -> usize;
    /// Row `i`.
    fn row(&self, i: usize) -> Row<'_>;
    /// Whether row `i` is available without computation.
    fn is_cached(&self, _i: usize) -> bool {
        true
    }
    /// How many rows are worth computing together on a miss (0: no prefetching).
    fn batch_size(&self) -> usize {
        0
    }
    /// Computes and caches the listed rows in one pass.
    fn prefetch(&self, _rows: &[usize]) {}
}

/// Precomputed full kernel matrix.
pub(crate) struct FullKernel {
    n: usize,
    data: Vec<f32>,
}

impl FullKernel {
    pub(crate) fn new(x: FeatureMatrixRef<'_>, norms: &[f32], gamma: f32) -> Self {
        Self {
            n: x.rows(),
            data: kernel::gram(x, norms, gamma),
        }
    }

    /// The block of `rows` at base samples `idx` (rows and columns), as a kernel of its own.
    pub(crate) fn block(rows: &dyn KernelRows, idx: &[usize]) -> Self {
        let m = idx.len();
        let mut data = vec![0.0f32; m * m];
        let cols: Vec<u32> = idx.iter().map(|&i| i as u32).collect();
        data.par_chunks_mut(m.max(1))
            .zip(idx)
            .for_each(|(out, &i)| crate::smo::gather(&rows.row(i), &cols, out));
        Self { n: m, data }
    }

    /// Bytes needed for `n` samples.
    pub(crate) fn bytes_for(n: usize) -> u64 {
        (n as u64) * (n as u64) * 4
    }
}

impl KernelRows for FullKernel {
    fn len(&self) -> usize {
        self.n
    }
    fn row(&self, i: usize) -> Row<'_> {
        Row::Borrowed(&self.data[i * self.n..(i + 1) * self.n])
    }
}

const NIL: u32 = u32::MAX;

/// Intrusive doubly linked LRU list over slot indices (O(1) touch, insert, evict).
struct Lru {
    rows: Vec<Option<Arc<[f32]>>>,
    prev: Vec<u32>,
    next: Vec<u32>,
    head: u32,
    tail: u32,
    used: usize,
    capacity: usize,
}

impl Lru {
    fn new(n: usize, capacity: usize) -> Self {
        Self {
            rows: vec![None; n],
            prev: vec![NIL; n],
            next: vec![NIL; n],
            head: NIL,
            tail: NIL,
            used: 0,
            capacity,
        }
    }

    fn unlink(&mut self, i: u32) {
        let (p, n) = (self.prev[i as usize], self.next[i as usize]);
        if p == NIL {
            self.head = n;
        } else {
            self.next[p as usize] = n;
        }
        if n == NIL {
            self.tail = p;
        } else {
            self.prev[n as usize] = p;
        }
    }

    fn push_front(&mut self, i: u32) {
        self.prev[i as usize] = NIL;
        self.next[i as usize] = self.head;
        if self.head != NIL {
            self.prev[self.head as usize] = i;
        }
        self.head = i;
        if self.tail == NIL {
            self.tail = i;
        }
    }

    fn get(&mut self, i: usize) -> Option<Arc<[f32]>> {
        let row = self.rows[i].clone()?;
        self.unlink(i as u32);
        self.push_front(i as u32);
        Some(row)
    }

    fn insert(&mut self, i: usize, row: Arc<[f32]>) {
        if self.rows[i].is_some() {
            self.unlink(i as u32);
        } else {
            while self.used >= self.capacity && self.tail != NIL {
                let t = self.tail;
                self.unlink(t);
                self.rows[t as usize] = None;
                self.used -= 1;
            }
            self.used += 1;
        }
        self.rows[i] = Some(row);
        self.push_front(i as u32);
    }
}

/// Rows computed on demand and kept in a bounded LRU cache.
pub(crate) struct CachedKernel<'x> {
    x: FeatureMatrixRef<'x>,
    norms: Vec<f32>,
    gamma: f32,
    lru: Mutex<Lru>,
    batch: usize,
    hits: AtomicU64,
    computed: AtomicU64,
}

impl<'x> CachedKernel<'x> {
    /// `cap_bytes` bounds the cached rows (at least a few rows are always kept so that the
    /// two rows of a working pair coexist).
    pub(crate) fn new(x: FeatureMatrixRef<'x>, gamma: f32, cap_bytes: u64) -> Self {
        let n = x.rows();
        let row_bytes = (n.max(1) * 4) as u64;
        let capacity = ((cap_bytes / row_bytes) as usize).max(8);
        Self {
            x,
            norms: kernel::sq_norms(x),
            gamma,
            lru: Mutex::new(Lru::new(n, capacity)),
            batch: (capacity / 4).clamp(1, 64),
            hits: AtomicU64::new(0),
            computed: AtomicU64::new(0),
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Lru> {
        // A panic while holding the lock cannot leave the list half-updated in a way that
        // matters more than losing cached rows, so recover the guard.
        self.lru.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn compute(&self, rows: &[usize]) -> Vec<Arc<[f32]>> {
        let n = self.x.rows();
        let mut buf = vec![0.0f32; rows.len() * n];
        kernel::kernel_rows(self.x, &self.norms, rows, self.gamma, &mut buf);
        self.computed
            .fetch_add(rows.len() as u64, Ordering::Relaxed);
        buf.chunks_exact(n.max(1)).map(Arc::from).collect()
    }

    /// (rows served from cache, rows computed) so far.
    #[cfg_attr(not(test), allow(dead_code))]
    pub(crate) fn stats(&self) -> (u64, u64) {
        (
            self.hits.load(Ordering::Relaxed),
            self.computed.load(Ordering::Relaxed),
        )
    }
}

impl KernelRows for CachedKernel<'_> {
    fn len(&self) -> usize {
        self.x.rows()
    }

    fn row(&self, i: usize) -> Row<'_> {
        if let Some(r) = self.lock().get(i) {
            self.hits.fetch_add(1, Ordering::Relaxed);
            return Row::Shared(r);
        }
        let r = self.compute(&[i]).remove(0);
        self.lock().insert(i, r.clone());
        Row::Shared(r)
    }

    fn is_cached(&self, i: usize) -> bool {
        self.lock().rows[i].is_some()
    }

    fn batch_size(&self) -> usize {
        self.batch
    }

    fn prefetch(&self, rows: &[usize]) {
        let missing: Vec<usize> = {
            let lru = self.lock();
            rows.iter()
                .copied()
                .filter(|&i| lru.rows[i].is_none())
                .take(self.batch)
                .collect()
        };
        if missing.is_empty() {
            return;
        }
        let computed = self.compute(&missing);
        let mut lru = self.lock();
        for (i, r) in missing.into_iter().zip(computed) {
            lru.insert(i, r);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::matrix::{View as _, owned};

    #[test]
    fn cached_rows_equal_full_rows_and_eviction_is_bounded() {
        let v: Vec<f32> = (0..40 * 6).map(|k| (k as f32 * 0.7).cos()).collect();
        let x = owned(v, 6);
        let norms = kernel::sq_norms(x.view());
        let full = FullKernel::new(x.view(), &norms, 0.3);
        // Room for 8 rows of 40 floats.
        let cached = CachedKernel::new(x.view(), 0.3, 8 * 40 * 4);
        cached.prefetch(&[0, 1, 2, 3, 4, 5, 6, 7, 8, 9]);
        for i in [3, 0, 39, 17, 3, 22, 5, 3] {
            let (a, b) = (full.row(i), cached.row(i));
            for j in 0..40 {
                assert!((a[j] - b[j]).abs() < 1e-6);
            }
        }
        assert!(cached.lock().used <= 8);
        assert!(cached.is_cached(3), "recently used row was evicted");
        let (hits, computed) = cached.stats();
        // The prefetch is capped at a quarter of the capacity (rows 0 and 1); then 0 and the
        // repeated 3s hit, the other five rows are computed.
        assert_eq!((hits, computed), (3, 7));
    }

    #[test]
    fn block_is_the_sub_matrix() {
        let v: Vec<f32> = (0..30 * 4).map(|k| (k as f32 * 0.3).sin()).collect();
        let x = owned(v, 4);
        let full = FullKernel::new(x.view(), &kernel::sq_norms(x.view()), 0.5);
        let idx = [29, 3, 4, 17, 0];
        let block = FullKernel::block(&full, &idx);
        assert_eq!(block.len(), idx.len());
        for (a, &i) in idx.iter().enumerate() {
            let (r, f) = (block.row(a), full.row(i));
            for (b, &j) in idx.iter().enumerate() {
                assert_eq!(r[b], f[j]);
            }
        }
    }
}
