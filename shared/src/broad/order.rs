//! The canonical output order: pairs sorted by `(first id, second id)`.
//!
//! Work items produce pairs in whatever order their sweep meets them; this
//! module concatenates and sorts them so that the output depends only on the
//! set of pairs, never on how the work was split or which thread did what.
//! It is a one-pass bucket sort on the high bits of the first id. In parallel
//! (buckets of a few pairs) a sort of each bucket follows, split over
//! buckets; on one thread the pairs are scattered straight into the output
//! (buckets of about a quarter of a pair) and one insertion sort over the
//! whole output finishes it, falling back to a comparison sort if a crowded
//! bucket makes it shift too much. Every buffer is reused.

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
/// Buckets per pair of the one-thread sort: enough that a bucket rarely holds
/// two pairs, so the insertion sort over the whole output hardly moves
/// anything.
const BUCKETS_PER_PAIR_SERIAL: usize = 4;
/// Buckets filled per leaf task in the parallel fill.
const LEAF_PAIRS: usize = 4096;

/// Reused buffers of one output type.
#[derive(Debug, Default, Clone)]
pub(crate) struct Buffers<T> {
    /// One output buffer per work item.
    pub bufs: Vec<Vec<T>>,
    /// Bucket-grouped copy of each buffer.
    tmp: Vec<Vec<T>>,
    /// Per buffer, `buckets + 1` bucket starts.
    counts: Vec<u32>,
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

    /// Sorts the first `n` work buffers' pairs into `out` (cleared first).
    /// Ids lie in `id_lo..=id_hi`.
    pub fn finish(&mut self, n: usize, id_lo: u32, id_hi: u32, out: &mut Vec<T>, par: bool) {
        out.clear();
        let total: usize = self.bufs[..n].iter().map(Vec::len).sum();
        if total == 0 {
            return;
        }
        // Bucket = (first id - id_lo) >> shift. In parallel: about 2 pairs
        // per bucket on one buffer, 16 when there are several (each has its
        // counters); on one thread about a quarter of a pair.
        let want_bits = if par {
            let per_bucket = if n == 1 { 2 } else { 16 };
            (total / per_bucket).max(1).ilog2()
        } else {
            (total * BUCKETS_PER_PAIR_SERIAL).ilog2()
        }
        .min(MAX_BUCKET_BITS);
        let span = id_hi.saturating_sub(id_lo);
        let span_bits = 32 - span.leading_zeros();
        let shift = span_bits.saturating_sub(want_bits);
        let nbk = (span >> shift) as usize + 1;
        if !par {
            self.finish_serial(n, id_lo, shift, nbk, total, out);
            return;
        }
        if self.tmp.len() < n {
            self.tmp.resize_with(n, Vec::new);
        }
        self.counts.clear();
        self.counts.resize(n * (nbk + 1), 0);
        let bucket = move |t: &T| ((t.ids().0.wrapping_sub(id_lo)) >> shift) as usize;
        let group = |(buf, (tmp, counts)): (&mut Vec<T>, (&mut Vec<T>, &mut [u32]))| {
            for t in buf.iter() {
                counts[bucket(t) + 1] += 1;
            }
            for b in 0..nbk {
                counts[b + 1] += counts[b];
            }
            tmp.clear();
            tmp.resize(buf.len(), T::default());
            // counts[b] is now the start of bucket b; advance it while
            // filling, then shift back so counts[b]..counts[b + 1] is bucket b.
            for t in buf.iter() {
                let b = bucket(t);
                tmp[counts[b] as usize] = *t;
                counts[b] += 1;
            }
            for b in (1..=nbk).rev() {
                counts[b] = counts[b - 1];
            }
            counts[0] = 0;
        };
        let bufs = &mut self.bufs[..n];
        let tmps = &mut self.tmp[..n];
        if par {
            use rayon::prelude::*;
            bufs.par_iter_mut()
                .zip(tmps.par_iter_mut().zip(self.counts.par_chunks_mut(nbk + 1)))
                .for_each(group);
        } else {
            bufs.iter_mut()
                .zip(tmps.iter_mut().zip(self.counts.chunks_mut(nbk + 1)))
                .for_each(group);
        }
        // Bucket starts in the output.
        self.starts.clear();
        self.starts.resize(nbk + 1, 0);
        for w in 0..n {
            let c = &self.counts[w * (nbk + 1)..(w + 1) * (nbk + 1)];
            for b in 0..nbk {
                self.starts[b + 1] += c[b + 1] - c[b];
            }
        }
        for b in 0..nbk {
            self.starts[b + 1] += self.starts[b];
        }
        out.resize(total, T::default());
        let ctx = Fill {
            tmp: &self.tmp[..n],
            counts: &self.counts,
            starts: &self.starts,
            stride: nbk + 1,
        };
        if par {
            ctx.fill_par(out, 0, nbk);
        } else {
            ctx.fill(out, 0, nbk);
        }
    }
}

impl<T: Keyed> Buffers<T> {
    /// [`Self::finish`] on this thread: one histogram over every buffer, a
    /// scatter straight into `out` (no intermediate copy), then one bounded
    /// insertion sort over the whole of `out`.
    fn finish_serial(
        &mut self,
        n: usize,
        id_lo: u32,
        shift: u32,
        nbk: usize,
        total: usize,
        out: &mut Vec<T>,
    ) {
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

/// Sorts a bucket by ids: an insertion sort for the usual handful of pairs.
#[inline]
fn sort_small<T: Keyed>(v: &mut [T]) {
    if v.len() > 24 {
        v.sort_unstable_by_key(Keyed::key);
        return;
    }
    for i in 1..v.len() {
        let x = v[i];
        let k = x.key();
        let mut j = i;
        while j > 0 && v[j - 1].key() > k {
            v[j] = v[j - 1];
            j -= 1;
        }
        v[j] = x;
    }
}

/// What the fill step reads.
struct Fill<'a, T> {
    tmp: &'a [Vec<T>],
    counts: &'a [u32],
    starts: &'a [u32],
    stride: usize,
}

impl<T: Keyed> Fill<'_, T> {
    /// Fills buckets `b0..b1` into `out` (which starts at bucket `b0`) and
    /// sorts each.
    fn fill(&self, out: &mut [T], b0: usize, b1: usize) {
        let base = self.starts[b0] as usize;
        for b in b0..b1 {
            let s = self.starts[b] as usize - base;
            let e = self.starts[b + 1] as usize - base;
            let mut at = s;
            for (w, tmp) in self.tmp.iter().enumerate() {
                let c = &self.counts[w * self.stride..];
                let seg = &tmp[c[b] as usize..c[b + 1] as usize];
                out[at..at + seg.len()].copy_from_slice(seg);
                at += seg.len();
            }
            sort_small(&mut out[s..e]);
        }
    }

    /// The same, splitting the bucket range over the rayon pool.
    fn fill_par(&self, out: &mut [T], b0: usize, b1: usize) {
        let len = (self.starts[b1] - self.starts[b0]) as usize;
        if len <= LEAF_PAIRS || b1 - b0 < 2 {
            self.fill(out, b0, b1);
            return;
        }
        let mid = (b0 + b1) / 2;
        let (left, right) = out.split_at_mut((self.starts[mid] - self.starts[b0]) as usize);
        rayon::join(
            || self.fill_par(left, b0, mid),
            || self.fill_par(right, mid, b1),
        );
    }
}
