//! Proves that solving, stepping, failing and formatting never touch the heap for `Const` dims.
//!
//! A counting global allocator wraps the system one. This file holds a single test so that no
//! other test thread allocates while it measures.

mod common;

use core::alloc::{GlobalAlloc, Layout};
use core::cell::Cell;
use core::fmt::{self, Write};
use core::sync::atomic::{AtomicUsize, Ordering};
use std::alloc::System;

use common::{Q, SliderCrank, reference};
use mechgen_runtime::{Simulation, Solver, write_csv_header};

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    // Only the measuring thread counts: libtest's own threads may allocate meanwhile (output
    // capture, timing), which made a global count flaky under load. A `const` `Cell` needs no
    // allocation or destructor, so reading it inside the allocator is safe.
    static COUNTING: Cell<bool> = const { Cell::new(false) };
}

fn count() {
    if COUNTING.with(Cell::get) {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
    }
}

struct Counting;

// Implementing `GlobalAlloc` requires `unsafe`; this impl only counts and forwards to `System`,
// under the same contract the caller already upholds.
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

#[global_allocator]
static GLOBAL: Counting = Counting;

/// A `fmt::Write` that only counts bytes, standing in for a UART or fixed buffer.
struct Sink(usize);

impl Write for Sink {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        self.0 += s.len();
        Ok(())
    }
}

#[test]
fn solving_and_stepping_never_allocate() {
    COUNTING.with(|c| c.set(true));
    drop(core::hint::black_box(Box::new(0_u8)));
    let before = ALLOCATIONS.load(Ordering::SeqCst);
    assert!(before > 0, "the counting allocator is not installed");

    let mut solver = Solver::new(reference(SliderCrank::default()));
    let mut guess = Q::zeros();
    mechgen_runtime::Mechanism::initial_guess(solver.mechanism(), &mut guess);
    let state = solver.solve(0.25, &guess).expect("assembles");
    let mut sink = Sink(0);
    write_csv_header(solver.mechanism(), &mut sink).unwrap();
    state.write_csv_row(&mut sink).unwrap();

    let mut simulation = Simulation::new(solver, 0.0).expect("assembles");
    let mut steps = 0;
    simulation
        .run(3.0, 500, |state| {
            steps += 1;
            state.write_csv_row(&mut sink).unwrap();
        })
        .expect("a full revolution solves");
    simulation.set_predictor(false);
    simulation.step_to(3.1).expect("solves");

    // Error paths: a NaN time, and a pose the rod is too short to reach.
    let nan = simulation.step_to(f64::NAN).unwrap_err();
    write!(sink, "{nan}").unwrap();
    simulation
        .solver_mut()
        .mechanism_mut()
        .inner_mut()
        .parameters
        .copy_from_slice(&[1.0, 0.5, 2.0, 0.3]);
    let unreachable = simulation.step_to(3.9).unwrap_err();
    write!(
        sink,
        "{}",
        unreachable.describe(simulation.solver().mechanism())
    )
    .unwrap();

    let allocations = ALLOCATIONS.load(Ordering::SeqCst) - before;
    assert_eq!(allocations, 0, "{allocations} heap allocations");
    assert_eq!(steps, 501);
    assert!(sink.0 > 0);
}
