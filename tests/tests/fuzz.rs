//! Deterministic mutation fuzzing of the example scenes: thousands of mutants (extreme and
//! degenerate numbers, deleted, duplicated and rewired statements, stray characters), each run
//! in-process through parse → check → the interpreter → assembly → a few steps. Every mutant
//! must end in a compile error, a typed solve error, or states whose constraints hold; no
//! panic, no `Ok` with a residual above tolerance, and a bounded number of evaluations
//! (counted, not timed).
//!
//! CI runs [`MUTANTS`] per scene. For a longer run on a developer's machine, set
//! `MECHGEN_FUZZ_MUTANTS` (per scene) and `MECHGEN_FUZZ_SEED`, e.g.
//! `MECHGEN_FUZZ_MUTANTS=100000 cargo test --release -p mechgen-tests --test fuzz -- --nocapture`.

use mechgen_cli::Interpreted;
use mechgen_runtime::{
    DEFAULT_MAX_HALVINGS, Mechanism, Simulation, Solver, SolverOptions, Stage, Structured, Unit,
    Vector, nalgebra::Dyn,
};

const SCENES: [&str; 3] = [
    include_str!("../../examples/scenes/piston_crank.mech"),
    include_str!("../../examples/scenes/four_bar.mech"),
    include_str!("../../examples/scenes/offset_slider.mech"),
];

/// Values a number literal is replaced with: degenerate, extreme, and just out of range.
const EXTREMES: [&str; 16] = [
    "0",
    "-1",
    "1e-300",
    "1e300",
    "1e150",
    "1e140",
    "1e20",
    "-1e20",
    "1e12",
    "1e-9",
    "sqrt(0 - 1)",
    "ln(0)",
    "1 / 0",
    "3.141592653589793",
    "1e5",
    "-0.5",
];

/// Mutants per scene in CI (4,500 in all, a few seconds).
const MUTANTS: usize = 1500;
/// Steps solved after assembly, over `DURATION` seconds.
const STEPS: usize = 6;
const DURATION: f64 = 0.02;

/// A small deterministic generator (SplitMix64): the corpus is the same on every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Byte ranges of the number literals of `text`.
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut found = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let starts = bytes[i].is_ascii_digit()
            && (i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_'));
        if starts {
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
                i += 1;
            }
            found.push((start, i));
        } else {
            i += 1;
        }
    }
    found
}

/// One mutation of `text`.
fn mutate(text: &str, rng: &mut Rng) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let statements: Vec<usize> = (0..lines.len())
        .filter(|&k| lines[k].trim_end().ends_with(';'))
        .collect();
    match rng.below(6) {
        // Most mutants change numbers: that is where the solver's limits are.
        0..=2 => {
            let mut out = text.to_owned();
            for _ in 0..1 + rng.below(2) {
                let spans = numbers(&out);
                let (start, end) = spans[rng.below(spans.len())];
                let value = EXTREMES[rng.below(EXTREMES.len())];
                out.replace_range(start..end, value);
            }
            out
        }
        3 => {
            let k = statements[rng.below(statements.len())];
            lines
                .iter()
                .enumerate()
                .filter(|&(i, _)| i != k)
                .map(|(_, l)| *l)
                .collect::<Vec<_>>()
                .join("\n")
        }
        4 => {
            let k = statements[rng.below(statements.len())];
            let mut out: Vec<&str> = lines.clone();
            out.insert(k, lines[k]);
            out.join("\n")
        }
        _ => {
            // A stray or swapped character somewhere.
            let mut bytes = text.as_bytes().to_vec();
            let at = rng.below(bytes.len());
            bytes[at] = b"(),;@.-*/0aZ_ "[rng.below(14)];
            String::from_utf8_lossy(&bytes).into_owned()
        }
    }
}

/// How one mutant ended.
#[derive(Debug, Default)]
struct Tally {
    compile_errors: usize,
    assembly_errors: usize,
    step_errors: usize,
    solved: usize,
    most_evaluations: u64,
}

/// The largest scaled residual of Φ at `q`: lengths over L, areas over L², angles as they are.
fn scaled_residual(m: &Interpreted, q: &Vector<Dyn>, t: f64) -> f64 {
    let mut phi = q.clone();
    m.phi(q, t, &mut phi);
    let scale = m.length_scale().abs().max(f64::MIN_POSITIVE);
    (0..phi.len()).fold(0.0, |worst: f64, i| {
        let power = match m.equation_unit(i) {
            Unit::Angle => 0,
            Unit::Length => 1,
            Unit::Area => 2,
        };
        let value = (phi[i] / scale.powi(power)).abs();
        if value.is_nan() {
            f64::INFINITY
        } else {
            worst.max(value)
        }
    })
}

/// The evaluation budget the solver's caps allow for a run of `solves` solves: per block and
/// solve, the iteration cap times (one Newton evaluation + the damping trials of a
/// Levenberg–Marquardt step + the diagnosis), times the sub-steps a step may take, plus a
/// crossing's bisections.
fn budget(m: &Interpreted, solves: usize) -> u64 {
    let blocks = (0..m.stage_count())
        .filter(|&s| matches!(m.stage(s), Some(Stage::Block(_))))
        .count() as u64;
    let options = SolverOptions::default();
    let per_solve = blocks * (options.max_iterations as u64 + 1) * (64 + 2) + 16;
    let substeps = 2 << DEFAULT_MAX_HALVINGS;
    per_solve * (substeps + 130) * solves as u64
}

fn run(source: &str, tally: &mut Tally) {
    let scene = match mechgen::compile_str(source) {
        Ok(scene) => scene,
        Err(_) => {
            tally.compile_errors += 1;
            return;
        }
    };
    let mechanism = Interpreted::new(&scene);
    let names = mechanism.clone();
    let mut simulation = match Simulation::new(Solver::new(mechanism), 0.0) {
        Ok(simulation) => simulation,
        Err(_) => {
            tally.assembly_errors += 1;
            return;
        }
    };
    let tolerance = SolverOptions::default().acceptance_tolerance;
    let mut failed = false;
    for k in 0..=STEPS {
        let t = DURATION * k as f64 / STEPS as f64;
        let stepped = if k == 0 {
            Ok(())
        } else {
            simulation.step_to(t).map(|_| ())
        };
        match stepped {
            Ok(()) => {
                let state = simulation.state();
                let residual = scaled_residual(&names, &state.q, state.t);
                assert!(
                    residual <= 100.0 * tolerance,
                    "Ok at t = {t} with scaled residual {residual:e}:\n{source}"
                );
            }
            Err(error) => {
                let text = error.describe(&names).to_string();
                assert!(!text.is_empty());
                failed = true;
                break;
            }
        }
    }
    let evaluations = simulation.solver().mechanism().evaluations();
    assert!(
        evaluations <= budget(&names, STEPS + 1),
        "{evaluations} evaluations:\n{source}"
    );
    tally.most_evaluations = tally.most_evaluations.max(evaluations);
    if failed {
        tally.step_errors += 1;
    } else {
        tally.solved += 1;
    }
}

#[test]
fn mutated_example_scenes_end_in_an_answer_or_a_typed_error() {
    let setting = |name: &str, default: u64| {
        std::env::var(name)
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(default)
    };
    let mutants = setting("MECHGEN_FUZZ_MUTANTS", MUTANTS as u64);
    let seed = setting("MECHGEN_FUZZ_SEED", 0x5EED);
    let mut tally = Tally::default();
    for (k, scene) in SCENES.iter().enumerate() {
        let mut rng = Rng(seed + k as u64);
        for _ in 0..mutants {
            let mutant = mutate(scene, &mut rng);
            let outcome = std::panic::catch_unwind(|| {
                let mut local = Tally::default();
                run(&mutant, &mut local);
                local
            });
            match outcome {
                Ok(local) => {
                    tally.compile_errors += local.compile_errors;
                    tally.assembly_errors += local.assembly_errors;
                    tally.step_errors += local.step_errors;
                    tally.solved += local.solved;
                    tally.most_evaluations = tally.most_evaluations.max(local.most_evaluations);
                }
                Err(_) => panic!("mutant panicked or broke an invariant:\n{mutant}"),
            }
        }
    }
    eprintln!("fuzz corpus: {tally:?}");
    // The corpus exercises every outcome.
    assert!(tally.compile_errors > 0 && tally.assembly_errors > 0 && tally.solved > 0);
}
