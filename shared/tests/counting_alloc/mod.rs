//! A counting global allocator shared by the allocation tests. Each test
//! binary that uses it installs it itself:
//! `#[global_allocator] static GLOBAL: counting_alloc::Counting = counting_alloc::Counting;`
#![allow(dead_code)] // Each test binary uses its own subset.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The system allocator, counting allocation calls (reallocations too) and
/// bytes made on threads that opted in. The count is per thread: with one
/// shared counter, a test counting on another thread at the same time (say
/// one that allocates on purpose to check the counter) would add to this
/// one's figure.
pub struct Counting;

/// One thread's counter.
struct Counter {
    on: Cell<bool>,
    calls: Cell<u64>,
    bytes_in: Cell<u64>,
    bytes_out: Cell<u64>,
}

thread_local! {
    static COUNTER: Counter = const {
        Counter {
            on: Cell::new(false),
            calls: Cell::new(0),
            bytes_in: Cell::new(0),
            bytes_out: Cell::new(0),
        }
    };
}

/// Records `calls` allocation calls taking `bytes_in` bytes and freeing
/// `bytes_out`.
fn note(calls: u64, bytes_in: usize, bytes_out: usize) {
    let _ = COUNTER.try_with(|c| {
        if c.on.get() {
            c.calls.set(c.calls.get() + calls);
            c.bytes_in.set(c.bytes_in.get() + bytes_in as u64);
            c.bytes_out.set(c.bytes_out.get() + bytes_out as u64);
        }
    });
}

// SAFETY: every call is forwarded unchanged to the system allocator.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note(1, layout.size(), 0);
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note(1, layout.size(), 0);
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note(1, new_size, layout.size());
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        note(0, 0, layout.size());
        unsafe { System.dealloc(ptr, layout) }
    }
}

/// What the current thread allocated while running `f`: its result,
/// allocation calls (reallocations included) and the change in live bytes.
pub fn calls_and_bytes<R>(f: impl FnOnce() -> R) -> (R, u64, i64) {
    let read = || COUNTER.with(|c| (c.calls.get(), c.bytes_in.get(), c.bytes_out.get()));
    let (calls, bytes_in, bytes_out) = read();
    COUNTER.with(|c| c.on.set(true));
    let r = f();
    COUNTER.with(|c| c.on.set(false));
    let (calls2, bytes_in2, bytes_out2) = read();
    let net = (bytes_in2 - bytes_in) as i64 - (bytes_out2 - bytes_out) as i64;
    (r, calls2 - calls, net)
}

/// Counts allocation calls made by `f` on this thread.
pub fn allocations(f: impl FnOnce()) -> u64 {
    calls_and_bytes(f).1
}
