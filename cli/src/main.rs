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
    let work = || {
        let mut stdout = io::BufWriter::new(io::stdout().lock());
        let mut stderr = io::stderr().lock();
        mechgen_cli::run(std::env::args_os().skip(1), &mut stdout, &mut stderr)
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
