//! A heap-counting global allocator (bytes in use and their peak) and a
//! panic counter, shared by the importer tests that bound memory: each test
//! binary installs the allocator itself:
//! `#[global_allocator] static ALLOC: peak::Counting = peak::Counting;`

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard, Once};

/// Counts the heap bytes in use and their peak.
pub struct Counting;

pub static CURRENT: AtomicUsize = AtomicUsize::new(0);
pub static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(l) };
        if !p.is_null() {
            let now = CURRENT.fetch_add(l.size(), Ordering::Relaxed) + l.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) };
        CURRENT.fetch_sub(l.size(), Ordering::Relaxed);
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        let q = unsafe { System.realloc(p, l, new) };
        if !q.is_null() {
            if new >= l.size() {
                let now = CURRENT.fetch_add(new - l.size(), Ordering::Relaxed) + new - l.size();
                PEAK.fetch_max(now, Ordering::Relaxed);
            } else {
                CURRENT.fetch_sub(l.size() - new, Ordering::Relaxed);
            }
        }
        q
    }
}

/// Peak heap use allowed while loading any generated file (beyond what was in
/// use before the load).
pub const PEAK_BYTES: usize = 256 << 20;

pub static PANICS: AtomicUsize = AtomicUsize::new(0);
static SERIAL: Mutex<()> = Mutex::new(());

/// One test at a time (the peak is process-wide), with the panic hook set.
pub fn serial() -> MutexGuard<'static, ()> {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            PANICS.fetch_add(1, Ordering::SeqCst);
            default(info);
        }));
    });
    SERIAL.lock().unwrap_or_else(|e| e.into_inner())
}

/// Runs `f` and checks that it did not panic (even caught) and stayed within
/// [`PEAK_BYTES`] of extra heap; returns its result and the extra peak.
pub fn measured<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let panics = PANICS.load(Ordering::SeqCst);
    let base = CURRENT.load(Ordering::SeqCst);
    PEAK.store(base, Ordering::SeqCst);
    let out = f();
    let peak = PEAK.load(Ordering::SeqCst).saturating_sub(base);
    assert_eq!(
        PANICS.load(Ordering::SeqCst),
        panics,
        "a panic happened (and its message was printed) while loading"
    );
    assert!(
        peak < PEAK_BYTES,
        "peak heap {peak} bytes is over {PEAK_BYTES}"
    );
    (out, peak)
}
