//! The host build of the firmware's revolutions: prints the same trace lines on stdout (compared
//! with the firmware's by `.ci/embedded`), then the host's ns per step of each scene on stderr.

use std::hint::black_box;
use std::io::{self, Write};
use std::process::ExitCode;
use std::time::Instant;

use mechgen_embedded_trace::{PistonCrank, PistonCrankDynamics, Revolution, STEPS, Scene};

/// Revolutions timed per scene; the median is reported.
const TIMED_REVOLUTIONS: usize = 201;

fn main() -> ExitCode {
    let mut out = io::stdout().lock();
    let traced = trace(PistonCrank::default(), &mut out)
        .and_then(|()| trace(PistonCrankDynamics::default(), &mut out));
    if let Err(error) = traced {
        eprintln!("host trace failed: {error}");
        return ExitCode::FAILURE;
    }
    for (label, ns) in [
        (PistonCrank::LABEL, ns_per_step(PistonCrank::default())),
        (
            PistonCrankDynamics::LABEL,
            ns_per_step(PistonCrankDynamics::default()),
        ),
    ] {
        match ns {
            Ok(ns) => eprintln!("# host {label} ns_per_step {ns:.0}"),
            Err(error) => {
                eprintln!("host timing failed: {error}");
                return ExitCode::FAILURE;
            }
        }
    }
    ExitCode::SUCCESS
}

/// Writes every state of a revolution, assembly included, as the firmware does.
fn trace<M: Scene>(mechanism: M, out: &mut impl Write) -> Result<(), String>
where
    mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    let mut revolution = Revolution::new(mechanism).map_err(|e| e.to_string())?;
    loop {
        let mut line = revolution.line();
        let bytes = line
            .finish()
            .map_err(|_| "trace line too long".to_owned())?;
        out.write_all(bytes).map_err(|e| e.to_string())?;
        if revolution.done() {
            return Ok(());
        }
        revolution.step().map_err(|e| e.to_string())?;
    }
}

/// The median over [`TIMED_REVOLUTIONS`] revolutions of the mean time of a step (assembly not
/// timed), in ns.
fn ns_per_step<M: Scene + Clone>(mechanism: M) -> Result<f64, String>
where
    mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    let mut times = Vec::with_capacity(TIMED_REVOLUTIONS);
    for _ in 0..TIMED_REVOLUTIONS {
        let mut revolution = Revolution::new(mechanism.clone()).map_err(|e| e.to_string())?;
        let start = Instant::now();
        while !revolution.done() {
            revolution.step().map_err(|e| e.to_string())?;
            black_box(revolution.state());
        }
        times.push(start.elapsed().as_secs_f64() * 1e9 / STEPS as f64);
    }
    times.sort_by(f64::total_cmp);
    Ok(times[times.len() / 2])
}
