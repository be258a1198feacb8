//! Output over semihosting (the emulator's stdout and stderr), and the handlers that report a
//! panic or a fault and exit the emulator with a failure status.

use core::panic::PanicInfo;

use cortex_m_rt::{ExceptionFrame, exception};
use cortex_m_semihosting::debug::{self, EXIT_FAILURE};
use cortex_m_semihosting::hio::{self, HostStream};
use mechgen_embedded_trace::Line;
use mechgen_runtime::SolveError;

use crate::Failed;

/// The host's stdout, for trace and cost lines.
pub struct Out(HostStream);

impl Out {
    /// Opens the host's stdout.
    pub fn open() -> Result<Self, Failed> {
        hio::hstdout().map(Self).map_err(|()| Failed)
    }

    /// Writes a finished line.
    pub fn line(&mut self, line: &mut Line) -> Result<(), Failed> {
        let bytes = line.finish().map_err(|_| self.failure(b"line too long"))?;
        self.0.write_all(bytes).map_err(|()| Failed)
    }

    /// Reports `what` on the host's stderr.
    pub fn failure(&mut self, what: &[u8]) -> Failed {
        if let Ok(mut err) = hio::hstderr() {
            let _ = err.write_all(b"firmware failed: ");
            let _ = err.write_all(what);
            let _ = err.write_all(b"\n");
        }
        Failed
    }

    /// Reports a solve error on the host's stderr: its kind and time (as hex bits), not its
    /// `Display` message, whose `f64` formatting would add about 20 KB of `core::fmt` to flash
    /// (the host build of the same revolution prints the full message).
    pub fn solve_error(&mut self, error: &SolveError) -> Failed {
        let mut line = Line::text("firmware failed: ");
        line.push_bytes(kind(error).as_bytes());
        if let Some(time) = error.time() {
            line.push_bytes(b" at t (bits)");
            line.push(time);
        }
        if let (Ok(mut err), Ok(bytes)) = (hio::hstderr(), line.finish()) {
            let _ = err.write_all(bytes);
        }
        Failed
    }
}

/// What kind of failure `error` is, in words.
fn kind(error: &SolveError) -> &'static str {
    match error {
        SolveError::NoConvergence { .. } => "no convergence",
        SolveError::NoAssembly { .. } => "no assembly",
        SolveError::Singular { .. } => "singular configuration",
        SolveError::BranchFlip { .. } => "branch flip",
        SolveError::NonFinite { .. } => "non-finite value",
        _ => "solve error (see the host build's message)",
    }
}

/// Writes `line` to the host's stderr and exits the emulator with a failure status.
fn fail(mut line: Line) -> ! {
    if let (Ok(mut err), Ok(bytes)) = (hio::hstderr(), line.finish()) {
        let _ = err.write_all(bytes);
    }
    debug::exit(EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}

/// Reports the panic's location and, when it is a plain string, its message, without
/// `core::fmt` (a formatted message, such as a bounds check's, is not rendered: that would link
/// the formatting machinery; the location finds it).
#[panic_handler]
fn panic(info: &PanicInfo) -> ! {
    let mut line = Line::text("firmware panicked");
    if let Some(location) = info.location() {
        line.push_bytes(b" at ");
        line.push_bytes(location.file().as_bytes());
        line.push_bytes(b" line");
        line.push_decimal(location.line() as usize);
    }
    if let Some(message) = info.message().as_str() {
        line.push_bytes(b": ");
        line.push_bytes(message.as_bytes());
    }
    fail(line)
}

// cortex-m-rt requires the fault handler to be an `unsafe fn`; it only reports.
#[allow(unsafe_code)]
#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    let mut line = Line::text("firmware faulted at pc");
    line.push_decimal(frame.pc() as usize);
    fail(line)
}
