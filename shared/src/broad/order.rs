//! The canonical output order: pairs sorted by `(first id, second id)`.
//!
//! Work items produce pairs in whatever order their sweep meets them; this
//! module concatenates and sorts them so that the output depends only on the
//! set of pairs, never on how the work was split or which thread did what.
//! It is a one-pass bucket sort on the high bits of the first id: the pairs
//! are scattered straight into the output (buckets of about a quarter of a
//! pair) and one insertion sort over the whole output finishes it, falling
//! back to a comparison sort if a crowded bucket makes it shift too much.
//! Every buffer is reused.
//!
//! It runs on one thread even for the parallel paths: a parallel bucket
//! sort (a histogram per buffer, then each bucket sorted on the pool) took
//! 300-540 µs for the 23,000 pairs of 100,000 boxes against 160-200 µs for
//! this one, which is cheap next to the search that found them.

use glam::IVec2;

/// An output element keyed by its two ids.
pub(crate) trait Keyed: Copy + Default + Send + Sync {
    /// `(first id, second id)`, the sort key.
    fn ids(&self) -> (u32, u32);

    /// The sort key as one integer, `first << 32 | second`: one compare
    /// instead of a lexicographic pair of them.
    #[inline(always)]
    fn key(&self) -> u64 {
        let (a, b) = self.ids();
        ((a as u64) << 32) | b as u64
    }
}

impl Keyed for (u32, u32) {
    #[inline(always)]
    fn ids(&self) -> (u32, u32) {
        *self
    }
}

impl Keyed for (u32, u32, IVec2) {
    #[inline(always)]
    fn ids(&self) -> (u32, u32) {
        (self.0, self.1)
    }
}

/// Buckets of the sort (more is faster to sort, slower to count).
const MAX_BUCKET_BITS: u32 = 16;
/// Buckets per pair: enough that a bucket rarely holds two pairs, so the
/// insertion sort over the whole output hardly moves anything.
const BUCKETS_PER_PAIR: usize = 4;

/// Reused buffers of one output type.
#[derive(Debug, Default, Clone)]
pub(crate) struct Buffers<T> {
    /// One output buffer per work item.
    pub bufs: Vec<Vec<T>>,
    /// Start of each bucket in the output (`buckets + 1`).
    starts: Vec<u32>,
}

impl<T: Keyed> Buffers<T> {
    /// Makes sure there are `n` cleared work buffers.
    pub fn prepare(&mut self, n: usize) {
        if self.bufs.len() < n {
            self.bufs.resize_with(n, Vec::new);
        }
        for b in &mut self.bufs[..n] {
            b.clear();
        }
    }

    /// Sorts the first `n` work buffers' pairs into `out` (cleared first):
    /// one histogram over every buffer, a scatter straight into `out` (no
    /// intermediate copy), then one bounded insertion sort over the whole of
    /// `out`. Ids lie in `id_lo..=id_hi`.
    pub fn finish(&mut self, n: usize, id_lo: u32, id_hi: u32, out: &mut Vec<T>) {
        out.clear();
        let total: usize = self.bufs[..n].iter().map(Vec::len).sum();
        if total == 0 {
            return;
        }
        // Bucket = (first id - id_lo) >> shift.
        let want_bits = (total * BUCKETS_PER_PAIR).ilog2().min(MAX_BUCKET_BITS);
        let span = id_hi.saturating_sub(id_lo);
        let span_bits = 32 - span.leading_zeros();
        let shift = span_bits.saturating_sub(want_bits);
        let nbk = (span >> shift) as usize + 1;
        let bucket = move |t: &T| ((t.ids().0.wrapping_sub(id_lo)) >> shift) as usize;
        let starts = &mut self.starts;
        starts.clear();
        starts.resize(nbk + 1, 0);
        for buf in &self.bufs[..n] {
            for t in buf {
                starts[bucket(t) + 1] += 1;
            }
        }
        // Running sum in a register (a loop over `starts[b]` would wait on
        // its own store at every bucket).
        let mut acc = 0;
        for c in starts.iter_mut() {
            acc += *c;
            *c = acc;
        }
        // `starts[b]` is now where bucket `b` starts; it becomes the next
        // free slot of the bucket as the pairs go in.
        out.resize(total, T::default());
        for buf in &self.bufs[..n] {
            for t in buf {
                let b = bucket(t);
                out[starts[b] as usize] = *t;
                starts[b] += 1;
            }
        }
        // Buckets hold about a quarter of a pair each: one insertion sort
        // over the whole output only ever moves a pair within its bucket,
        // and costs no loop over the buckets.
        sort_nearly_sorted(out);
    }
}

/// Sorts `v` by ids, fast when every element is near its place: an
/// insertion sort, abandoned for a comparison sort once it has shifted
/// more than a few elements per element (a crowded bucket).
fn sort_nearly_sorted<T: Keyed>(v: &mut [T]) {
    sort_nearly_sorted_by_key(v, 4, Keyed::key);
}

/// Sorts `v` by `key` with an insertion sort, linear when every element is
/// near its place, falling back to a comparison sort past `shifts` shifts
/// per element.
pub(crate) fn sort_nearly_sorted_by_key<T: Copy, K: Ord>(
    v: &mut [T],
    shifts: usize,
    key: impl Fn(&T) -> K,
) {
    let budget = shifts * v.len() + 64;
    let mut steps = 0;
    for i in 1..v.len() {
        let x = v[i];
        let k = key(&x);
        let mut j = i;
        while j > 0 && key(&v[j - 1]) > k {
            v[j] = v[j - 1];
            j -= 1;
        }
        v[j] = x;
        steps += i - j;
        if steps > budget {
            v.sort_unstable_by_key(key);
            return;
        }
    }
}
