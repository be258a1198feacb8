//! The seed piston-crank, kinematic and with its masses, stepped over one crank revolution on a
//! Cortex-M4F (QEMU's `mps2-an386`): every state is written over semihosting as the trace lines
//! the host build writes (compared by `.ci/embedded`), followed by the cost of a step: emulated
//! instructions (SysTick under `-icount shift=0`) and the stack high-water mark.
#![no_std]
#![no_main]
#![deny(unsafe_code)]
// Built without either scene only to measure the rest of the firmware's size.
#![cfg_attr(
    not(any(feature = "kinematics", feature = "dynamics")),
    allow(dead_code)
)]

mod report;
mod stack;

use cortex_m::peripheral::SYST;
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::entry;
use cortex_m_semihosting::debug::{self, EXIT_FAILURE, EXIT_SUCCESS};
#[cfg(feature = "kinematics")]
use mechgen_embedded_trace::PistonCrank;
#[cfg(feature = "dynamics")]
use mechgen_embedded_trace::PistonCrankDynamics;
use mechgen_embedded_trace::{Line, Revolution, STEPS, Scene};
use mechgen_runtime::Storage;
use mechgen_runtime::nalgebra::DefaultAllocator;

use report::Out;
use stack::Painted;

#[entry]
fn main() -> ! {
    let ok = run().is_ok();
    debug::exit(if ok { EXIT_SUCCESS } else { EXIT_FAILURE });
    // Reached only without a debugger or emulator to exit to.
    loop {
        cortex_m::asm::wfi();
    }
}

/// Why the run failed, already reported.
struct Failed;

fn run() -> Result<(), Failed> {
    let mut out = Out::open()?;
    let peripherals = cortex_m::Peripherals::take().ok_or(Failed)?;
    let mut clock = Clock::start(peripherals.SYST);
    calibrate(&mut clock, &mut out)?;
    #[cfg(feature = "kinematics")]
    revolution(PistonCrank::default(), &mut clock, &mut out)?;
    #[cfg(feature = "dynamics")]
    revolution(PistonCrankDynamics::default(), &mut clock, &mut out)?;
    Ok(())
}

/// Emulated instructions per SysTick tick: the AN386's processor clock is 25 MHz (40 ns a
/// tick) and `-icount shift=0` advances the emulator's clock 1 ns per instruction.
const INSTRUCTIONS_PER_TICK: u64 = 40;

/// SysTick, free-running from the processor clock over its full 24 bits (no interrupt).
struct Clock(SYST);

impl Clock {
    fn start(mut syst: SYST) -> Self {
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(0x00FF_FFFF);
        syst.clear_current();
        syst.enable_counter();
        Self(syst)
    }

    /// Runs `f`, returning its result and the instructions it took (to a tick: ±40).
    #[inline(always)]
    fn instructions<R>(&mut self, f: impl FnOnce() -> R) -> (R, u64) {
        let before = SYST::get_current();
        let result = f();
        let after = SYST::get_current();
        let ticks = before.wrapping_sub(after) & 0x00FF_FFFF;
        (result, u64::from(ticks) * INSTRUCTIONS_PER_TICK)
    }
}

/// Times `cortex_m::asm::delay(n)`, a loop of 2n + 2 instructions, so that the script can check
/// [`INSTRUCTIONS_PER_TICK`] (a wrong `-icount` or board would show here).
fn calibrate(clock: &mut Clock, out: &mut Out) -> Result<(), Failed> {
    const N: u32 = 1_000_000;
    let ((), measured) = clock.instructions(|| cortex_m::asm::delay(N));
    let mut line = Line::text("# calibration");
    line.push_bytes(b" expected");
    line.push_decimal(2 * N as usize + 2);
    line.push_bytes(b" measured");
    line.push_decimal(measured as usize);
    out.line(&mut line)
}

/// The cost of the steps of a revolution.
#[derive(Default)]
struct Cost {
    instructions: u64,
    max_instructions: u64,
    max_stack: usize,
}

/// Steps `mechanism` over a revolution, writing each state's trace line, then its cost line:
/// `# LABEL steps N instructions_total I instructions_max J stack_max S assembly_stack A
/// state_bytes B`.
fn revolution<M: Scene>(mechanism: M, clock: &mut Clock, out: &mut Out) -> Result<(), Failed>
where
    DefaultAllocator: Storage<M::Dim>,
{
    let painted = Painted::below_caller().map_err(|_| out.failure(b"stack window"))?;
    let (revolution, _) = clock.instructions(|| Revolution::new(mechanism));
    let assembly_stack = painted
        .high_water()
        .map_err(|_| out.failure(b"stack window"))?;
    let mut revolution = revolution.map_err(|e| out.solve_error(&e))?;
    out.line(&mut revolution.line())?;
    let mut cost = Cost::default();
    while !revolution.done() {
        let painted = Painted::below_caller().map_err(|_| out.failure(b"stack window"))?;
        let (stepped, instructions) = clock.instructions(|| revolution.step());
        let stack = painted
            .high_water()
            .map_err(|_| out.failure(b"stack window"))?;
        stepped.map_err(|e| out.solve_error(&e))?;
        cost.instructions += instructions;
        cost.max_instructions = cost.max_instructions.max(instructions);
        cost.max_stack = cost.max_stack.max(stack);
        out.line(&mut revolution.line())?;
    }
    let mut line = Line::text("# ");
    line.push_bytes(M::LABEL.as_bytes());
    for (name, value) in [
        ("steps", STEPS),
        // The total, not the mean: a 64-bit division would add 0.9 kB to the firmware.
        ("instructions_total", saturate(cost.instructions)),
        ("instructions_max", saturate(cost.max_instructions)),
        ("stack_max", cost.max_stack),
        ("assembly_stack", assembly_stack),
        ("state_bytes", core::mem::size_of::<Revolution<M>>()),
    ] {
        line.push_bytes(b" ");
        line.push_bytes(name.as_bytes());
        line.push_decimal(value);
    }
    out.line(&mut line)
}

/// `n` as a `usize` (32 bits here), or `usize::MAX` if it does not fit.
fn saturate(n: u64) -> usize {
    usize::try_from(n).unwrap_or(usize::MAX)
}
