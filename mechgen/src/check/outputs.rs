//! The `outputs` statement: how far the scene computes (positions, velocities, accelerations,
//! forces).

use super::{Checker, dynamics};
use crate::model::Outputs;
use crate::syntax::spec::Spec;

impl Checker {
    /// `outputs positions[, velocities[, accelerations[, forces]]];`: a prefix of the four
    /// levels, in order, since each needs the one before (velocities solve at the positions,
    /// …). Without the statement: everything the scene can compute (forces when it declares
    /// masses or loads).
    pub(super) fn outputs(&mut self, spec: &Spec) -> Outputs {
        let Some(names) = &spec.outputs else {
            return if dynamics::declared(spec) {
                Outputs::Forces
            } else {
                Outputs::Accelerations
            };
        };
        for (k, name) in names.iter().enumerate() {
            let expected = Outputs::NAMES.get(k);
            if expected.is_some_and(|e| name == e) {
                continue;
            }
            let message = if !Outputs::NAMES.contains(&name.to_string().as_str()) {
                format!(
                    "unknown output `{name}`; the outputs are `positions`, `velocities`, \
                     `accelerations` and `forces`"
                )
            } else {
                "list outputs in order, each with the ones it needs: `outputs positions;`, \
                 `outputs positions, velocities;`, `outputs positions, velocities, \
                 accelerations;` or `outputs positions, velocities, accelerations, forces;`"
                    .to_owned()
            };
            self.errors.push(name.span(), message);
            return Outputs::Accelerations;
        }
        Outputs::ALL[names.len().clamp(1, Outputs::ALL.len()) - 1]
    }
}
