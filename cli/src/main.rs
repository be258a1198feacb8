//! The `mechgen` binary: `expand`, `check` and `solve` `.mech` scenes (see `mechgen --help`).

use std::io::{self, Write};
use std::process::ExitCode;

/// mechgen's parser and checker recurse per nesting level and per operator of a chain. The
/// input limits (`mechgen::limits`) bound that depth; this stack leaves a wide margin even
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
    let closed = stdout_was_closed();
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

/// Whether standard output was closed when mechgen started (`mechgen solve … >&-`). Rust's
/// runtime reopens a closed standard descriptor on `/dev/null`, read-write, so writes to it
/// would "succeed" and a run would report rows it never wrote; a redirection to `/dev/null`
/// opens it write-only, and stays a success. Read from `/proc` (Linux); elsewhere standard
/// output is taken as open.
fn stdout_was_closed() -> bool {
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::fs::MetadataExt;
        const ACCESS_MODE: u32 = 0o3;
        const READ_WRITE: u32 = 0o2;
        let Ok(info) = std::fs::read_to_string("/proc/self/fdinfo/1") else {
            return false;
        };
        let flags = info
            .lines()
            .find_map(|line| line.strip_prefix("flags:"))
            .and_then(|flags| u32::from_str_radix(flags.trim(), 8).ok());
        let same_file = |a: &std::fs::Metadata, b: &std::fs::Metadata| {
            (a.dev(), a.ino(), a.rdev()) == (b.dev(), b.ino(), b.rdev())
        };
        match (
            flags,
            std::fs::metadata("/proc/self/fd/1"),
            std::fs::metadata("/dev/null"),
        ) {
            (Some(flags), Ok(stdout), Ok(null)) => {
                flags & ACCESS_MODE == READ_WRITE && same_file(&stdout, &null)
            }
            _ => false,
        }
    }
    #[cfg(not(target_os = "linux"))]
    false
}

/// Standard output that was closed: every write fails, as it would on the closed descriptor.
struct Closed;

impl Write for Closed {
    fn write(&mut self, _: &[u8]) -> io::Result<usize> {
        Err(io::Error::other(
            "standard output is closed (a read-write /dev/null counts as closed: `>&-` leaves \
             one); redirect it with `> FILE` or `> /dev/null`",
        ))
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}
