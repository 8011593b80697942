//! The pair-finding kernels over [`Strips`], generic over what a found pair
//! becomes ([`Sink`]) and monomorphised per sink: no trait object or `match`
//! in the hot loop.
//!
//! The scans test [`BLOCK`] entries at a time without branching (each test
//! is a few 4-lane vector compares, written with `wide` so that they stay
//! vector code whatever the optimiser decides, folded into a bit mask) and
//! stop at the first entry that starts too far right; strips end with a
//! sentinel that always stops a scan. Bodies move little, so most boxes
//! have no or one candidate and a branchy scan would mispredict on almost
//! every box.
//!
//! Pairs of dynamic strips are not handed to the sink as they are found:
//! each block's first hit is written into a candidate list whether or not
//! there is one (the count then advances by `mask != 0`; only a second hit
//! in one block branches), and the sink takes the whole list afterwards in
//! one sequential pass. Only the boxes reaching into the next strip scan it:
//! they are listed during the self scan, again without a branch.

use super::strips::{row_level, row_strip, Levels, Row, Strips, BLOCK, SENTINEL};
use core::ops::Range;
use wide::i32x4;

/// Receives every pair of boxes whose interiors overlap (strictly, on both
/// axes): entry `i` of `a` and entry `j` of `b`.
pub(crate) trait Sink {
    /// One overlapping pair.
    fn hit(&mut self, a: &Strips, i: usize, b: &Strips, j: usize);
}

/// The block of `BLOCK` values starting at `k`, as one vector.
#[inline(always)]
fn block(v: &[i32], k: usize) -> i32x4 {
    let b: [i32; BLOCK] = v[k..k + BLOCK].try_into().unwrap();
    i32x4::new(b)
}

/// Bit `t` set when `v[k + t] < x`.
#[inline(always)]
fn lanes_lt(v: &[i32], k: usize, x: i32) -> u32 {
    block(v, k).simd_lt(i32x4::splat(x)).to_bitmask()
}

/// Bit `t` set when `v[k + t] <= x`.
#[inline(always)]
fn lanes_le(v: &[i32], k: usize, x: i32) -> u32 {
    !block(v, k).simd_gt(i32x4::splat(x)).to_bitmask() & low(BLOCK as u32)
}

/// Bit `t` set when entry `k + t` of `s` ends right of `x0` and overlaps
/// `(y0, y1)` in y.
#[inline(always)]
fn lanes_rest(s: &Strips, k: usize, x0: i32, y0: i32, y1: i32) -> u32 {
    let (mx, ny, my) = (block(&s.maxx, k), block(&s.miny, k), block(&s.maxy, k));
    (mx.simd_gt(i32x4::splat(x0)) & my.simd_gt(i32x4::splat(y0)) & i32x4::splat(y1).simd_gt(ny))
        .to_bitmask()
}

/// The low `n` bits.
#[inline(always)]
fn low(n: u32) -> u32 {
    (1u32 << n) - 1
}

/// Tests box `(x0, x1, y0, y1)` against the entries of `s` from `k` on while
/// they start left of `x1`, calling `hit(j)` for each overlap.
#[inline(always)]
fn scan(s: &Strips, mut k: usize, x0: i32, x1: i32, y0: i32, y1: i32, mut hit: impl FnMut(usize)) {
    loop {
        let run = lanes_lt(&s.minx, k, x1).trailing_ones();
        let mut h = lanes_rest(s, k, x0, y0, y1) & low(run);
        while h != 0 {
            hit(k + h.trailing_zeros() as usize);
            h &= h - 1;
        }
        if run < BLOCK as u32 {
            return;
        }
        k += BLOCK;
    }
}

/// Moves cursor `p` of a run of `b` (sorted by left edge, ending in a
/// sentinel, no box wider than `max_w`) past the boxes that end before `x0`
/// can be reached: left edge `<= x0 - max_w`.
#[inline(always)]
fn advance(b: &Strips, p: &mut usize, x0: i32, max_w: u32) {
    let lo = x0 as i64 - max_w as i64;
    if lo >= i32::MIN as i64 {
        // The sentinel is never <= lo (real edges are below i32::MAX).
        loop {
            let c = lanes_le(&b.minx, *p, lo as i32).trailing_ones();
            *p += c as usize;
            if c < BLOCK as u32 {
                break;
            }
        }
    }
}

/// [`advance`] four blocks at a time, for cursors that move several entries
/// per box (the next-strip cursor of the reaching boxes, about six entries
/// between two of them on the standard scene): a second step, and the
/// mispredicted loop exit it costs, is rare (two blocks a step fell short
/// about one time in four: 4 % slower at N = 10,000). Needs `4 * BLOCK`
/// entries readable after the sentinel (`strips::PAD`).
#[inline(always)]
fn advance_far(b: &Strips, p: &mut usize, x0: i32, max_w: u32) {
    let lo = x0 as i64 - max_w as i64;
    if lo >= i32::MIN as i64 {
        loop {
            let m = lanes_le(&b.minx, *p, lo as i32)
                | lanes_le(&b.minx, *p + BLOCK, lo as i32) << BLOCK
                | lanes_le(&b.minx, *p + 2 * BLOCK, lo as i32) << (2 * BLOCK)
                | lanes_le(&b.minx, *p + 3 * BLOCK, lo as i32) << (3 * BLOCK);
            let c = m.trailing_ones();
            *p += c as usize;
            if c < 4 * BLOCK as u32 {
                break;
            }
        }
    }
}

/// Every overlapping pair of a box of run `ra` of `a` with a box of run `rb`
/// of `b` (both sorted by left edge, `rb` followed by a sentinel, no box of
/// `rb` wider than `max_w`). For each box of `ra`, in order, a cursor in `rb`
/// skips the boxes that end before it can start (left edge
/// `<= a.min.x - max_w`, a bound that only grows), then a forward scan tests
/// the boxes that start before it ends.
#[inline(always)]
pub(crate) fn sweep_two<S: Sink>(
    a: &Strips,
    ra: Range<usize>,
    b: &Strips,
    rb: Range<usize>,
    max_w: u32,
    sink: &mut S,
) {
    let mut p = rb.start;
    for i in ra {
        let (x0, x1, y0, y1) = (a.minx[i], a.maxx[i], a.miny[i], a.maxy[i]);
        advance(b, &mut p, x0, max_w);
        scan(b, p, x0, x1, y0, y1, |j| sink.hit(a, i, b, j));
    }
}

/// Reused buffers of one work item's sweeps.
#[derive(Debug, Default, Clone)]
pub(crate) struct Scratch {
    /// Candidate pairs.
    cands: Vec<[u32; 2]>,
    /// Boxes of one strip reaching into the next.
    reach: Vec<u32>,
}

/// Candidate pairs `[i, j]` (entries of one set), written without a branch
/// per block: the buffer is kept longer than its contents and `n` counts
/// the pairs in it. Passed by value through the sweeps rather than behind
/// a reference (measured about 1 % faster).
pub(crate) struct Cands {
    buf: Vec<[u32; 2]>,
    n: usize,
}

impl Cands {
    /// An empty list over `buf` (whose contents are overwritten).
    #[inline]
    pub fn new(buf: Vec<[u32; 2]>) -> Self {
        Self { buf, n: 0 }
    }

    /// The pairs found, and the buffer to keep for the next time.
    #[inline]
    pub fn into_parts(self) -> (Vec<[u32; 2]>, usize) {
        (self.buf, self.n)
    }

    /// Adds `[i, k + t]` for every bit `t` of `h`. The first is stored
    /// whatever `h` (and kept only if `h != 0`); only a second hit in one
    /// block (rare) takes a branch.
    #[inline(always)]
    fn push(&mut self, i: usize, k: usize, mut h: u32) {
        if self.n + 2 * BLOCK > self.buf.len() {
            self.buf = grow(core::mem::take(&mut self.buf));
        }
        self.buf[self.n] = [i as u32, (k as u32).wrapping_add(h.trailing_zeros())];
        self.n += (h != 0) as usize;
        h &= h.wrapping_sub(1);
        while h != 0 {
            self.buf[self.n] = [i as u32, (k as u32).wrapping_add(h.trailing_zeros())];
            self.n += 1;
            h &= h - 1;
        }
    }
}

/// A longer candidate buffer (by value: no address of the list escapes).
#[cold]
#[inline(never)]
fn grow(mut buf: Vec<[u32; 2]>) -> Vec<[u32; 2]> {
    let len = (2 * buf.len()).max(1024);
    buf.resize(len, [0; 2]);
    buf
}

/// [`scan`] into a candidate list: box `i` against the entries of `s` from
/// `k` on while they start left of `x1`.
#[inline(always)]
fn scan_into(s: &Strips, mut k: usize, i: usize, x: (i32, i32, i32, i32), c: &mut Cands) {
    let (x0, x1, y0, y1) = x;
    loop {
        let run = lanes_lt(&s.minx, k, x1).trailing_ones();
        c.push(i, k, lanes_rest(s, k, x0, y0, y1) & low(run));
        if run < BLOCK as u32 {
            return;
        }
        k += BLOCK;
    }
}

/// Every overlapping pair inside run `ra` of `s` (each box scans forward)
/// and, with `next` (the next strip and its top edge), of `ra` against the
/// next strip (as [`sweep_two`]), into a candidate list. Only the boxes
/// reaching below the next strip's top edge can meet it: the self scan
/// lists them without a branch (a branch per box, taken or not at random,
/// was measured slower), then only they scan the next strip.
#[inline(always)]
fn sweep_self_and_next(
    s: &Strips,
    ra: Range<usize>,
    next: Option<(&Row, i64)>,
    c: Cands,
    reach: &mut Vec<u32>,
) -> Cands {
    // A local copy: the count and buffer stay in registers (measured about
    // 2 % off the tick at N = 10,000 against updating the caller's list in
    // place).
    let mut c = Cands { buf: c.buf, n: c.n };
    // Each box with the block after it, as windows of the four columns: the
    // self scan's first block needs no bounds check (a run ends with its
    // sentinel and the arrays with `PAD` more entries).
    let r = ra.start..ra.end + BLOCK;
    let boxes = s.minx[r.clone()]
        .windows(BLOCK + 1)
        .zip(s.maxx[r.clone()].windows(BLOCK + 1))
        .zip(s.miny[r.clone()].windows(BLOCK + 1))
        .zip(s.maxy[r].windows(BLOCK + 1));
    // The boxes reaching into the next strip (below `bottom`), listed
    // without a branch: only they scan it.
    if reach.len() < ra.len() {
        reach.resize(ra.len(), 0);
    }
    // A slice and an `i32` bound kept in registers through the loop (a box
    // bottom is an `i32`; no strip top is above `i32::MAX`).
    let listed = &mut reach[..ra.len()];
    let bottom = next.map_or(i32::MAX, |n| n.1.min(i32::MAX as i64) as i32);
    let mut m = 0;
    for (i, (((a, b), e), d)) in ra.clone().zip(boxes) {
        let x = (a[0], b[0], e[0], d[0]);
        let (x0, x1, y0, y1) = x;
        let tail = |v: &[i32]| i32x4::new([v[1], v[2], v[3], v[4]]);
        let run = tail(a)
            .simd_lt(i32x4::splat(x1))
            .to_bitmask()
            .trailing_ones();
        let rest = tail(b).simd_gt(i32x4::splat(x0))
            & tail(d).simd_gt(i32x4::splat(y0))
            & i32x4::splat(y1).simd_gt(tail(e));
        c.push(i, i + 1, rest.to_bitmask() & low(run));
        if run == BLOCK as u32 {
            scan_into(s, i + 1 + BLOCK, i, x, &mut c);
        }
        listed[m] = i as u32;
        m += (y1 > bottom) as usize;
    }
    if let Some((next, _)) = next {
        let mut p = next.start as usize;
        for &i in &reach[..m] {
            let i = i as usize;
            let x = (s.minx[i], s.maxx[i], s.miny[i], s.maxy[i]);
            advance_far(s, &mut p, x.0, next.max_w);
            scan_into(s, p, i, x, &mut c);
        }
    }
    c
}

multiversioned! {
    /// Same-level pairs for the dynamic strips `rows` (row-table indices of
    /// `dy`): inside each strip, with the next strip, and with the static
    /// strips one above, level with and one below.
    pub(crate) fn same_level<S: Sink>(
        lv: &Levels,
        dy: &Strips,
        st: &Strips,
        rows: Range<usize>,
        scratch: &mut Scratch,
        sink: &mut S,
    ) {
        same_level_in(lv, dy, st, rows, scratch, sink)
    }
}

/// The body of [`same_level`].
#[inline(always)]
fn same_level_in<S: Sink>(
    lv: &Levels,
    dy: &Strips,
    st: &Strips,
    rows: Range<usize>,
    scratch: &mut Scratch,
    sink: &mut S,
) {
    // Dynamic pairs: candidates first, then the sink in one sequential pass
    // (the scans stay free of the output's branches and buffers).
    let mut c = Cands::new(core::mem::take(&mut scratch.cands));
    for ri in rows.clone() {
        let r = dy.rows[ri];
        let run = r.start as usize..r.end as usize;
        let next = match dy.rows.get(ri + 1) {
            Some(next) if next.key == r.key + 1 && row_level(next.key) == row_level(r.key) => {
                let top = lv.strip_top(row_level(next.key), row_strip(next.key));
                Some((next, top))
            }
            _ => None,
        };
        c = sweep_self_and_next(dy, run, next, c, &mut scratch.reach);
    }
    let (buf, n) = c.into_parts();
    for &[i, j] in &buf[..n] {
        sink.hit(dy, i as usize, dy, j as usize);
    }
    scratch.cands = buf;
    if st.rows.is_empty() {
        return;
    }
    let mut cursor = None;
    for ri in rows {
        let r = dy.rows[ri];
        let run = r.start as usize..r.end as usize;
        // Static strips with keys r.key - 1 ..= r.key + 1 of the same level;
        // dynamic strips come in key order, so the cursor only moves forward.
        let lo = r.key.saturating_sub(1);
        let c = cursor.get_or_insert_with(|| st.rows.partition_point(|s| s.key < lo));
        while *c < st.rows.len() && st.rows[*c].key < lo {
            *c += 1;
        }
        let mut k = *c;
        while k < st.rows.len() && st.rows[k].key <= r.key.saturating_add(1) {
            let s = st.rows[k];
            if row_level(s.key) == row_level(r.key) {
                let srun = s.start as usize..s.end as usize;
                sweep_two(dy, run.clone(), st, srun, s.max_w, sink);
            }
            k += 1;
        }
    }
}

multiversioned! {
    /// Pairs of entries `xs` of `x` (all on levels above 0) with the boxes
    /// of `y` on lower levels. For each box of `x` and each lower level of
    /// `y`: the strips it can reach, and in each a binary search on the left
    /// edge bounded by the strip's widest box, then a scan.
    pub(crate) fn cross_level<S: Sink>(
        lv: &Levels,
        x: &Strips,
        xs: Range<usize>,
        y: &Strips,
        sink: &mut S,
    ) {
        cross_level_in(lv, x, xs, y, sink)
    }
}

/// The body of [`cross_level`].
#[inline(always)]
fn cross_level_in<S: Sink>(lv: &Levels, x: &Strips, xs: Range<usize>, y: &Strips, sink: &mut S) {
    for e in xs {
        if x.minx[e] == SENTINEL {
            continue;
        }
        let lx = level_of_entry(x, e);
        let (x0, x1, y0, y1) = (x.minx[e], x.maxx[e], x.miny[e], x.maxy[e]);
        for l in 0..lx {
            if y.level_rows[l] == y.level_rows[l + 1] {
                continue;
            }
            // A box of level l is at most S tall: it can overlap only if its
            // top edge is in (y0 - S, y1).
            let lo = lv.strip(l, y0 as i64 - lv.height(l) + 1);
            let hi = lv.strip(l, y1 as i64 - 1);
            for ri in y.rows_in(l, lo, hi) {
                let r = y.rows[ri];
                let from = x0 as i64 - r.max_w as i64;
                let first = r.start as usize
                    + y.minx[r.start as usize..r.end as usize]
                        .partition_point(|&m| (m as i64) <= from);
                scan(y, first, x0, x1, y0, y1, |j| sink.hit(x, e, y, j));
            }
        }
    }
}

/// Calls `hit(j)` for every entry `j` of `y` whose box overlaps box `(x0,
/// x1, y0, y1)` (interiors, strictly): the larger-box side of
/// [`cross_level`] for one box of any size, over every level of `y`.
pub(crate) fn query(lv: &Levels, y: &Strips, b: (i32, i32, i32, i32), mut hit: impl FnMut(usize)) {
    let (x0, x1, y0, y1) = b;
    for l in 0..lv.count {
        if y.level_rows[l] == y.level_rows[l + 1] {
            continue;
        }
        let lo = lv.strip(l, y0 as i64 - lv.height(l) + 1);
        let hi = lv.strip(l, y1 as i64 - 1);
        for ri in y.rows_in(l, lo, hi) {
            let r = y.rows[ri];
            let from = x0 as i64 - r.max_w as i64;
            let first = r.start as usize
                + y.minx[r.start as usize..r.end as usize].partition_point(|&m| (m as i64) <= from);
            scan(y, first, x0, x1, y0, y1, &mut hit);
        }
    }
}

/// The level of entry `e` (from the set's level boundaries).
#[inline]
fn level_of_entry(s: &Strips, e: usize) -> usize {
    let e = e as u32;
    s.level_start[1..]
        .iter()
        .position(|&start| e < start)
        .unwrap_or(super::strips::MAX_LEVELS - 1)
}
