//! The `mechgen` binary: `expand`, `check`, `solve` and `simulate` `.mech` scenes (see
//! `mechgen --help`).

use std::io::{self, Write};
use std::process::ExitCode;

/// mechgen's parser and checker recurse per nesting level and per operator of a chain. The
/// input limits (`mechgen::syntax::limits`) bound that depth; this stack leaves a wide margin even
/// for unoptimised builds, whose frames are large. Only touched pages are committed.
const STACK_BYTES: usize = 256 << 20;

fn main() -> ExitCode {
    std::panic::set_hook(Box::new(|info| {
        let _ = writeln!(
            io::stderr(),
            "error: internal error in mechgen (a bug, not a problem with your input): {info}\n  \
             please report it together with the command line and the scene"
        );
    }));
    let closed = startup::stdout_was_closed();
    let work = move || {
        let mut stderr = io::stderr().lock();
        let args = std::env::args_os().skip(1);
        if closed {
            return mechgen_cli::run(args, &mut Closed, &mut stderr);
        }
        let mut stdout = io::BufWriter::new(io::stdout().lock());
        mechgen_cli::run(args, &mut stdout, &mut stderr)
    };
    let code = match std::thread::Builder::new()
        .stack_size(STACK_BYTES)
        .spawn(work)
    {
        // A panic was already reported by the hook.
        Ok(handle) => handle.join().unwrap_or(101),
        // No thread (resource limits): run on the main thread's smaller stack instead.
        Err(_) => work(),
    };
    ExitCode::from(code)
}

/// Whether standard output was closed when mechgen started (`mechgen solve … >&-`).
///
/// Rust's runtime reopens a closed standard descriptor on `/dev/null` before `main`, so writes
/// to it would "succeed" and a run would report rows it never wrote. Nothing in `main` can tell
/// that descriptor from a `/dev/null` the caller opened on purpose (`> /dev/null`, or Python's
/// `subprocess.DEVNULL`, read-write like the runtime's), so the descriptor is looked at before
/// the runtime touches it: a function in `.init_array` runs before Rust's start-up code. That
/// needs `unsafe` (an FFI call and a link section), which the workspace otherwise denies: one
/// `fcntl(1, F_GETFD)`, which only reads the descriptor's flags. Elsewhere than Linux standard
/// output is taken as open.
#[cfg(target_os = "linux")]
#[allow(unsafe_code)]
mod startup {
    use std::sync::atomic::{AtomicBool, Ordering};

    static STDOUT_CLOSED: AtomicBool = AtomicBool::new(false);

    unsafe extern "C" {
        fn fcntl(fd: i32, cmd: i32, ...) -> i32;
    }

    /// `F_GETFD` on Linux (every architecture).
    const F_GETFD: i32 = 1;

    extern "C" fn record_stdout() {
        // SAFETY: `F_GETFD` reads the descriptor's flags and has no other effect; a closed
        // descriptor makes it return -1 (EBADF).
        let closed = unsafe { fcntl(1, F_GETFD) } == -1;
        STDOUT_CLOSED.store(closed, Ordering::Relaxed);
    }

    #[used]
    #[unsafe(link_section = ".init_array")]
    static RECORD_STDOUT: extern "C" fn() = record_stdout;

    pub fn stdout_was_closed() -> bool {
        STDOUT_CLOSED.load(Ordering::Relaxed)
    }
}

#[cfg(not(target_os = "linux"))]
mod startup {
    pub fn stdout_was_closed() -> bool {
        false
    }
}

/// Standard output that was closed: every write fails, as it would on the closed descriptor.
struct Closed;

impl Write for Closed {
    fn write(&mut self, _: &[u8]) -> io::Result<usize> {
        Err(io::Error::other(
            "standard output is closed; redirect it with `> FILE` or `> /dev/null`",
        ))
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}
