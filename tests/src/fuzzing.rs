//! Deterministic mutation fuzzing of the example scenes, shared by the CI test
//! (`tests/tests/fuzz.rs`) and the `cargo fuzz` targets (`fuzz/`): mutants of the example scenes
//! (extreme and degenerate numbers, deleted, duplicated and rewired statements, stray
//! characters), each run in-process through parse → check → the interpreter → assembly → a few
//! steps. Every mutant must end in a compile error, a typed solve error, or states whose
//! constraints hold (and whose reactions are finite, for a scene with forces): no panic, no
//! `Ok` whose scaled residual, re-evaluated with the scene's unstructured Φ (not the plan's
//! kernels the solver used), exceeds the acceptance tolerance, and a bounded number of
//! evaluations (counted, not timed). [`run`] panics when a mutant breaks one of these, which is
//! what both harnesses detect.
//!
//! The seeds include a scene solved entirely in closed form (a weld, a gear and a rack with
//! phases) and a planetary gear train, so that mutants drive closed-form stages to huge angles
//! (the numbers below include 1e12 to 1e20), where rounding alone breaks their constraints.

use mechgen_interp::Interpreted;
use mechgen_runtime::codegen::Stage;
use mechgen_runtime::{
    DEFAULT_MAX_HALVINGS, Mechanism, Outputs, Simulation, Solver, SolverOptions, Structured, Unit,
    Vector, nalgebra::Dyn,
};

/// The scenes mutants are made from: the examples, and a slider-crank with every load kind
/// (so that the force solve meets degenerate masses, springs and loads too).
pub const SCENES: [&str; 7] = [
    include_str!("../../examples/scenes/piston_crank.mech"),
    include_str!("../../examples/scenes/four_bar.mech"),
    include_str!("../../examples/scenes/offset_slider.mech"),
    include_str!("../../examples/scenes/piston_crank_dynamics.mech"),
    LOADED,
    include_str!("../../examples/scenes/planetary.mech"),
    CLOSED_FORM,
];

/// Every coordinate assigned in closed form: a bracket welded at an angle to a driven arm, a
/// gear with a phase and a rack and pinion with a phase, all driven by one angle. A mutant that
/// turns `20` into `1e12` drives them to angles whose rounding breaks the weld's angle, the
/// gear's phase and the rack's offset.
const CLOSED_FORM: &str = "mechanism ClosedForm {
    param w = 20;
    ground frame at (0, 0, 0);
    body arm near (0, 0, 0);
    body bracket near (10, 0, 0.5);
    body wheel near (50, 0, 0);
    body bar near (0, -10, 0);
    joint pivot: revolute(frame, arm);
    joint fix: weld(arm @ (10, 0), bracket, angle 30deg);
    joint axle: revolute(frame @ (50, 0), wheel);
    joint mesh: gear(arm, wheel, ratio -2, phase 0.1);
    joint slide: prismatic(frame @ (0, -10), bar, along (1, 0));
    joint teeth: rack(slide, arm, ratio 3.3, phase 0.7);
    driver spin: angle(arm) = 0.3 + w * t;
}";

/// A slider-crank whose rod is a distance link, with offset centres of mass, gravity, a force
/// in world and in body axes, a torque and a spring-damper.
const LOADED: &str = "mechanism Loaded {
    param omega = 20;
    ground frame at (0, 0, 0);
    body crank near (0, 0, 0.2) mass 2 inertia 0.01 centre (0.03, 0.01);
    body slider near (0.33, 0, 0) mass 0.7 inertia 0.001 centre (0.01, 0.02);
    joint pivot: revolute(frame, crank);
    joint guide: prismatic(frame, slider, along (1, 0));
    joint rod: distance(crank @ (0.1, 0), slider, 0.25);
    driver spin: angle(crank) = 0.2 + omega * t;
    branch ahead: dot(frame -> frame @ (1, 0), crank @ (0.1, 0) -> slider) > 0;
    gravity (0, -9.81);
    load gas: force(slider @ (0.01, 0)) = (-200 * (1 + sin(omega * t)), 0);
    load nudge: local_force(crank @ (0.1, 0)) = (0, 3);
    load brake: torque(crank) = -0.5 * t;
    load coil: spring(frame @ (0.6, 0.1), slider, stiffness 500, length 0.2, damping 4);
}";

/// Values a number literal is replaced with: degenerate, extreme, and just out of range.
const EXTREMES: [&str; 18] = [
    "1e17",
    "3e9",
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

/// Steps solved after assembly, over `DURATION` seconds.
const STEPS: usize = 6;
const DURATION: f64 = 0.02;

/// A small deterministic generator (SplitMix64): the corpus is the same on every run.
pub struct Rng(pub u64);

impl Rng {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A number in `0..n` (0 for `n = 0`).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
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

/// One mutation of `text`, chosen by `rng`.
pub fn mutate(text: &str, rng: &mut Rng) -> String {
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
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct Tally {
    /// Refused by parse or check.
    pub compile_errors: usize,
    /// Compiled, but assembly failed with a typed error.
    pub assembly_errors: usize,
    /// Assembled, then a step failed with a typed error.
    pub step_errors: usize,
    /// Every step solved.
    pub solved: usize,
    /// The most evaluations one mutant took.
    pub most_evaluations: u64,
}

impl Tally {
    /// Adds another tally's counts.
    pub fn add(&mut self, other: &Tally) {
        self.compile_errors += other.compile_errors;
        self.assembly_errors += other.assembly_errors;
        self.step_errors += other.step_errors;
        self.solved += other.solved;
        self.most_evaluations = self.most_evaluations.max(other.most_evaluations);
    }
}

/// The largest scaled residual of Φ at `q`: lengths over L, areas over L², angles as they are.
/// The interpreter's Φ is the scene's unstructured one: independent of the stages, closed
/// forms and kernels the solver used. (The solver scales by the power of two below L, so its
/// own scaled residuals are at least these.)
pub fn scaled_residual(m: &Interpreted, q: &Vector<Dyn>, t: f64) -> f64 {
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

/// Runs one scene source through the whole pipeline and records how it ended in `tally`.
///
/// # Panics
/// When the scene breaks an invariant (module docs): an `Ok` state whose constraints do not
/// hold, or more evaluations than the solver's caps allow.
pub fn run(source: &str, tally: &mut Tally) {
    let scene = match mechgen::compile(mechgen::Input::Text(source), &mechgen::Options::default()) {
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
        Err(failure) => {
            let evaluations = failure.solver.mechanism().evaluations();
            assert!(
                evaluations <= budget(&names, 1),
                "{evaluations} evaluations to fail assembly:\n{source}"
            );
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
                    residual <= tolerance,
                    "Ok at t = {t} with scaled residual {residual:e} (acceptance \
                     {tolerance:e}):\n{source}"
                );
                if names.outputs() == Outputs::Forces {
                    let forces = state.constraint_forces();
                    assert!(
                        forces.iter().all(|f| f.is_finite()),
                        "Ok at t = {t} with non-finite reactions:\n{source}"
                    );
                }
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
