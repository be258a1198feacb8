//! Solving one instant, or a run, with closed forms on and off, and measuring the differences
//! between states (and against the exact motion) in scene lengths and radians.

use core::f64::consts::TAU;
use core::mem::discriminant;

use mechgen_runtime::nalgebra::{Const, DefaultAllocator};
use mechgen_runtime::{
    Accelerations, Mechanism, Simulation, SolveError, Solver, SolverOptions, State, Storage,
    Structured, Unit, Vector,
};

use super::exact::Exact;

/// The default options with closed forms on or off (the Newton path of before), on the stage
/// sweep.
pub fn options(closed_forms: bool) -> SolverOptions {
    SolverOptions {
        closed_forms,
        // The stage sweep's closed-form start, which these tests are about (the generated
        // straight step, which takes the same solutions without Newton's last round-off-sized
        // correction, has its own tests in `straight_step.rs`).
        straight_step: false,
        ..SolverOptions::default()
    }
}

/// q, q̇, q̈ of a solved instant.
#[derive(Debug, Clone)]
pub struct Solved<const N: usize> {
    pub q: [f64; N],
    pub qd: [f64; N],
    pub qdd: [f64; N],
    /// Blocks the position solve started from a closed-form candidate.
    pub closed_forms: usize,
    /// Block Jacobians the position solve evaluated.
    pub evaluations: usize,
}

/// Solves `scene` at `t` from `guess`: the state of [`Solver::solve`], and the closed-form count
/// of [`Solver::solve_position`] from the same guess (which must give the same positions).
pub fn solve<M, const N: usize>(
    scene: &M,
    closed_forms: bool,
    t: f64,
    guess: &[f64; N],
) -> Result<Solved<N>, SolveError>
where
    M: Structured<Dim = Const<N>> + Accelerations + Clone,
{
    let mut solver = Solver::with_options(scene.clone(), options(closed_forms));
    let start = Vector::<Const<N>>::from_column_slice(guess);
    let state = solver.solve(t, &start)?;
    let mut q = start;
    let convergence = solver.solve_position(&mut q, t)?;
    assert_eq!(
        q, state.q,
        "the position solve alone lands where the full solve did"
    );
    let solved = Solved {
        q: array(state.q.as_slice()),
        qd: array(state.qd().as_slice()),
        qdd: array(state.qdd().as_slice()),
        closed_forms: convergence.closed_forms,
        evaluations: convergence.evaluations,
    };
    assert!(
        [solved.q, solved.qd, solved.qdd]
            .iter()
            .flatten()
            .all(|x| x.is_finite()),
        "a success is finite: {solved:?}"
    );
    Ok(solved)
}

fn array<const N: usize>(values: &[f64]) -> [f64; N] {
    values.try_into().expect("the scene's dimension")
}

/// Both paths fail, and with the same kind of error.
pub fn assert_same_error<T: core::fmt::Debug>(
    what: &str,
    closed: &Result<T, SolveError>,
    newton: &Result<T, SolveError>,
) {
    match (closed, newton) {
        (Err(a), Err(b)) => assert_eq!(
            discriminant(a),
            discriminant(b),
            "{what}: closed forms fail with {a:?}, the Newton path with {b:?}"
        ),
        _ => panic!("{what}: expected both to fail; closed forms {closed:?}, Newton {newton:?}"),
    }
}

/// The largest differences of q (absolute), q̇ and q̈ (relative to the largest magnitude of
/// `want`'s), lengths divided by `length` and angles compared modulo whole turns.
fn differences<M: Mechanism<Dim = Const<N>>, const N: usize>(
    scene: &M,
    length: f64,
    got: [&[f64; N]; 3],
    want: [&[f64; N]; 3],
) -> [f64; 3] {
    let unit = |k: usize| match scene.coordinate_unit(k) {
        Unit::Angle => 1.0,
        _ => length,
    };
    let mut worst = [0.0f64; 3];
    for level in 0..3 {
        let scale = if level == 0 {
            1.0
        } else {
            (0..N)
                .map(|k| want[level][k].abs() / unit(k))
                .fold(f64::MIN_POSITIVE, f64::max)
        };
        for k in 0..N {
            let mut d = got[level][k] - want[level][k];
            if level == 0 && scene.coordinate_unit(k) == Unit::Angle {
                d -= TAU * (d / TAU).round();
            }
            worst[level] = worst[level].max(d.abs() / unit(k) / scale);
        }
    }
    worst
}

/// q, q̇ and q̈ of an instant, solved or exact.
pub trait Levels<const N: usize> {
    fn levels(&self) -> [&[f64; N]; 3];
}

impl<const N: usize> Levels<N> for Solved<N> {
    fn levels(&self) -> [&[f64; N]; 3] {
        [&self.q, &self.qd, &self.qdd]
    }
}

impl<const N: usize> Levels<N> for Exact<N> {
    fn levels(&self) -> [&[f64; N]; 3] {
        [&self.q, &self.qd, &self.qdd]
    }
}

/// [`differences`] between two instants (solved, or the exact motion).
pub fn apart<M: Mechanism<Dim = Const<N>>, const N: usize>(
    scene: &M,
    length: f64,
    got: &impl Levels<N>,
    want: &impl Levels<N>,
) -> [f64; 3] {
    differences(scene, length, got.levels(), want.levels())
}

/// Each difference within its tolerance.
pub fn assert_within(what: &str, worst: [f64; 3], tolerance: [f64; 3]) {
    assert!(
        worst.iter().zip(tolerance).all(|(w, t)| *w <= t),
        "{what}: q, q̇, q̈ differ by {worst:?} (tolerances {tolerance:?})"
    );
}

/// The exact motion's positions, every length moved by up to `spread` scene lengths and every
/// angle by up to `spread` radians (the fractions in `moves`, in [−1, 1], cycled) and by
/// `turns` whole turns: a guess near one branch. (The solve recomputes explicit coordinates.)
pub fn guess_near<M: Mechanism<Dim = Const<N>>, const N: usize>(
    scene: &M,
    length: f64,
    exact: &[f64; N],
    (moves, spread): (&[f64], f64),
    turns: i32,
) -> [f64; N] {
    let mut guess = *exact;
    for (k, (g, m)) in guess.iter_mut().zip(moves.iter().cycle()).enumerate() {
        *g += match scene.coordinate_unit(k) {
            Unit::Angle => m * spread + TAU * f64::from(turns),
            _ => m * spread * length,
        };
    }
    guess
}

/// Every angle of `got` in the same turn as `want`'s, to round-off.
pub fn assert_same_turns<M: Mechanism<Dim = Const<N>>, const N: usize>(
    what: &str,
    scene: &M,
    got: &[f64; N],
    want: &[f64; N],
) {
    for k in (0..N).filter(|&k| scene.coordinate_unit(k) == Unit::Angle) {
        assert!(
            (got[k] - want[k]).abs() <= 1e-12 * want[k].abs().max(1.0),
            "{what}: angle {k} is {}, not {}",
            got[k],
            want[k]
        );
    }
}

/// Every state of a run of `steps` equal steps over `[0, t_end]` from the assembly at t = 0.
pub fn run<M, const N: usize>(
    scene: &M,
    closed_forms: bool,
    t_end: f64,
    steps: usize,
) -> Vec<Solved<N>>
where
    M: Structured<Dim = Const<N>> + Accelerations + Clone,
{
    record(
        Solver::with_options(scene.clone(), options(closed_forms)),
        t_end,
        steps,
    )
}

/// [`run`] for the interpreter running a scene's `.mech` text (its default parameters).
pub fn run_interpreted<const N: usize>(
    text: &str,
    closed_forms: bool,
    t_end: f64,
    steps: usize,
) -> Vec<Solved<N>> {
    let scene = mechgen::compile(mechgen::Input::Text(text), &mechgen::Options::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let interpreted = mechgen_interp::Interpreted::new(&scene);
    record(
        Solver::with_options(interpreted, options(closed_forms)),
        t_end,
        steps,
    )
}

fn record<M, const N: usize>(solver: Solver<M>, t_end: f64, steps: usize) -> Vec<Solved<N>>
where
    M: Structured + Accelerations,
    DefaultAllocator: Storage<M::Dim>,
{
    let mut simulation = Simulation::new(solver, 0.0).expect("assembles at t = 0");
    let mut states = Vec::with_capacity(steps + 1);
    simulation
        .run(t_end, steps, |state: &State<M>| {
            states.push(Solved {
                q: array(state.q.as_slice()),
                qd: array(state.qd().as_slice()),
                qdd: array(state.qdd().as_slice()),
                closed_forms: state.closed_forms,
                evaluations: state.evaluations,
            });
        })
        .expect("solves every step");
    states
}
