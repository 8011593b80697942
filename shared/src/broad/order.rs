//! The canonical output order: pairs sorted by `(first id, second id)`.
//!
//! Work items produce pairs in whatever order their sweep meets them; this
//! module sorts them so that the output depends only on the set of pairs,
//! never on how the work was split or which thread did what.
//!
//! The id range is cut into *parts* (one on one thread, a few per thread in
//! parallel): a work item pushes each pair straight into the buffer of its
//! part, so the parts can then be sorted independently, each into its own
//! slice of the output, on as many threads as there are. A part is sorted
//! by a one-pass bucket sort on the high bits of the first id: the pairs
//! are scattered straight into the output (buckets of about a quarter of a
//! pair) and one insertion sort over the part finishes it, falling back to
//! a comparison sort if a crowded bucket makes it shift too much. Every
//! buffer is reused.
//!
//! With one part the sort took 160-200 µs for the 23,000 pairs of 100,000
//! boxes, on one thread whatever the pool: the largest serial step of the
//! parallel path. (A parallel bucket sort over one buffer per work item, a
//! histogram per buffer and each bucket sorted on the pool, took 300-540 µs:
//! too many small tasks.)

use super::isa::Isa;
use glam::IVec2;
use rayon::join;

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

/// Buckets of a part's sort (more is faster to sort, slower to count).
const MAX_BUCKET_BITS: u32 = 16;
/// Buckets per pair: enough that a bucket rarely holds two pairs, so the
/// insertion sort over a part hardly moves anything.
const BUCKETS_PER_PAIR: usize = 4;

/// Fewest pairs sorted in parallel: below, the joins cost more than the
/// sort (about 12 µs for the 2,350 pairs of N = 10,000 on one thread).
const PAR_SORT_MIN: usize = 4096;

/// How first ids map to parts: part `(id - id_lo) >> shift`.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct Split {
    /// Number of parts.
    pub parts: usize,
    id_lo: u32,
    id_hi: u32,
    /// Up to 32, hence applied to a `u64`.
    shift: u32,
}

impl Split {
    /// At most `want` parts (at least one) over the ids `id_lo..=id_hi`.
    fn new(want: usize, id_lo: u32, id_hi: u32) -> Self {
        let span = id_hi.saturating_sub(id_lo);
        let span_bits = 32 - span.leading_zeros();
        let shift = span_bits.saturating_sub(want.max(1).ilog2());
        Self {
            parts: ((span as u64 >> shift) + 1) as usize,
            id_lo,
            id_hi,
            shift,
        }
    }

    /// The part of first id `id`.
    #[inline(always)]
    fn part(&self, id: u32) -> usize {
        (id.wrapping_sub(self.id_lo) as u64 >> self.shift) as usize
    }

    /// The ids of part `p`.
    fn ids(&self, p: usize) -> (u32, u32) {
        let lo = self.id_lo as u64 + ((p as u64) << self.shift);
        let hi = (lo + (1u64 << self.shift) - 1).min(self.id_hi as u64);
        (lo as u32, hi as u32)
    }
}

/// One work item's output: a buffer per part.
pub(crate) struct Parts<'a, T> {
    bufs: &'a mut [Vec<T>],
    split: Split,
}

impl<'a, T: Keyed> Parts<'a, T> {
    /// The buffers of one work item (`split.parts` of them).
    pub fn new(bufs: &'a mut [Vec<T>], split: Split) -> Self {
        Self { bufs, split }
    }

    /// Adds `t` to its part.
    #[inline(always)]
    pub fn push(&mut self, t: T) {
        self.bufs[self.split.part(t.ids().0)].push(t);
    }
}

/// Reused buffers of one output type.
#[derive(Debug, Default, Clone)]
pub(crate) struct Buffers<T> {
    /// One output buffer per work item and part: `bufs[w * parts + p]`.
    bufs: Vec<Vec<T>>,
    /// Work items of the current run.
    items: usize,
    split: Split,
    /// Per part: the start of each bucket in the part's output.
    starts: Vec<Vec<u32>>,
}

impl<T: Keyed> Buffers<T> {
    /// Makes sure there are cleared buffers for `items` work items, each cut
    /// into at most `parts` parts of the ids `id_lo..=id_hi`; returns them,
    /// `split.parts` per work item, and how ids map to them.
    pub fn prepare(
        &mut self,
        items: usize,
        parts: usize,
        id_lo: u32,
        id_hi: u32,
    ) -> (&mut [Vec<T>], Split) {
        self.split = Split::new(parts, id_lo, id_hi);
        self.items = items;
        let n = items * self.split.parts;
        if self.bufs.len() < n {
            self.bufs.resize_with(n, Vec::new);
        }
        for b in &mut self.bufs[..n] {
            b.clear();
        }
        if self.starts.len() < self.split.parts {
            self.starts.resize_with(self.split.parts, Vec::new);
        }
        (&mut self.bufs[..n], self.split)
    }

    /// Sorts the pairs of the prepared buffers into `out` (replacing its
    /// contents), each part on its own (on the current rayon pool with
    /// `par`, when there are enough pairs to pay for it), with the `isa`
    /// versions of the sort.
    pub fn finish(&mut self, out: &mut Vec<T>, par: bool, isa: Isa) {
        let (split, items) = (self.split, self.items);
        let bufs = &self.bufs[..items * split.parts];
        let total: usize = bufs.iter().map(Vec::len).sum();
        // Every element is overwritten by the sort: whatever `out` held is
        // kept where it fits rather than cleared and filled again (a serial
        // write of the whole output, 370 KB at N = 100,000); `resize` only
        // truncates, or fills the new tail.
        out.resize(total, T::default());
        let all = Whole { bufs, split, isa };
        let par = par && total >= PAR_SORT_MIN;
        all.sort(0..split.parts, out, &mut self.starts[..split.parts], par);
    }
}

/// Every work item's buffers, read by the part sorts.
#[derive(Clone, Copy)]
struct Whole<'a, T> {
    bufs: &'a [Vec<T>],
    split: Split,
    /// Which versions of [`sort_part`] run.
    isa: Isa,
}

impl<T: Keyed> Whole<'_, T> {
    /// The buffers of part `p`, one per work item.
    fn of(&self, p: usize) -> impl Iterator<Item = &Vec<T>> + '_ {
        self.bufs.iter().skip(p).step_by(self.split.parts)
    }

    /// Sorts `parts` into `out` (exactly their size), halving the range
    /// over the pool with `par`.
    fn sort(
        &self,
        parts: core::ops::Range<usize>,
        out: &mut [T],
        starts: &mut [Vec<u32>],
        par: bool,
    ) {
        if parts.len() == 1 {
            return sort_part(self.isa, self, parts.start, out, &mut starts[0]);
        }
        let mid = parts.start + parts.len() / 2;
        let left: usize = (parts.start..mid)
            .flat_map(|p| self.of(p))
            .map(Vec::len)
            .sum();
        let (lo, hi) = out.split_at_mut(left);
        let (s_lo, s_hi) = starts.split_at_mut(mid - parts.start);
        if par {
            join(
                || self.sort(parts.start..mid, lo, s_lo, par),
                || self.sort(mid..parts.end, hi, s_hi, par),
            );
        } else {
            self.sort(parts.start..mid, lo, s_lo, par);
            self.sort(mid..parts.end, hi, s_hi, par);
        }
    }

    /// Sorts part `p` into `out`: one histogram over its buffers, a scatter
    /// straight into `out` (no intermediate copy), then one bounded
    /// insertion sort.
    #[inline(always)]
    fn sort_part(&self, p: usize, out: &mut [T], starts: &mut Vec<u32>) {
        if out.is_empty() {
            return;
        }
        let (id_lo, id_hi) = self.split.ids(p);
        // Bucket = (first id - id_lo) >> shift.
        let want_bits = (out.len() * BUCKETS_PER_PAIR).ilog2().min(MAX_BUCKET_BITS);
        let span = id_hi.saturating_sub(id_lo);
        let span_bits = 32 - span.leading_zeros();
        let shift = span_bits.saturating_sub(want_bits);
        let nbk = (span >> shift) as usize + 1;
        let bucket = move |t: &T| ((t.ids().0.wrapping_sub(id_lo)) >> shift) as usize;
        starts.clear();
        starts.resize(nbk + 1, 0);
        for buf in self.of(p) {
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
        for buf in self.of(p) {
            for t in buf {
                let b = bucket(t);
                out[starts[b] as usize] = *t;
                starts[b] += 1;
            }
        }
        // Buckets hold about a quarter of a pair each: one insertion sort
        // over the part only ever moves a pair within its bucket, and costs
        // no loop over the buckets.
        sort_nearly_sorted(out);
    }
}

multiversioned! {
    /// [`Whole::sort_part`], in the version `isa` picks.
    fn sort_part<T: Keyed>(w: &Whole<'_, T>, p: usize, out: &mut [T], starts: &mut Vec<u32>) {
        w.sort_part(p, out, starts)
    }
}

/// Sorts `v` by ids, fast when every element is near its place: an
/// insertion sort, abandoned for a comparison sort once it has shifted
/// more than a few elements per element (a crowded bucket).
#[inline(always)]
fn sort_nearly_sorted<T: Keyed>(v: &mut [T]) {
    sort_nearly_sorted_by_key(v, 4, Keyed::key);
}

/// Sorts `v` by `key` with an insertion sort, linear when every element is
/// near its place, falling back to a comparison sort past `shifts` shifts
/// per element. Inlined, so that it is part of each target's version of
/// its callers.
#[inline(always)]
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_cover_the_ids_in_order() {
        for (want, lo, hi) in [
            (1, 0, u32::MAX),
            (8, 0, u32::MAX),
            (8, 5, 5),
            (8, 3, 9),
            (32, 100, 1_000_000),
            (3, u32::MAX - 10, u32::MAX),
        ] {
            let s = Split::new(want, lo, hi);
            assert!(
                (1..=want.max(1)).contains(&s.parts),
                "{want} {lo} {hi}: {s:?}"
            );
            let mut next = lo as u64;
            for p in 0..s.parts {
                let (a, b) = s.ids(p);
                assert_eq!(a as u64, next, "part {p} starts where the last ended");
                assert!(a <= b);
                assert_eq!((s.part(a), s.part(b)), (p, p));
                next = b as u64 + 1;
            }
            assert_eq!(next, hi as u64 + 1, "the parts end at the last id");
        }
    }

    #[test]
    fn parts_sort_like_one_sort() {
        // Pairs from several work items, first ids all over the range and
        // crowded near both ends; every part count gives the one order.
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let pairs: Vec<(u32, u32)> = (0..2 * PAR_SORT_MIN)
            .map(|k| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                let a = match k % 3 {
                    0 => x as u32,
                    1 => (x % 50) as u32,
                    _ => u32::MAX - (x % 50) as u32,
                };
                (a, (x >> 32) as u32)
            })
            .collect();
        let mut expect = pairs.clone();
        expect.sort_unstable();
        let (lo, hi) = (expect[0].0, expect[expect.len() - 1].0);
        for (parts, items) in [(1, 1), (4, 3), (32, 7)] {
            let runs = [false, true].map(|par| [(par, Isa::Best), (par, Isa::Baseline)]);
            for (par, isa) in runs.into_iter().flatten() {
                let mut b = Buffers::default();
                let (bufs, split) = b.prepare(items, parts, lo, hi);
                for (k, t) in pairs.iter().enumerate() {
                    let w = k % items;
                    Parts::new(&mut bufs[w * split.parts..(w + 1) * split.parts], split).push(*t);
                }
                let mut out = vec![(7, 7)];
                b.finish(&mut out, par, isa);
                assert_eq!(
                    out, expect,
                    "{parts} parts, {items} items, par {par}, {isa:?}"
                );
            }
        }
    }
}
