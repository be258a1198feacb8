//! The accuracy-against-run-time report: every example scene with a closed form, every way of
//! solving it (generated, finite differences, automatic differentiation, interpreter), swept
//! over solver settings; writes `report/` (Markdown, SVG work-precision diagrams, CSV).
//!
//! `cargo run --release --example report -- [--out DIR] [--quick] [--scene seed|four_bar]`

use std::io::{IsTerminal, Write};
use std::time::Instant;

use mechgen_examples::report::{self, Options, Progress};

fn main() {
    let options = Options::from_args(std::env::args().skip(1)).unwrap_or_else(|e| {
        eprintln!("error: {e}");
        std::process::exit(2)
    });
    if cfg!(debug_assertions) {
        eprintln!("warning: debug build; timings are not representative (use --release)");
    }
    let mut bar = Bar::new();
    match report::run(&options, &mut |p| bar.show(p)) {
        Ok(report) => print!("{}", report.summary()),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}

/// A textual progress bar on stderr: redrawn in place on a terminal, otherwise one line per
/// tenth of the work (so logs stay short).
struct Bar {
    terminal: bool,
    start: Instant,
    last_tenth: usize,
}

impl Bar {
    fn new() -> Self {
        Bar {
            terminal: std::io::stderr().is_terminal(),
            start: Instant::now(),
            last_tenth: usize::MAX,
        }
    }

    fn show(&mut self, p: &Progress<'_>) {
        const WIDTH: usize = 30;
        let fraction = if p.total == 0 {
            1.0
        } else {
            p.done as f64 / p.total as f64
        };
        let filled = ((fraction * WIDTH as f64) as usize).min(WIDTH);
        let elapsed = self.start.elapsed().as_secs_f64();
        let line = format!(
            "[{}{}] {:>3}/{} {:>4.0} s  {} {}",
            "#".repeat(filled),
            ".".repeat(WIDTH - filled),
            p.done,
            p.total,
            elapsed,
            p.scene,
            p.task
        );
        let mut err = std::io::stderr().lock();
        if self.terminal {
            // Clear to the end of the line: the previous task may have been longer.
            let _ = write!(err, "\r{line}\x1b[K");
            if p.done == p.total {
                let _ = writeln!(err);
            }
        } else {
            let tenth = (fraction * 10.0) as usize;
            if tenth != self.last_tenth || p.done == p.total {
                self.last_tenth = tenth;
                let _ = writeln!(err, "{line}");
            }
        }
        let _ = err.flush();
    }
}
