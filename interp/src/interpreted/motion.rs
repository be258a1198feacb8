//! The equations of motion of an interpreted scene (`M v`, `K v`, `C v`, the energies) as
//! tapes over the products `mechgen::plan::motion` planned, behind the runtime's
//! `EquationsOfMotion` trait; the vector `v` of a product is fed in q̈'s slot, as the
//! generated code reads it.

use mechgen::expr::tape::Tape;
use mechgen::plan::motion::EquationsOfMotion as Planned;
use mechgen_runtime::nalgebra::Dyn;
use mechgen_runtime::{EnergyTerms, EquationsOfMotion, Vector};

use super::Interpreted;
use super::textbook::copy_into;

/// One tape per function of the trait; `None` for a product whose matrix has no entries.
#[derive(Debug, Clone)]
pub(super) struct MotionTapes {
    mass: Tape,
    stiffness: Option<Tape>,
    damping: Option<Tape>,
    energy: Tape,
}

impl MotionTapes {
    pub(super) fn new(arena: &mechgen::expr::Arena, planned: &Planned) -> Self {
        MotionTapes {
            mass: Tape::new(arena, &planned.mass_times),
            stiffness: (planned.stiffness_times.as_deref()).map(|k| Tape::new(arena, k)),
            damping: (planned.damping_times.as_deref()).map(|c| Tape::new(arena, c)),
            energy: Tape::new(arena, &planned.energy.terms()),
        }
    }

    pub(super) fn tapes(&self) -> impl Iterator<Item = &Tape> {
        [&self.mass, &self.energy]
            .into_iter()
            .chain(&self.stiffness)
            .chain(&self.damping)
    }
}

impl Interpreted {
    /// `A v` by `tape` (a stiffness or damping product) at `(q, q̇, t)`; `false` without it.
    fn product(
        &self,
        tape: Option<&Tape>,
        (q, qd, t): (&Vector<Dyn>, &Vector<Dyn>, f64),
        v: &Vector<Dyn>,
        out: &mut Vector<Dyn>,
    ) -> bool {
        let Some(tape) = tape else {
            return false;
        };
        let inputs = self.inputs_with(q.as_slice(), qd.as_slice(), v.as_slice(), &[], t);
        self.run(tape, inputs, |values| copy_into(values, out));
        true
    }
}

/// A scene compiled without its equations of motion writes NaN for `M v` and the energies and
/// has no `K` or `C` (one interpreter type serves every scene, as for the force levels).
impl EquationsOfMotion for Interpreted {
    fn mass_times(&self, q: &Vector<Dyn>, v: &Vector<Dyn>, out: &mut Vector<Dyn>) {
        match &self.motion {
            Some(motion) => {
                let inputs = self.inputs_with(q.as_slice(), &[], v.as_slice(), &[], 0.0);
                self.run(&motion.mass, inputs, |values| copy_into(values, out));
            }
            None => out.as_mut_slice().fill(f64::NAN),
        }
    }

    fn stiffness_times(
        &self,
        q: &Vector<Dyn>,
        qd: &Vector<Dyn>,
        t: f64,
        v: &Vector<Dyn>,
        out: &mut Vector<Dyn>,
    ) -> bool {
        let tape = self.motion.as_ref().and_then(|m| m.stiffness.as_ref());
        self.product(tape, (q, qd, t), v, out)
    }

    fn damping_times(
        &self,
        q: &Vector<Dyn>,
        qd: &Vector<Dyn>,
        t: f64,
        v: &Vector<Dyn>,
        out: &mut Vector<Dyn>,
    ) -> bool {
        let tape = self.motion.as_ref().and_then(|m| m.damping.as_ref());
        self.product(tape, (q, qd, t), v, out)
    }

    fn energy_terms(&self, q: &Vector<Dyn>, qd: &Vector<Dyn>, t: f64) -> EnergyTerms {
        let Some(motion) = &self.motion else {
            return EnergyTerms {
                gravity: f64::NAN,
                springs: f64::NAN,
                loads: f64::NAN,
                dampers: f64::NAN,
            };
        };
        let mut terms = [f64::NAN; 4];
        let inputs = self.inputs(q.as_slice(), qd.as_slice(), t);
        self.run(&motion.energy, inputs, |values| {
            terms.iter_mut().zip(values).for_each(|(o, v)| *o = *v);
        });
        let [gravity, springs, loads, dampers] = terms;
        EnergyTerms {
            gravity,
            springs,
            loads,
            dampers,
        }
    }
}
