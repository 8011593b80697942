//! The spatial partition: boxes sorted into horizontal strips, one set of
//! strips per size level, each strip sorted by left edge.
//!
//! A box lives in the strip of its level that holds its top edge, at the
//! place its left edge sorts to. Sorting is by one `u64` key,
//! `level << 60 | strip << 32 | (min.x as u32 ^ 1 << 31)`, so a whole set is
//! one sorted array (kept as parallel arrays, SoA) and a strip is a run of
//! it. Strips are unbounded in x and the key covers the full `i32` range in
//! y, so no world size is configured and no hash map is needed.
//!
//! A box of size `w x h` lives on the finest level whose strip height `S`
//! satisfies `max(w, h) <= S`. Two boxes of one level can only overlap when
//! their strips are equal or adjacent (both are at most one strip tall), and
//! in a strip sorted by left edge each box only has to look forward while the
//! next left edge is left of its right edge: a sweep. Boxes of different
//! levels are found by the larger box querying the strips of the smaller
//! box's level that it can reach.
//!
//! In the arrays every strip is followed by a *sentinel* entry whose left
//! edge is `i32::MAX`, and the arrays end with [`PAD`] more: a forward scan
//! (`while minx[k] < x`) stops at the end of its strip with no index test,
//! and fixed blocks of [`BLOCK`] entries can be read anywhere in a strip.

use super::bounds::Bounds;
use super::isa::Isa;
use core::ops::Range;
use wide::i32x4;

/// Most levels a set can have (the level is 4 bits of the key).
pub(crate) const MAX_LEVELS: usize = 16;
/// Entries tested at once by the block kernels.
pub(crate) const BLOCK: usize = 4;
/// Sentinels after the last strip's sentinel, so that four blocks read from
/// any entry stay in bounds.
pub(crate) const PAD: usize = 4 * BLOCK;
/// The left edge of a sentinel.
pub(crate) const SENTINEL: i32 = i32::MAX;

/// Strip geometry shared by every set of one broad phase.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Levels {
    /// `log2` of each level's strip height; the last is 32 (one strip).
    pub shift: [u32; MAX_LEVELS],
    /// Number of levels in use.
    pub count: usize,
}

impl Levels {
    /// Levels from `base` (`log2` of the finest strip height, at least 4)
    /// growing by `step` bits per level until one strip covers every `i32`.
    pub fn new(base: u32, step: u32) -> Self {
        let base = base.clamp(4, 32);
        let step = step.clamp(1, 28);
        let mut shift = [32; MAX_LEVELS];
        let mut count = 0;
        let mut s = base;
        while count < MAX_LEVELS {
            shift[count] = s.min(32);
            count += 1;
            if s >= 32 {
                break;
            }
            s += step;
        }
        // Whatever happens, the last level in use holds everything.
        shift[count - 1] = 32;
        Self { shift, count }
    }

    /// The level of a box whose larger side is `h` (units, `h < 2^32`).
    #[inline(always)]
    pub fn level_of(&self, h: i64) -> usize {
        if h <= 1i64 << self.shift[0] {
            return 0;
        }
        let mut l = 1;
        while l + 1 < self.count && h > 1i64 << self.shift[l] {
            l += 1;
        }
        l
    }

    /// The strip of coordinate `y` on level `l`: `floor((y + 2^31) / S)`, in
    /// `[0, 2^(32 - shift))`; `y` is clamped into the `i32` range first.
    #[inline(always)]
    pub fn strip(&self, l: usize, y: i64) -> u32 {
        let y = y.clamp(i32::MIN as i64, i32::MAX as i64);
        ((y + (1i64 << 31)) >> self.shift[l]) as u32
    }

    /// [`Self::strip`] of a coordinate already in the `i32` range.
    #[inline(always)]
    fn strip_i32(&self, l: usize, y: i32) -> u32 {
        ((((y as u32) ^ (1 << 31)) as u64) >> self.shift[l]) as u32
    }

    /// The top edge of strip `strip` of level `l` (the inverse of
    /// [`Self::strip`]).
    #[inline]
    pub fn strip_top(&self, l: usize, strip: u32) -> i64 {
        ((strip as i64) << self.shift[l]) - (1i64 << 31)
    }

    /// Strip height of level `l` in units.
    #[inline]
    pub fn height(&self, l: usize) -> i64 {
        1i64 << self.shift[l]
    }

    /// The sort key of a box: its level is set by its larger side, so that
    /// no box of a level is wider than the level's strip height either.
    #[inline(always)]
    pub fn key(&self, b: &Bounds) -> u64 {
        let w = b.max.x as i64 - b.min.x as i64;
        let h = b.max.y as i64 - b.min.y as i64;
        let l = self.level_of(w.max(h));
        ((l as u64) << 60)
            | ((self.strip_i32(l, b.min.y) as u64) << 32)
            | ((b.min.x as u32) ^ (1 << 31)) as u64
    }
}

/// The strip part of a key: `level << 28 | strip`.
#[inline]
pub(crate) fn row_key(key: u64) -> u32 {
    (key >> 32) as u32
}

/// The level of a row key.
#[inline]
pub(crate) fn row_level(row_key: u32) -> usize {
    (row_key >> 28) as usize
}

/// The strip (of its level) of a row key.
#[inline]
pub(crate) fn row_strip(row_key: u32) -> u32 {
    row_key & ((1 << 28) - 1)
}

/// One non-empty strip: a run of the sorted arrays.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Row {
    /// `level << 28 | strip`.
    pub key: u32,
    /// First entry.
    pub start: u32,
    /// One past the last entry: the strip's sentinel.
    pub end: u32,
    /// Widest box in the strip (units).
    pub max_w: u32,
}

/// A box on its way into the sweep arrays. Kept boxes travel like this,
/// without a key: their strip is known from where they are, and within a
/// strip the key orders like the left edge. 24 bytes rather than 32 is less
/// traffic for the split, which is bound by memory (measured: 3 % off the
/// one-thread tick at N = 10,000, 15 % off the update at 100,000).
#[derive(Debug, Clone, Copy)]
struct Kept {
    minx: i32,
    maxx: i32,
    miny: i32,
    maxy: i32,
    id: u32,
    idx: u32,
}

impl Kept {
    #[inline(always)]
    fn new(idx: u32, id: u32, b: &Bounds) -> Self {
        Self {
            minx: b.min.x,
            maxx: b.max.x,
            miny: b.min.y,
            maxy: b.max.y,
            id,
            idx,
        }
    }

    /// Width in units (saturated).
    #[inline(always)]
    fn width(&self) -> u32 {
        (self.maxx as i64 - self.minx as i64).clamp(0, u32::MAX as i64) as u32
    }
}

/// A box that changed strip, with its sort key.
#[derive(Debug, Clone, Copy)]
struct Entry {
    key: u64,
    b: Kept,
}

impl Entry {
    #[inline(always)]
    fn new(key: u64, idx: u32, id: u32, b: &Bounds) -> Self {
        Self {
            key,
            b: Kept::new(idx, id, b),
        }
    }
}

/// One slice of the old strips, updated on its own (in parallel with the
/// others when asked).
///
/// Aligned to two cache lines: chunks sit side by side and different
/// threads write their counters and vector lengths at once, so they must
/// not share a line (false sharing).
#[derive(Debug, Default, Clone)]
#[repr(align(128))]
struct Chunk {
    /// Old row-table indices covered.
    rows: Range<usize>,
    /// Boxes that kept their strip, in sorted order.
    stay: Vec<Kept>,
    /// Distinct strip keys of `stay`, in order, each with the end of its
    /// boxes in `stay`.
    stay_rows: Vec<(u32, u32)>,
    /// Boxes that changed strip, sorted by key.
    movers: Vec<Entry>,
    /// Insertion-sort steps taken.
    steps: usize,
    /// The movers (indices into the merged, sorted list) whose keys fall in
    /// this chunk's key range.
    mv: Range<usize>,
    /// First output entry.
    base: usize,
    /// Output entries (boxes and sentinels).
    size: usize,
    /// Output strips (absolute starts).
    out_rows: Vec<Row>,
    /// Smallest and largest id laid out.
    id_lo: u32,
    id_hi: u32,
}

impl Chunk {
    /// Reads this chunk's boxes in their old order, re-keys them and splits
    /// them into kept (re-sorted by insertion as they come) and movers.
    #[inline(always)]
    fn split(&mut self, lv: &Levels, rows: &[Row], idx: &[u32], items: &[(u32, Bounds)]) {
        self.stay.clear();
        self.stay_rows.clear();
        self.movers.clear();
        self.steps = 0;
        for r in &rows[self.rows.clone()] {
            let before = self.stay.len();
            for &i in &idx[r.start as usize..r.end as usize] {
                let (id, b) = &items[i as usize];
                let key = lv.key(b);
                if row_key(key) == r.key {
                    // Same strip: the left edge orders like the key.
                    let mut w = self.stay.len();
                    self.stay.push(Kept::new(i, *id, b));
                    while w > before && self.stay[w - 1].minx > b.min.x {
                        self.stay.swap(w - 1, w);
                        w -= 1;
                        self.steps += 1;
                    }
                } else {
                    self.movers.push(Entry::new(key, i, *id, b));
                }
            }
            if self.stay.len() > before {
                self.stay_rows.push((r.key, self.stay.len() as u32));
            }
        }
        // In the order of the strips they left, each for the strip before or
        // after: every mover is within a few strips' movers of its place.
        super::order::sort_nearly_sorted_by_key(&mut self.movers, 16, |m| m.key);
    }

    /// Output size: every box plus one sentinel per distinct strip.
    fn measure(&mut self, movers: &[Entry]) {
        let mv = &movers[self.mv.clone()];
        let mut distinct = self.stay_rows.len();
        let (mut k, mut last) = (0, u32::MAX);
        for m in mv {
            let rk = row_key(m.key);
            if rk == last {
                continue;
            }
            last = rk;
            while k < self.stay_rows.len() && self.stay_rows[k].0 < rk {
                k += 1;
            }
            if self.stay_rows.get(k).map(|r| r.0) != Some(rk) {
                distinct += 1;
            }
        }
        self.size = self.stay.len() + mv.len() + distinct;
    }

    /// Merges the kept boxes and this chunk's movers into `out`, strip by
    /// strip, one sentinel after each.
    #[inline(always)]
    fn layout(&mut self, movers: &[Entry], mut out: Slices<'_>) {
        self.out_rows.clear();
        let (st, mv) = (&self.stay, &movers[self.mv.clone()]);
        let (mut r, mut i, mut j, mut at) = (0, 0, 0, 0);
        let mut acc = Acc::default();
        loop {
            let sk = self.stay_rows.get(r).map(|x| x.0);
            let mk = mv.get(j).map(|m| row_key(m.key));
            let rk = match (sk, mk) {
                (Some(a), Some(b)) => a.min(b),
                (Some(k), None) | (None, Some(k)) => k,
                (None, None) => break,
            };
            let i1 = if sk == Some(rk) {
                r += 1;
                self.stay_rows[r - 1].1 as usize
            } else {
                i
            };
            let mut j1 = j;
            while j1 < mv.len() && row_key(mv[j1].key) == rk {
                j1 += 1;
            }
            acc.max_w = 0;
            let end = put(&mut out, at, &st[i..i1], &mv[j..j1], &mut acc);
            out.set_sentinel(end);
            self.out_rows.push(Row {
                key: rk,
                start: (self.base + at) as u32,
                end: (self.base + end) as u32,
                max_w: acc.max_w,
            });
            (i, j, at) = (i1, j1, end + 1);
        }
        debug_assert_eq!(at, self.size);
        self.id_lo = acc.id_lo;
        self.id_hi = acc.id_hi;
    }
}

multiversioned! {
    /// [`Chunk::split`], in the version `isa` picks.
    fn split_chunk(
        c: &mut Chunk,
        lv: &Levels,
        rows: &[Row],
        idx: &[u32],
        items: &[(u32, Bounds)],
    ) {
        c.split(lv, rows, idx, items)
    }
}

multiversioned! {
    /// [`Chunk::layout`], in the version `isa` picks.
    fn layout_chunk(c: &mut Chunk, movers: &[Entry], out: Slices<'_>) {
        c.layout(movers, out)
    }
}

/// Running figures of a layout: the widest box of the current strip and the
/// id range.
#[derive(Debug, Clone, Copy)]
struct Acc {
    max_w: u32,
    id_lo: u32,
    id_hi: u32,
}

impl Default for Acc {
    fn default() -> Self {
        Self {
            max_w: 0,
            id_lo: u32::MAX,
            id_hi: 0,
        }
    }
}

/// Writes the merge of the sorted runs `stay` and `new` (kept boxes first
/// on equal keys) into `out` from entry `at` on; returns the next free
/// entry. The kept boxes go in runs, column by column.
#[inline(always)]
fn put(out: &mut Slices<'_>, at: usize, stay: &[Kept], new: &[Entry], acc: &mut Acc) -> usize {
    let (mut at, mut i) = (at, 0);
    for m in new {
        // One strip: the left edge orders like the key.
        let mut k = i;
        while k < stay.len() && stay[k].minx <= m.b.minx {
            k += 1;
        }
        at = put_run(out, at, &stay[i..k], acc);
        at = put_run(out, at, core::slice::from_ref(&m.b), acc);
        i = k;
    }
    put_run(out, at, &stay[i..], acc)
}

/// Writes `run` into `out` from entry `at` on, column by column; returns
/// the next free entry. Four boxes at a time: their four edges are loaded
/// as four vectors, transposed into one vector per column and stored as
/// such; the widest box and the id range are kept in vectors too (a width
/// as the wrapping difference, exact for a valid box), as unsigned values
/// with their top bit flipped so that signed lane maxima and minima order
/// them: `wide`'s unsigned ones are four scalar operations without SSE4.1,
/// which the x86-64 baseline lacks (with them the layout took about one
/// and a half times as long).
#[inline(always)]
fn put_run(out: &mut Slices<'_>, at: usize, run: &[Kept], acc: &mut Acc) -> usize {
    let end = at + run.len();
    let mut k = at;
    let flip = |x: u32| (x ^ FLIP) as i32;
    let (mut wv, mut lov, mut hiv) = (
        i32x4::splat(flip(acc.max_w)),
        i32x4::splat(flip(acc.id_lo)),
        i32x4::splat(flip(acc.id_hi)),
    );
    let top = i32x4::splat(i32::MIN);
    let mut quads = run.chunks_exact(4);
    for q in &mut quads {
        let edges = |e: &Kept| i32x4::new([e.minx, e.maxx, e.miny, e.maxy]);
        let [mnx, mxx, mny, mxy] =
            i32x4::transpose([edges(&q[0]), edges(&q[1]), edges(&q[2]), edges(&q[3])]);
        out.minx[k..k + 4].copy_from_slice(&mnx.to_array());
        out.maxx[k..k + 4].copy_from_slice(&mxx.to_array());
        out.miny[k..k + 4].copy_from_slice(&mny.to_array());
        out.maxy[k..k + 4].copy_from_slice(&mxy.to_array());
        let ids = [q[0].id, q[1].id, q[2].id, q[3].id];
        out.id[k..k + 4].copy_from_slice(&ids);
        out.idx[k..k + 4].copy_from_slice(&[q[0].idx, q[1].idx, q[2].idx, q[3].idx]);
        wv = wv.max((mxx - mnx) ^ top);
        let idv = i32x4::new(ids.map(flip));
        lov = lov.min(idv);
        hiv = hiv.max(idv);
        k += 4;
    }
    let unflip = |v: i32x4| v.to_array().map(|x| x as u32 ^ FLIP);
    let mut a = Acc {
        max_w: unflip(wv).into_iter().max().unwrap_or(0),
        id_lo: unflip(lov).into_iter().min().unwrap_or(u32::MAX),
        id_hi: unflip(hiv).into_iter().max().unwrap_or(0),
    };
    for e in quads.remainder() {
        (
            out.minx[k],
            out.maxx[k],
            out.miny[k],
            out.maxy[k],
            out.id[k],
            out.idx[k],
        ) = (e.minx, e.maxx, e.miny, e.maxy, e.id, e.idx);
        a.max_w = a.max_w.max(e.width());
        a.id_lo = a.id_lo.min(e.id);
        a.id_hi = a.id_hi.max(e.id);
        k += 1;
    }
    *acc = a;
    end
}

/// The top bit, flipped to order unsigned values as signed ones.
const FLIP: u32 = 1 << 31;

/// One set of boxes (the static or the dynamic ones) in strip order.
#[derive(Debug, Default, Clone)]
pub(crate) struct Strips {
    /// Left edges in sorted order, strips separated by sentinels.
    pub minx: Vec<i32>,
    /// Right edges.
    pub maxx: Vec<i32>,
    /// Top edges.
    pub miny: Vec<i32>,
    /// Bottom edges.
    pub maxy: Vec<i32>,
    /// Caller ids.
    pub id: Vec<u32>,
    /// Non-empty strips in key order.
    pub rows: Vec<Row>,
    /// `rows[level_rows[l]..level_rows[l + 1]]` are level `l`'s strips.
    pub level_rows: [u32; MAX_LEVELS + 1],
    /// Entries `level_start[l]..level_start[l + 1]` are level `l`'s boxes
    /// (and sentinels).
    pub level_start: [u32; MAX_LEVELS + 1],
    /// Smallest id (`u32::MAX` when empty).
    pub id_lo: u32,
    /// Largest id (0 when empty).
    pub id_hi: u32,
    /// Number of boxes.
    count: usize,
    /// Entries in use, sentinels included, padding excluded (the arrays are
    /// longer: they only grow, and are overwritten in place).
    used: usize,
    /// Input index of each entry (`u32::MAX` for sentinels), kept for the
    /// next update.
    idx: Vec<u32>,
    /// Per-chunk scratch.
    chunks: Vec<Chunk>,
    /// Scratch: all movers, sorted.
    movers: Vec<Entry>,
    /// Scratch for a full sort.
    full: Vec<(u64, u32)>,
    /// Boxes that changed strip at the last update (a statistic).
    pub last_movers: usize,
    /// Whether the last update sorted from scratch (a statistic).
    pub last_full_sort: bool,
}

impl Strips {
    /// Number of boxes.
    #[inline]
    pub fn len(&self) -> usize {
        self.count
    }

    /// Number of entries including sentinels (but not the final padding).
    #[inline]
    pub fn slots(&self) -> usize {
        self.used
    }

    /// Rebuilds the set from `items`, reusing the previous order as a hint:
    /// boxes that stayed in their strip keep their order up to local swaps
    /// (an insertion sort as they are read, linear when few boxes overtake
    /// each other), the few that changed strip are sorted apart and merged
    /// in. The result never depends on the hint: only the cost does.
    ///
    /// With `par`, the old strips are cut into chunks of about `chunk` boxes
    /// that are re-keyed and laid out in parallel on the current rayon pool;
    /// the arrays come out identical either way, as they do whichever `isa`
    /// versions of the hot loops run.
    pub fn update(
        &mut self,
        lv: &Levels,
        items: &[(u32, Bounds)],
        par: bool,
        chunk: usize,
        isa: Isa,
    ) {
        let n = items.len();
        let mut full = !(n == self.count && n > 0);
        self.movers.clear();
        if !full {
            self.plan_chunks(if par { chunk.max(1) } else { usize::MAX });
            let nc = self.chunks.len();
            let (rows, idx) = (&self.rows, &self.idx);
            let job = |c: &mut Chunk| split_chunk(isa, c, lv, rows, idx, items);
            if par {
                use rayon::prelude::*;
                self.chunks[..nc].par_iter_mut().for_each(job);
            } else {
                self.chunks[..nc].iter_mut().for_each(job);
            }
            let steps: usize = self.chunks[..nc].iter().map(|c| c.steps).sum();
            for c in &self.chunks[..nc] {
                self.movers.extend_from_slice(&c.movers);
            }
            full = steps > 4 * n + 64 || self.movers.len() > n / 4;
        }
        self.last_movers = self.movers.len();
        self.last_full_sort = full;
        if full {
            self.full.clear();
            self.full.extend(
                items
                    .iter()
                    .enumerate()
                    .map(|(i, it)| (lv.key(&it.1), i as u32)),
            );
            if par {
                use rayon::prelude::*;
                self.full.par_sort_unstable_by_key(|e| e.0);
            } else {
                self.full.sort_unstable_by_key(|e| e.0);
            }
            self.movers.clear();
            if self.chunks.is_empty() {
                self.chunks.push(Chunk::default());
            }
            let c = &mut self.chunks[0];
            c.stay.clear();
            c.stay_rows.clear();
            for &(key, i) in &self.full {
                let (id, b) = &items[i as usize];
                if c.stay_rows.last().map(|r| r.0) != Some(row_key(key)) {
                    c.stay_rows.push((row_key(key), 0));
                }
                c.stay.push(Kept::new(i, *id, b));
                let n = c.stay.len() as u32;
                if let Some(last) = c.stay_rows.last_mut() {
                    last.1 = n;
                }
            }
            c.rows = 0..0;
            self.chunks.truncate(1);
        } else {
            // Each chunk sorted its own movers (in parallel, so that little
            // serial work separates the split from the layout): only those
            // crossing a chunk boundary are out of place, by a few strips'
            // movers. (A parallel sort of the few thousand movers of
            // N = 100,000 took 66 µs.)
            super::order::sort_nearly_sorted_by_key(&mut self.movers, 16, |m| m.key);
        }
        self.count = n;
        self.layout(par, isa);
    }

    /// Cuts the old strips into chunks of about `target` boxes.
    fn plan_chunks(&mut self, target: usize) {
        let mut k = 0;
        let mut start = 0;
        let mut count = 0;
        let nrows = self.rows.len();
        for (ri, r) in self.rows.iter().enumerate() {
            count += (r.end - r.start) as usize;
            if count >= target || ri + 1 == nrows {
                if self.chunks.len() <= k {
                    self.chunks.push(Chunk::default());
                }
                self.chunks[k].rows = start..ri + 1;
                k += 1;
                start = ri + 1;
                count = 0;
            }
        }
        self.chunks.truncate(k.max(1));
        if k == 0 {
            self.chunks[0].rows = 0..0;
        }
    }

    /// Merges the kept boxes and the movers into the sweep arrays, adding a
    /// sentinel after each strip, and indexes the strips.
    fn layout(&mut self, par: bool, isa: Isa) {
        // Hand each chunk the movers of its key range: from its first old
        // strip up to the next chunk's first.
        let nc = self.chunks.len();
        let mut from = 0;
        for c in 0..nc {
            let to = if c + 1 < nc {
                let first = self.rows[self.chunks[c + 1].rows.start].key;
                let bound = (first as u64) << 32;
                from + self.movers[from..].partition_point(|m| m.key < bound)
            } else {
                self.movers.len()
            };
            self.chunks[c].mv = from..to;
            from = to;
        }
        let mut base = 0;
        for c in &mut self.chunks {
            c.measure(&self.movers);
            c.base = base;
            base += c.size;
        }
        let used = base;
        let need = used + PAD;
        for v in [
            &mut self.minx,
            &mut self.maxx,
            &mut self.miny,
            &mut self.maxy,
        ] {
            if v.len() < need {
                v.resize(need, 0);
            }
        }
        for v in [&mut self.id, &mut self.idx] {
            if v.len() < need {
                v.resize(need, 0);
            }
        }
        let out = Slices {
            minx: &mut self.minx[..used],
            maxx: &mut self.maxx[..used],
            miny: &mut self.miny[..used],
            maxy: &mut self.maxy[..used],
            id: &mut self.id[..used],
            idx: &mut self.idx[..used],
        };
        lay_chunks(&mut self.chunks, &self.movers, out, par, isa);
        // Padding sentinels.
        let mut pad = Slices {
            minx: &mut self.minx,
            maxx: &mut self.maxx,
            miny: &mut self.miny,
            maxy: &mut self.maxy,
            id: &mut self.id,
            idx: &mut self.idx,
        };
        for k in used..need {
            pad.set_sentinel(k);
        }
        self.used = used;
        self.rows.clear();
        let (mut id_lo, mut id_hi) = (u32::MAX, 0);
        for c in &self.chunks {
            self.rows.extend_from_slice(&c.out_rows);
            id_lo = id_lo.min(c.id_lo);
            id_hi = id_hi.max(c.id_hi);
        }
        self.id_lo = id_lo;
        self.id_hi = id_hi;
        // Level boundaries in the row table and the entries.
        let mut r = 0usize;
        for l in 0..=MAX_LEVELS {
            while r < self.rows.len() && row_level(self.rows[r].key) < l {
                r += 1;
            }
            self.level_rows[l] = r as u32;
            self.level_start[l] = self.rows.get(r).map_or(used as u32, |row| row.start);
        }
    }

    /// Row-table indices of the strips of level `l` whose strip number lies
    /// in `lo..=hi`.
    #[inline]
    pub fn rows_in(&self, l: usize, lo: u32, hi: u32) -> core::ops::Range<usize> {
        let (a, b) = (self.level_rows[l] as usize, self.level_rows[l + 1] as usize);
        let rows = &self.rows[a..b];
        let base = (l as u32) << 28;
        let s = rows.partition_point(|r| r.key < base | lo);
        let e = s + rows[s..].partition_point(|r| r.key <= base | hi);
        a + s..a + e
    }
}

/// Disjoint parts of the sweep arrays.
struct Slices<'a> {
    minx: &'a mut [i32],
    maxx: &'a mut [i32],
    miny: &'a mut [i32],
    maxy: &'a mut [i32],
    id: &'a mut [u32],
    idx: &'a mut [u32],
}

impl<'a> Slices<'a> {
    /// Makes entry `k` a sentinel.
    #[inline(always)]
    fn set_sentinel(&mut self, k: usize) {
        self.minx[k] = SENTINEL;
        self.maxx[k] = SENTINEL;
        self.miny[k] = 0;
        self.maxy[k] = 0;
        self.id[k] = u32::MAX;
        self.idx[k] = u32::MAX;
    }

    fn split_at(self, k: usize) -> (Slices<'a>, Slices<'a>) {
        let (a0, b0) = self.minx.split_at_mut(k);
        let (a1, b1) = self.maxx.split_at_mut(k);
        let (a2, b2) = self.miny.split_at_mut(k);
        let (a3, b3) = self.maxy.split_at_mut(k);
        let (a4, b4) = self.id.split_at_mut(k);
        let (a5, b5) = self.idx.split_at_mut(k);
        (
            Slices {
                minx: a0,
                maxx: a1,
                miny: a2,
                maxy: a3,
                id: a4,
                idx: a5,
            },
            Slices {
                minx: b0,
                maxx: b1,
                miny: b2,
                maxy: b3,
                id: b4,
                idx: b5,
            },
        )
    }
}

/// Lays out `chunks` into `out` (which starts at the first chunk's base),
/// splitting the work over the rayon pool when `par`.
fn lay_chunks(chunks: &mut [Chunk], movers: &[Entry], out: Slices<'_>, par: bool, isa: Isa) {
    if chunks.len() == 1 || !par {
        let mut out = out;
        for c in chunks {
            let (mine, rest) = out.split_at(c.size);
            layout_chunk(isa, c, movers, mine);
            out = rest;
        }
        return;
    }
    let mid = chunks.len() / 2;
    let (left, right) = chunks.split_at_mut(mid);
    let (lo, hi) = out.split_at(right[0].base - left[0].base);
    rayon::join(
        || lay_chunks(left, movers, lo, par, isa),
        || lay_chunks(right, movers, hi, par, isa),
    );
}
