//! Generated code and the interpreter run one kernel list (`mechgen::plan::kernels`): called
//! directly, every `Structured` method of every stage writes the same entries (the same values,
//! to the round-off that separates libm's elementary functions from std's), leaves the same
//! entries untouched, and answers a buffer too short for its kernel the same way (NaN, never
//! stale values). The solver only ever passes buffers of the right length; this holds the
//! contract itself, for any caller.

use mechgen_examples::scenes::{FourBar, PistonCrankDynamics};
use mechgen_runtime::nalgebra::Const;
use mechgen_runtime::{Storage, Structured, Vector};
use mechgen_tests::example_scene;

/// What an untouched entry holds.
const SENTINEL: f64 = 7.25e101;

/// Everything each method wrote, method by method and stage by stage, for one state.
fn transcript<M: Structured>(m: &M, q: &[f64], qd: &[f64], qdd: &[f64]) -> Vec<(String, Vec<f64>)>
where
    mechgen_runtime::nalgebra::DefaultAllocator: Storage<M::Dim>,
{
    let vector = |values: &[f64]| {
        Vector::<M::Dim>::from_iterator_generic(m.dim(), Const::<1>, values.iter().copied())
    };
    let (q, qd, qdd) = (vector(q), vector(qd), vector(qdd));
    let n = q.len();
    let stages = m.stage_count();
    let mut out = Vec::new();
    // The trig cache as the sweep fills it, then every kernel with the cache full (as the
    // rates and the force solve see it) and with one too short for any kernel that reads it.
    let mut trig = vec![SENTINEL; 64];
    for s in 0..stages {
        m.fill_trig(s, &q, &mut trig);
    }
    out.push(("fill_trig".to_owned(), trig.clone()));
    let t = 0.37;
    let lambda: Vec<f64> = (0..n).map(|i| 0.5 - 0.1 * i as f64).collect();
    for (label, trig) in [("", &trig[..]), (" short trig", &trig[..1])] {
        for s in 0..stages {
            let tag = |method: &str| format!("{method} stage {s}{label}");
            let mut w = vector(&vec![SENTINEL; n]);
            w.copy_from(&q);
            m.assign_positions(s, &mut w, trig, t);
            out.push((tag("positions"), w.as_slice().to_vec()));
            let mut w = qd.clone();
            m.assign_velocities(s, &q, trig, &mut w, t);
            out.push((tag("velocities"), w.as_slice().to_vec()));
            let mut w = qdd.clone();
            m.assign_accelerations(s, &q, trig, &qd, &mut w, t);
            out.push((tag("accelerations"), w.as_slice().to_vec()));
            for len in [8, 1] {
                let mut candidates = vec![SENTINEL; 4 * len];
                m.closed_form(s, &q, trig, t, &mut candidates);
                out.push((tag(&format!("closed form ({len})")), candidates));
                let (mut phi, mut values) = (vec![SENTINEL; len], vec![SENTINEL; 3 * len]);
                m.block_jacobian(s, &q, trig, t, &mut phi, &mut values);
                out.push((tag(&format!("jacobian ({len})")), [phi, values].concat()));
                let mut rhs = vec![SENTINEL; len];
                m.velocity_rhs(s, &q, trig, &qd, t, &mut rhs);
                out.push((tag(&format!("velocity rhs ({len})")), rhs.clone()));
                m.acceleration_rhs(s, &q, trig, &qd, &qdd, t, &mut rhs);
                out.push((tag(&format!("acceleration rhs ({len})")), rhs.clone()));
                m.force_rhs(s, &q, trig, &qd, &qdd, &lambda, t, &mut rhs);
                out.push((tag(&format!("force rhs ({len})")), rhs));
            }
            for len in [n, 1] {
                let mut l = lambda.clone();
                l.truncate(len);
                m.assign_multipliers(s, &q, trig, &qd, &qdd, &mut l, t);
                out.push((tag(&format!("multipliers ({len})")), l));
            }
        }
    }
    out
}

/// The two transcripts agree entry by entry: both NaN, both untouched, or equal to round-off.
fn agree(generated: &[(String, Vec<f64>)], interpreted: &[(String, Vec<f64>)]) {
    assert_eq!(generated.len(), interpreted.len());
    for ((label, a), (_, b)) in generated.iter().zip(interpreted) {
        assert_eq!(a.len(), b.len(), "{label}");
        for (i, (&x, &y)) in a.iter().zip(b).enumerate() {
            let same = (x.is_nan() && y.is_nan())
                || (x == SENTINEL && y == SENTINEL)
                || (x != SENTINEL && y != SENTINEL && (x - y).abs() <= 1e-13 * x.abs().max(1.0));
            assert!(
                same,
                "{label}, entry {i}: generated {x:e}, interpreted {y:e}"
            );
        }
    }
}

/// A state of no particular meaning: kernels are functions of it, consistent or not.
fn state(n: usize, phase: f64) -> [Vec<f64>; 3] {
    let wave = |k: f64| {
        (0..n)
            .map(|i| (phase + k * i as f64).sin() * 30.0)
            .collect()
    };
    [wave(0.7), wave(1.3), wave(2.9)]
}

#[test]
fn every_method_of_every_stage_writes_what_generated_code_writes() {
    // Closed-form candidates that exist (a loop that closes), compared as values, not NaN.
    let mut closing = 0;
    let mut count = |transcript: &[(String, Vec<f64>)]| {
        closing += transcript
            .iter()
            .filter(|(tag, values)| {
                tag.starts_with("closed form") && values.iter().any(|v| v.abs() < 10.0)
            })
            .count();
    };
    for phase in [0.1, 1.9, 4.0] {
        let [q, qd, qdd] = state(15, phase);
        let generated = transcript(&PistonCrankDynamics::default(), &q, &qd, &qdd);
        count(&generated);
        agree(
            &generated,
            &transcript(&example_scene("piston_crank_dynamics.mech"), &q, &qd, &qdd),
        );
        let [q, qd, qdd] = state(12, phase);
        let generated = transcript(&FourBar::default(), &q, &qd, &qdd);
        count(&generated);
        agree(
            &generated,
            &transcript(&example_scene("four_bar.mech"), &q, &qd, &qdd),
        );
    }
    assert!(closing > 0, "some state closes a loop");
}
