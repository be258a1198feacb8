//! Output over semihosting (the emulator's stdout and stderr), and the handlers that report a
//! panic or a fault and exit the emulator with a failure status.

use core::fmt::Write;
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

    /// Reports a solve error (its message) on the host's stderr.
    pub fn solve_error(&mut self, error: &SolveError) -> Failed {
        if let Ok(mut err) = hio::hstderr() {
            let _ = writeln!(err, "firmware failed: {error}");
        }
        Failed
    }
}

#[panic_handler]
fn panic(info: &PanicInfo) -> ! {
    if let Ok(mut err) = hio::hstderr() {
        let _ = writeln!(err, "firmware panicked: {info}");
    }
    debug::exit(EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}

// cortex-m-rt requires the fault handler to be an `unsafe fn`; it only reports.
#[allow(unsafe_code)]
#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    if let Ok(mut err) = hio::hstderr() {
        let _ = writeln!(err, "firmware faulted: {frame:?}");
    }
    debug::exit(EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}
