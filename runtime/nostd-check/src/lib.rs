//! Build check: generated code and `mechgen-runtime` linked into a `#![no_std]` static library
//! without an allocator.
#![no_std]

use core::fmt::{self, Write};

use mechgen_runtime::{Simulation, Solver, mechanism, write_csv_header};

mod free;

// Generated code, not a hand-written mechanism: this proves that what `mechanism!` emits (math
// shim, fixed-size storage, no std paths) links without std or alloc. The scene uses every joint
// kind, a time-varying driver, a branch invariant, and mass properties, gravity and every load
// kind (so the force solve is generated and run), so every emission path is exercised.
mechanism! {
    /// A slider-crank whose connecting rod is a distance link, driven by an oscillating crank.
    mechanism Linkage {
        param amplitude = 0.5;
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0) mass 2 inertia 0.1 centre (0.3, 0);
        body slider near (3.4, 0, 0) mass 1 inertia 0.05;
        joint pivot: revolute(frame, crank);
        joint guide: prismatic(frame, slider, along (1, 0));
        joint rod: distance(crank @ (1, 0), slider, 2.5);
        driver swing: angle(crank) = amplitude * sin(3 * t) + t^2 / 10;
        branch slider_ahead: dot(frame -> frame @ (1, 0), crank @ (1, 0) -> slider) > 0;
        gravity (0, -9.81);
        load gas: force(slider) = (-3 * sin(t), 0);
        load nudge: local_force(crank @ (1, 0)) = (0, 0.5);
        load brake: torque(crank) = -0.1 * t;
        load coil: spring(frame @ (5, 0), slider, stiffness 10, length 1.5, damping 0.2);
    }
}

/// Counts bytes, standing in for a serial port.
struct Sink(usize);

impl Write for Sink {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        self.0 += s.len();
        Ok(())
    }
}

/// Steps the pendulum to `t_end` and returns the CSV byte count (0 on any failure).
pub extern "C" fn mechgen_nostd_check(t_end: f64, steps: u32) -> usize {
    let mut sink = Sink(0);
    let Ok(mut simulation) = Simulation::new(Solver::new(Linkage::default()), 0.0) else {
        return 0;
    };
    if write_csv_header(simulation.solver().mechanism(), &mut sink).is_err() {
        return 0;
    }
    let mut ok = true;
    let run = simulation.run(t_end, steps as usize, |state| {
        ok &= state.write_csv_row(&mut sink).is_ok();
        ok &= state.constraint_forces().iter().all(|f| f.is_finite());
    });
    match run {
        Ok(()) if ok => sink.0,
        Ok(()) => 0,
        Err(error) => {
            let _ = write!(sink, "{}", simulation.solver().describe(&error));
            0
        }
    }
}

/// Keeps the entry point (and so the monomorphised solver) in the archive: without
/// `#[no_mangle]`, which needs `unsafe` syntax in edition 2024, nothing else references it.
#[used]
static ENTRY: extern "C" fn(f64, u32) -> usize = mechgen_nostd_check;
/// The integrator's entry point, kept likewise.
#[used]
static INTEGRATE: extern "C" fn(f64) -> f64 = free::mechgen_nostd_integrate;

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}
