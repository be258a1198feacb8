//! A counting global allocator for the no-allocation tests (`no_alloc.rs`,
//! `dynamics_no_alloc.rs`): it forwards to the system allocator and counts the allocations made
//! on the thread that asked to count ([`start`]). A test binary installs it with
//! `#[global_allocator] static GLOBAL: Counting = Counting;`, and holds a single test so that no
//! other test thread allocates while it counts.

use core::alloc::{GlobalAlloc, Layout};
use core::cell::Cell;
use core::fmt::{self, Write};
use core::sync::atomic::{AtomicUsize, Ordering};
use std::alloc::System;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    // Only the measuring thread counts: libtest's own threads may allocate meanwhile (output
    // capture, timing), which made a global count flaky under load. A `const` `Cell` needs no
    // allocation or destructor, so reading it inside the allocator is safe.
    static COUNTING: Cell<bool> = const { Cell::new(false) };
}

/// Counts this thread's allocations from now on.
pub fn start() {
    COUNTING.with(|c| c.set(true));
}

/// Stops counting this thread's allocations.
pub fn stop() {
    COUNTING.with(|c| c.set(false));
}

/// The allocations counted so far.
pub fn allocations() -> usize {
    ALLOCATIONS.load(Ordering::SeqCst)
}

fn count() {
    if COUNTING.with(Cell::get) {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
    }
}

/// The counting allocator.
pub struct Counting;

// Implementing `GlobalAlloc` requires `unsafe`; this impl only counts and forwards to `System`.
#[allow(unsafe_code)]
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

/// A `fmt::Write` that only counts bytes, standing in for a UART or a fixed buffer.
pub struct Sink(pub usize);

impl Write for Sink {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        self.0 += s.len();
        Ok(())
    }
}
