//! The integrator allocates nothing once built: fixed and error-controlled steps, landing on
//! requested times, runs with a callback, the energy book, the reactions, `set_free`, and the
//! error paths (a toggle of the partition, Newton failure, a step below its minimum, a
//! non-finite force) with their descriptions, on fixed-size scenes.
//!
//! A counting global allocator wraps the system one (as `tests/tests/no_alloc.rs` does for
//! the solver). This file holds a single test so that no other test thread allocates while it
//! counts.

mod common;

use core::alloc::{GlobalAlloc, Layout};
use core::cell::Cell;
use core::fmt::{self, Write};
use core::sync::atomic::{AtomicUsize, Ordering};
use std::alloc::System;

use common::free_pendulum::FreePendulum;
use common::scene::Scene;
use common::sliders::Sliders;
use mechgen_runtime::{Integrator, IntegratorOptions, Solver, StepControl};

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    // Only the measuring thread counts (libtest's own threads may allocate meanwhile).
    static COUNTING: Cell<bool> = const { Cell::new(false) };
}

fn count() {
    if COUNTING.with(Cell::get) {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
    }
}

struct Counting;

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

#[global_allocator]
static GLOBAL: Counting = Counting;

/// A `fmt::Write` that only counts bytes.
struct Sink(usize);

impl Write for Sink {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        self.0 += s.len();
        Ok(())
    }
}

fn fixed(step: f64) -> IntegratorOptions {
    IntegratorOptions {
        control: StepControl::Fixed { step },
        ..IntegratorOptions::default()
    }
}

/// Runs `f` while counting allocations on this thread; returns how many it made.
fn counted(f: impl FnOnce()) -> usize {
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    COUNTING.with(|c| c.set(true));
    f();
    COUNTING.with(|c| c.set(false));
    ALLOCATIONS.load(Ordering::Relaxed) - before
}

#[test]
fn the_integrator_steps_without_allocating() {
    // The counter is live: a real allocation is seen.
    assert!(counted(|| drop(std::hint::black_box(vec![1u8; 8]))) > 0);
    let mut sink = Sink(0);

    // A swing, error-controlled: steps, landing, a run, the book, reactions, a restart.
    let p = FreePendulum::released(-0.4, 1.0);
    let mut swing = Integrator::new(
        Solver::new(Scene::new(p.clone())),
        0.0,
        IntegratorOptions::default(),
    )
    .unwrap();
    let allocations = counted(|| {
        for _ in 0..20 {
            swing.step().unwrap();
        }
        swing.step_to(0.37).unwrap();
        let mut total = 0.0;
        swing.run(0.8, |_, energy| total += energy.total()).unwrap();
        assert!(total.is_finite() && swing.energy().kinetic > 0.0);
        assert!(swing.constraint_forces().unwrap()[0].is_finite());
        swing.set_free(0, -1.0, 0.5).unwrap();
        swing.step_to(1.0).unwrap();
    });
    assert_eq!(allocations, 0, "error-controlled swing");

    // Two stiff sliders, fixed steps (the linear predictor, two free degrees of freedom).
    let sliders = Sliders {
        masses: [1.0, 1.0],
        k1: 80.0,
        k2: 2e11,
        c2: 0.0,
        gap: 0.5,
        initial: [(0.1, 0.0), (0.6, 0.0)],
        free: [[0.0; 3]; 2],
    };
    let mut stiff = Integrator::new(Solver::new(Scene::new(sliders)), 0.0, fixed(0.01)).unwrap();
    let allocations = counted(|| {
        stiff.step_to(0.5).unwrap();
    });
    assert_eq!(allocations, 0, "stiff");

    // Error paths and their descriptions.
    let mut toggle = p.clone();
    toggle.free_x = true;
    toggle.initial = (Some(toggle.length * (-2.0_f64).cos()), 8.0);
    toggle.guess = -2.0;
    let mut toggling = Integrator::new(
        Solver::new(Scene::new(toggle)),
        0.0,
        IntegratorOptions::default(),
    )
    .unwrap();
    let mut failing = Integrator::new(
        Solver::new(Scene::new(p.clone())),
        0.0,
        IntegratorOptions {
            max_iterations: 1,
            newton_tolerance: 1e-300,
            ..fixed(0.05)
        },
    )
    .unwrap();
    let mut nan = p.clone();
    nan.nan_after = 0.05;
    let mut poisoned = Integrator::new(Solver::new(Scene::new(nan)), 0.0, fixed(0.01)).unwrap();
    let allocations = counted(|| {
        for integrator in [&mut toggling, &mut failing, &mut poisoned] {
            let error = integrator.step_to(2.0).map(|_| ()).unwrap_err();
            write!(sink, "{error} {}", integrator.describe(&error)).unwrap();
        }
    });
    assert_eq!(allocations, 0, "error paths");
    assert!(sink.0 > 0);
}
