//! Broad phase: which pairs of bounding boxes overlap, fast, in a canonical
//! order, optionally on many threads.
//!
//! # Partition: levelled strips with sort-and-sweep
//! Boxes (integer corners, [`Bounds`]) are kept in *strips*: horizontal bands
//! of height `S`, each sorted by left edge. A box goes to the finest *level*
//! whose strip height is at least its own height (levels grow by a factor of
//! 4 from 128 px by default, up to a single strip for the whole `i32` range),
//! so a 2 px bullet and a 4096 px platform each sit where they are cheap: a
//! wide-but-flat platform stays on level 0 (width never matters), a tall one
//! goes up. Two boxes of one level can only overlap if their strips are equal
//! or adjacent; inside a strip pair a merge-like sweep on the left edges
//! tests only boxes that already overlap in x (plus one that ends each scan).
//! A box of a higher level finds the lower-level boxes it covers by binary
//! search in each strip it reaches. The whole set is one array sorted by one
//! `u64` key (level, strip, left edge): no world size to configure, no hash
//! map, and coordinates anywhere in the `i32` range.
//!
//! * **Static bodies** ([`BroadPhase::set_static`]) are sorted once; ticks
//!   only sweep dynamic strips against them.
//! * **Temporal coherence**: each update starts from the previous order. A box
//!   that stayed in its strip is re-sorted in place by an insertion sort
//!   (bodies move little, so it is linear); the few that changed strip are
//!   sorted apart and merged in. Results never depend on the previous order,
//!   only the cost does.
//! * **Determinism**: the output is sorted by `(first id, second id)` with
//!   `first < second` (a bucket sort on the first id, then one bounded
//!   insertion sort), so it depends only on the input, never on thread
//!   count or scheduling.
//!   The MTV in a contact moves the *first* (smaller id) body.
//! * **No allocation per tick** in steady state: every buffer is kept and
//!   reused.
//! * **Parallel** (`*_par` methods): strips are cut into batches of about
//!   equal box counts, run with rayon's work stealing; a batch files each
//!   pair under its first id's range (a few ranges per thread), and the
//!   ranges are then sorted into the canonical order in parallel, each into
//!   its own slice of the output. The dynamic update is cut into chunks the
//!   same way (each chunk also sorts its own movers). The plain
//!   methods never touch rayon. They use the *current* rayon pool, so a
//!   caller picks the thread count with
//!   `rayon::ThreadPoolBuilder::new().num_threads(n).build()?.install(..)`.
//! * **Compiled twice**: the hot loops are compiled for the x86-64 baseline
//!   and for x86-64-v3 (AVX2, BMI1/2, ...), and each call takes the best
//!   version the CPU has (the `multiversion` crate; the check is one atomic
//!   load). The vector code is written for 4 lanes either way; the newer
//!   instructions (blends, 32-bit lane min/max, inserts and extracts,
//!   three-operand forms) make it about 7 % faster at N = 10,000
//!   (`docs/PERFORMANCE.md`). Integer code only: both versions give the
//!   same results bit for bit. [`BroadPhaseConfig::isa`] can instead pin
//!   the baseline ([`Isa::Baseline`]), which a machine with AVX2 would
//!   otherwise never run: the broad-phase tests check every scene under
//!   both choices, on any machine, and benchmarks compare the two.
//!
//! Pairs are reported only when the interiors overlap (`a.min < b.max` and
//! `b.min < a.max` on both axes): boxes that share an edge are not a pair.
//! Static-static pairs are never reported. Ids are the caller's and should be
//! distinct across the static and dynamic sets.
//!
//! [`standard`] is the benchmark scene of `docs/PERFORMANCE.md`.

/// Compiles `fn` for x86-64-v3 as well as the baseline (see the module
/// docs) and makes it take an [`Isa`] first: [`Isa::Best`] calls the
/// `multiversion` version, which picks the best the CPU has at run time,
/// [`Isa::Baseline`] a plain copy of the same body compiled for the
/// baseline only (what a CPU without AVX2 runs), so that the tests check
/// both versions on any machine. The choice is one branch on a value per
/// call: the wrapped functions run per batch or chunk, not per box. Kept to
/// thin wrappers around `#[inline(always)]` bodies, so that everything the
/// body calls is part of each version and rustfmt formats the bodies. The
/// signature takes `name: Type` arguments and `<T: Bound>` generics only.
macro_rules! multiversioned {
    (
        $(#[$attr:meta])*
        $vis:vis fn $name:ident $(<$($g:ident: $bound:path),+ $(,)?>)?
            ($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)?
        $body:block
    ) => {
        $(#[$attr])*
        #[inline]
        $vis fn $name $(<$($g: $bound),+>)? (
            isa: $crate::broad::Isa,
            $($arg: $ty),*
        ) $(-> $ret)? {
            #[multiversion::multiversion(targets(
                "x86_64+avx2+avx+bmi1+bmi2+fma+lzcnt+popcnt+movbe+f16c"
            ))]
            fn best $(<$($g: $bound),+>)? ($($arg: $ty),*) $(-> $ret)? $body
            // Out of line, like the versions of `best`: the copy does not
            // grow the caller, which the `Best` path runs through too.
            #[inline(never)]
            fn baseline $(<$($g: $bound),+>)? ($($arg: $ty),*) $(-> $ret)? $body
            match isa {
                $crate::broad::Isa::Best => best($($arg),*),
                $crate::broad::Isa::Baseline => baseline($($arg),*),
            }
        }
    };
}

mod bounds;
mod isa;
mod order;
pub mod standard;
mod strips;
mod sweep;

pub use bounds::Bounds;
pub use isa::Isa;

use glam::IVec2;
use order::{Buffers, Keyed, Parts};
use strips::{Levels, Strips};
use sweep::Sink;

/// The minimum translation vector that moves `a` out of `b`, when their
/// interiors overlap.
///
/// The same answer as [`crate::query::Contact`] for two
/// [`crate::shape::Aabb`] centred in these boxes: the axis of least overlap
/// (x on ties), pushing `a` away from `b`'s centre (left or up when the
/// centres coincide on that axis).
#[inline]
pub fn aabb_mtv(a: &Bounds, b: &Bounds) -> Option<IVec2> {
    if !a.overlaps(b) {
        return None;
    }
    Some(mtv_of(
        (a.min.x, a.max.x, a.min.y, a.max.y),
        (b.min.x, b.max.x, b.min.y, b.max.y),
    ))
}

/// [`aabb_mtv`] for boxes known to overlap, as `(min x, max x, min y, max y)`.
///
/// Along each axis the push is away from `b`'s centre (`d`, twice the centre
/// offset, picks the side; `d == 0` pushes towards `-x`/`-y`) and its length
/// is what it takes to clear `b` on that side: `a.max - b.min` to the left,
/// `b.max - a.min` to the right, i.e. the sum of half sizes minus the centre
/// distance, exactly as the centred-box contact computes it.
///
/// Written with masks, not branches: each of the three choices is a coin
/// toss from pair to pair, which a branch would mispredict half the time.
#[inline(always)]
fn mtv_of(a: (i32, i32, i32, i32), b: (i32, i32, i32, i32)) -> IVec2 {
    let (a0, a1, a2, a3) = (a.0 as i64, a.1 as i64, a.2 as i64, a.3 as i64);
    let (b0, b1, b2, b3) = (b.0 as i64, b.1 as i64, b.2 as i64, b.3 as i64);
    // All ones when the push is towards -x (-y).
    let mx = -(((b0 + b1) - (a0 + a1) >= 0) as i64);
    let my = -(((b2 + b3) - (a2 + a3) >= 0) as i64);
    let ox = ((a1 - b0) & mx) | ((b1 - a0) & !mx);
    let oy = ((a3 - b2) & my) | ((b3 - a2) & !my);
    // Negated where the mask is set.
    let (sx, sy) = ((ox ^ mx) - mx, (oy ^ my) - my);
    let on_x = -((ox <= oy) as i64);
    IVec2::new((sx & on_x) as i32, (sy & !on_x) as i32)
}

/// Tuning of a [`BroadPhase`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BroadPhaseConfig {
    /// `log2` of the finest strip height in units (clamped to `4..=32`).
    /// Best at a few times the height of the common small body (only the
    /// boxes reaching into the next strip scan it): the default, 15, is
    /// 128 px.
    pub strip_shift: u32,
    /// `log2` of the ratio between the strip heights of consecutive levels
    /// (clamped to `1..=28`); default 2 (x4).
    pub level_shift: u32,
    /// Least number of dynamic boxes per parallel batch; default 1024.
    pub batch: usize,
    /// Which compiled versions of the hot loops run (module docs, "Compiled
    /// twice"): the best the CPU has (the default), or always the x86-64
    /// baseline, to test the baseline on a machine with AVX2 and to compare
    /// the two in benchmarks. The results are the same bit for bit.
    pub isa: Isa,
}

impl Default for BroadPhaseConfig {
    fn default() -> Self {
        Self {
            strip_shift: 15,
            level_shift: 2,
            batch: 1024,
            isa: Isa::Best,
        }
    }
}

/// Id-range parts per thread of the parallel output sort: a few, so that
/// work stealing evens out parts of unequal sizes.
const PARTS_PER_THREAD: usize = 4;

/// What one batch of work covers.
#[derive(Debug, Clone, Copy)]
enum Work {
    /// Dynamic strips (row-table indices): same-level pairs.
    Rows(u32, u32),
    /// Dynamic boxes on levels above 0 (entry indices) against lower levels
    /// of both sets.
    CrossDynamic(u32, u32),
    /// Static boxes on levels above 0 against lower dynamic levels.
    CrossStatic(u32, u32),
}

/// The broad phase: a static set indexed once, a dynamic set updated every
/// tick, and the pair search over both. See the [module docs](self).
///
/// Cloning copies the sets and every buffer: the clone continues
/// incrementally from the same state.
#[derive(Debug, Clone)]
pub struct BroadPhase {
    levels: Levels,
    batch: usize,
    isa: Isa,
    statics: Strips,
    dynamics: Strips,
    work: Vec<Work>,
    /// Sweep buffers (candidate pairs), one per work item.
    scratch: Vec<sweep::Scratch>,
    pairs: Buffers<(u32, u32)>,
    contacts: Buffers<(u32, u32, IVec2)>,
}

impl Default for BroadPhase {
    fn default() -> Self {
        Self::new(BroadPhaseConfig::default())
    }
}

/// Statistics of the last update, for tuning and benchmarks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct BroadPhaseStats {
    /// Static boxes.
    pub statics: usize,
    /// Dynamic boxes.
    pub dynamics: usize,
    /// Non-empty dynamic strips.
    pub dynamic_strips: usize,
    /// Dynamic boxes that changed strip at the last update.
    pub movers: usize,
    /// Whether the last update sorted from scratch rather than incrementally.
    pub full_sort: bool,
}

impl BroadPhase {
    /// An empty broad phase.
    pub fn new(config: BroadPhaseConfig) -> Self {
        Self {
            levels: Levels::new(config.strip_shift, config.level_shift),
            batch: config.batch.max(1),
            isa: config.isa,
            statics: Strips::default(),
            dynamics: Strips::default(),
            work: Vec::new(),
            scratch: Vec::new(),
            pairs: Buffers::default(),
            contacts: Buffers::default(),
        }
    }

    /// Replaces the static set (bodies that never move): indexed once here,
    /// then only read by every tick.
    pub fn set_static(&mut self, items: &[(u32, Bounds)]) {
        self.statics.update(&self.levels, items, false, 0, self.isa);
    }

    /// Replaces the dynamic set with this tick's boxes. Passing the same
    /// bodies in the same order every tick (the usual case) makes the update
    /// incremental; any other input is still correct, just sorted afresh.
    pub fn update_dynamic(&mut self, items: &[(u32, Bounds)]) {
        self.dynamics
            .update(&self.levels, items, false, 0, self.isa);
    }

    /// [`Self::update_dynamic`] with the work split over the current rayon
    /// pool; the resulting state is identical.
    pub fn update_dynamic_par(&mut self, items: &[(u32, Bounds)]) {
        let chunk = self.chunk_target(items.len());
        self.dynamics
            .update(&self.levels, items, true, chunk, self.isa);
    }

    /// Boxes per parallel batch: at least `batch`, about two batches per
    /// thread (enough for work stealing to even out, few enough that the
    /// per-batch costs stay small).
    fn chunk_target(&self, n: usize) -> usize {
        self.batch
            .max(n / (2 * rayon::current_num_threads()))
            .max(1)
    }

    /// Statistics of the current sets and of the last update.
    pub fn stats(&self) -> BroadPhaseStats {
        BroadPhaseStats {
            statics: self.statics.len(),
            dynamics: self.dynamics.len(),
            dynamic_strips: self.dynamics.rows.len(),
            movers: self.dynamics.last_movers,
            full_sort: self.dynamics.last_full_sort,
        }
    }

    /// Every pair (dynamic-dynamic and dynamic-static) whose boxes overlap,
    /// as `(smaller id, larger id)`, sorted; on this thread only.
    pub fn find_pairs(&mut self, out: &mut Vec<(u32, u32)>) {
        self.run(&PairKernel, out, false);
    }

    /// [`Self::find_pairs`] on the current rayon pool; same output.
    pub fn find_pairs_par(&mut self, out: &mut Vec<(u32, u32)>) {
        self.run(&PairKernel, out, true);
    }

    /// Every overlapping pair with its box-box MTV ([`aabb_mtv`], moving the
    /// first body), sorted by ids: the AABB-only fast path, computed straight
    /// from the sorted box arrays; on this thread only.
    pub fn contacts_aabb(&mut self, out: &mut Vec<(u32, u32, IVec2)>) {
        self.run(&AabbKernel, out, false);
    }

    /// [`Self::contacts_aabb`] on the current rayon pool; same output.
    pub fn contacts_aabb_par(&mut self, out: &mut Vec<(u32, u32, IVec2)>) {
        self.run(&AabbKernel, out, true);
    }

    /// The general path: for every overlapping pair of boxes, asks
    /// `narrow(first id, second id)` for the MTV of the actual shapes (moving
    /// the first) and keeps the pairs that answer `Some`; sorted by ids; on
    /// this thread only.
    pub fn contacts_with<F>(&mut self, narrow: &F, out: &mut Vec<(u32, u32, IVec2)>)
    where
        F: Fn(u32, u32) -> Option<IVec2> + Sync,
    {
        self.run(&NarrowKernel(narrow), out, false);
    }

    /// [`Self::contacts_with`] on the current rayon pool; same output.
    pub fn contacts_with_par<F>(&mut self, narrow: &F, out: &mut Vec<(u32, u32, IVec2)>)
    where
        F: Fn(u32, u32) -> Option<IVec2> + Sync,
    {
        self.run(&NarrowKernel(narrow), out, true);
    }

    /// Calls `f(id)` for every box of the static set whose interior overlaps
    /// `b`'s (in no particular order): one box query, for callers that know
    /// which few boxes changed.
    pub fn query_static(&self, b: &Bounds, f: impl FnMut(u32)) {
        Self::query(&self.levels, &self.statics, b, f);
    }

    /// [`Self::query_static`] over the dynamic set as the last update left it.
    pub fn query_dynamic(&self, b: &Bounds, f: impl FnMut(u32)) {
        Self::query(&self.levels, &self.dynamics, b, f);
    }

    fn query(lv: &Levels, set: &Strips, b: &Bounds, mut f: impl FnMut(u32)) {
        if set.len() == 0 {
            return;
        }
        let q = (b.min.x, b.max.x, b.min.y, b.max.y);
        sweep::query(lv, set, q, |j| f(set.id[j]));
    }

    /// Plans the batches, runs `kernel` over them and sorts the result.
    fn run<T, K>(&mut self, kernel: &K, out: &mut Vec<T>, par: bool)
    where
        T: Keyed,
        K: Kernel<T>,
        Self: HasBuffers<T>,
    {
        self.plan(par);
        let n = self.work.len();
        let (lv, dy, st, isa) = (&self.levels, &self.dynamics, &self.statics, self.isa);
        let (mut id_lo, mut id_hi) = (dy.id_lo, dy.id_hi);
        if st.len() > 0 {
            id_lo = id_lo.min(st.id_lo);
            id_hi = id_hi.max(st.id_hi);
        }
        let work = &self.work;
        if self.scratch.len() < n {
            self.scratch.resize_with(n, Default::default);
        }
        let scratch = &mut self.scratch[..n];
        let bufs = <Self as HasBuffers<T>>::buffers(&mut self.pairs, &mut self.contacts);
        let parts = if par {
            PARTS_PER_THREAD * rayon::current_num_threads()
        } else {
            1
        };
        let (item_bufs, split) = bufs.prepare(n, parts, id_lo, id_hi);
        type Job<'a, T> = ((&'a Work, &'a mut [Vec<T>]), &'a mut sweep::Scratch);
        let job = |((w, out), c): Job<'_, T>| {
            let mut sink = Emit {
                out: Parts::new(out, split),
                kernel,
            };
            run_work(lv, dy, st, isa, *w, c, &mut sink);
        };
        if par {
            use rayon::prelude::*;
            work.par_iter()
                .zip(item_bufs.par_chunks_mut(split.parts))
                .zip(scratch.par_iter_mut())
                .for_each(job);
        } else {
            work.iter()
                .zip(item_bufs.chunks_mut(split.parts))
                .zip(scratch.iter_mut())
                .for_each(job);
        }
        bufs.finish(out, par, isa);
    }

    /// Cuts the work into batches: one of each kind on one thread; batches of
    /// about `max(batch, dynamics / (2 * threads))` boxes in parallel.
    fn plan(&mut self, par: bool) {
        self.work.clear();
        let (dy, st) = (&self.dynamics, &self.statics);
        if dy.len() == 0 {
            return;
        }
        let target = if par {
            self.chunk_target(dy.len())
        } else {
            usize::MAX
        };
        // Same-level strips, cut at strip boundaries.
        let mut start = 0usize;
        let mut count = 0usize;
        for (ri, r) in dy.rows.iter().enumerate() {
            count += (r.end - r.start) as usize;
            if count >= target {
                self.work.push(Work::Rows(start as u32, ri as u32 + 1));
                start = ri + 1;
                count = 0;
            }
        }
        if start < dy.rows.len() {
            self.work
                .push(Work::Rows(start as u32, dy.rows.len() as u32));
        }
        // Larger levels against smaller ones: fewer boxes, more work each.
        let cross_target = if par {
            (target / 16).max(16)
        } else {
            usize::MAX
        };
        let mut push_cross = |from: usize, to: usize, f: fn(u32, u32) -> Work| {
            let mut s = from;
            while s < to {
                let e = to.min(s.saturating_add(cross_target));
                self.work.push(f(s as u32, e as u32));
                s = e;
            }
        };
        push_cross(dy.level_start[1] as usize, dy.slots(), Work::CrossDynamic);
        push_cross(st.level_start[1] as usize, st.slots(), Work::CrossStatic);
    }
}

/// Runs one batch.
fn run_work<S: Sink>(
    lv: &Levels,
    dy: &Strips,
    st: &Strips,
    isa: Isa,
    w: Work,
    scratch: &mut sweep::Scratch,
    sink: &mut S,
) {
    match w {
        Work::Rows(s, e) => {
            sweep::same_level(isa, lv, dy, st, s as usize..e as usize, scratch, sink)
        }
        Work::CrossDynamic(s, e) => {
            sweep::cross_level(isa, lv, dy, s as usize..e as usize, dy, sink);
            sweep::cross_level(isa, lv, dy, s as usize..e as usize, st, sink);
        }
        Work::CrossStatic(s, e) => {
            sweep::cross_level(isa, lv, st, s as usize..e as usize, dy, sink)
        }
    }
}

/// Picks the buffers of one output type.
trait HasBuffers<T> {
    fn buffers<'a>(
        pairs: &'a mut Buffers<(u32, u32)>,
        contacts: &'a mut Buffers<(u32, u32, IVec2)>,
    ) -> &'a mut Buffers<T>;
}

impl HasBuffers<(u32, u32)> for BroadPhase {
    fn buffers<'a>(
        pairs: &'a mut Buffers<(u32, u32)>,
        _: &'a mut Buffers<(u32, u32, IVec2)>,
    ) -> &'a mut Buffers<(u32, u32)> {
        pairs
    }
}

impl HasBuffers<(u32, u32, IVec2)> for BroadPhase {
    fn buffers<'a>(
        _: &'a mut Buffers<(u32, u32)>,
        contacts: &'a mut Buffers<(u32, u32, IVec2)>,
    ) -> &'a mut Buffers<(u32, u32, IVec2)> {
        contacts
    }
}

/// What an overlapping pair becomes.
trait Kernel<T>: Sync {
    /// Pushes the output for entry `i` of `a` and entry `j` of `b`, if any.
    fn pair(&self, a: &Strips, i: usize, b: &Strips, j: usize, out: &mut Parts<'_, T>);
}

/// A sink writing one kernel's output into one work item's part buffers.
struct Emit<'a, T, K> {
    out: Parts<'a, T>,
    kernel: &'a K,
}

impl<T: Keyed, K: Kernel<T>> Sink for Emit<'_, T, K> {
    #[inline(always)]
    fn hit(&mut self, a: &Strips, i: usize, b: &Strips, j: usize) {
        self.kernel.pair(a, i, b, j, &mut self.out);
    }
}

/// Ids only.
struct PairKernel;

impl Kernel<(u32, u32)> for PairKernel {
    #[inline(always)]
    fn pair(&self, a: &Strips, i: usize, b: &Strips, j: usize, out: &mut Parts<'_, (u32, u32)>) {
        let (x, y) = (a.id[i], b.id[j]);
        out.push(if x < y { (x, y) } else { (y, x) });
    }
}

/// Ids and the box-box MTV.
struct AabbKernel;

impl Kernel<(u32, u32, IVec2)> for AabbKernel {
    #[inline(always)]
    fn pair(
        &self,
        a: &Strips,
        i: usize,
        b: &Strips,
        j: usize,
        out: &mut Parts<'_, (u32, u32, IVec2)>,
    ) {
        let ba = (a.minx[i], a.maxx[i], a.miny[i], a.maxy[i]);
        let bb = (b.minx[j], b.maxx[j], b.miny[j], b.maxy[j]);
        let (x, y) = (a.id[i], b.id[j]);
        out.push(if x < y {
            (x, y, mtv_of(ba, bb))
        } else {
            (y, x, mtv_of(bb, ba))
        });
    }
}

/// Ids and the MTV from a caller's narrow phase.
struct NarrowKernel<'f, F>(&'f F);

impl<F> Kernel<(u32, u32, IVec2)> for NarrowKernel<'_, F>
where
    F: Fn(u32, u32) -> Option<IVec2> + Sync,
{
    #[inline(always)]
    fn pair(
        &self,
        a: &Strips,
        i: usize,
        b: &Strips,
        j: usize,
        out: &mut Parts<'_, (u32, u32, IVec2)>,
    ) {
        let (x, y) = (a.id[i], b.id[j]);
        let (x, y) = if x < y { (x, y) } else { (y, x) };
        if let Some(m) = (self.0)(x, y) {
            out.push((x, y, m));
        }
    }
}

/// The reference answer by testing every pair: dynamic-dynamic and
/// dynamic-static pairs whose interiors overlap, with their [`aabb_mtv`],
/// sorted like [`BroadPhase::contacts_aabb`]. Quadratic: for tests and
/// benchmarks.
pub fn brute_force(
    statics: &[(u32, Bounds)],
    dynamics: &[(u32, Bounds)],
    out: &mut Vec<(u32, u32, IVec2)>,
) {
    out.clear();
    let mut push = |(ia, a): (u32, Bounds), (ib, b): (u32, Bounds)| {
        let (ia, a, ib, b) = if ia < ib {
            (ia, a, ib, b)
        } else {
            (ib, b, ia, a)
        };
        if let Some(m) = aabb_mtv(&a, &b) {
            out.push((ia, ib, m));
        }
    };
    for (k, &d) in dynamics.iter().enumerate() {
        for &e in &dynamics[k + 1..] {
            push(d, e);
        }
        for &s in statics {
            push(d, s);
        }
    }
    out.sort_unstable_by_key(|c| (c.0, c.1));
}
