//! The free degrees of freedom of an interpreted scene: their state, which every tape reads
//! (`Inputs::free`), and `Dynamic` (names, equations, declared initial state by tape at the
//! current parameters).

use mechgen::Scene;
use mechgen::expr::tape::{Env, Tape};
use mechgen_runtime::Dynamic;
use mechgen_runtime::nalgebra::Dyn;

use super::Interpreted;

/// A scene's free degrees of freedom, in declaration order.
#[derive(Debug, Clone)]
pub(super) struct FreeDofs {
    names: Vec<String>,
    equations: Vec<usize>,
    /// Each one's `[value, rate, acceleration]`: what the kinematic tapes read.
    pub(super) state: Vec<[f64; 3]>,
    /// Whether each declares `from`.
    declared: Vec<bool>,
    /// Each one's `from` (0 where not declared), then each one's `speed`, in parameters.
    initial: Tape,
}

impl FreeDofs {
    /// The free degrees of freedom of `scene`, at the declared state for the parameters'
    /// defaults (value 0 where no `from` is declared), at rest.
    pub(super) fn new(scene: &Scene) -> Self {
        let model = &scene.model;
        let zero = model.arena.zero();
        let roots: Vec<_> = (model.frees.iter().map(|f| f.from.unwrap_or(zero)))
            .chain(model.frees.iter().map(|f| f.speed))
            .collect();
        let mut frees = FreeDofs {
            names: model.frees.iter().map(|f| f.name.to_string()).collect(),
            equations: (0..model.frees.len())
                .map(|k| model.free_equation(k).unwrap_or(usize::MAX))
                .collect(),
            state: Vec::new(),
            declared: model.frees.iter().map(|f| f.from.is_some()).collect(),
            initial: Tape::new(&model.arena, &roots),
        };
        let env = Env {
            params: model.params.iter().map(|p| p.default).collect(),
            ..Env::default()
        };
        let mut values = vec![0.0; roots.len()];
        (frees.initial).eval(env.inputs(), &mut frees.initial.scratch(), &mut values);
        frees.state = (0..frees.names.len())
            .map(|k| {
                let (from, speed) = frees.declared(&values, k);
                [from.unwrap_or(0.0), speed, 0.0]
            })
            .collect();
        frees
    }

    /// The tape of the declared initial states (for the shared scratch's size).
    pub(super) fn tape(&self) -> &Tape {
        &self.initial
    }

    /// Free degree of freedom `k`'s declared `(from, speed)`, read from the initial tape's
    /// outputs.
    fn declared(&self, values: &[f64], k: usize) -> (Option<f64>, f64) {
        let count = self.names.len();
        match (self.declared.get(k), values.get(k), values.get(count + k)) {
            (Some(&declared), Some(&from), Some(&speed)) => (declared.then_some(from), speed),
            _ => (None, 0.0),
        }
    }
}

impl Interpreted {
    /// Number of free degrees of freedom (0 for a scene without: it is not `Dynamic` then,
    /// though the trait's methods answer as for an empty list).
    pub fn free_count(&self) -> usize {
        self.free.names.len()
    }
}

impl Dynamic for Interpreted {
    type Free = Dyn;

    fn free(&self) -> Dyn {
        Dyn(self.free.names.len())
    }

    fn free_name(&self, k: usize) -> Option<&str> {
        self.free.names.get(k).map(String::as_str)
    }

    fn free_equation(&self, k: usize) -> usize {
        self.free.equations.get(k).copied().unwrap_or(usize::MAX)
    }

    fn free_initial(&self, k: usize) -> (Option<f64>, f64) {
        let mut initial = (None, 0.0);
        let inputs = self.inputs(&[], &[], 0.0);
        self.run(&self.free.initial, inputs, |values| {
            initial = self.free.declared(values, k);
        });
        initial
    }

    fn free_state(&self, k: usize) -> [f64; 3] {
        self.free.state.get(k).copied().unwrap_or([f64::NAN; 3])
    }

    fn set_free(&mut self, k: usize, state: [f64; 3]) {
        if let Some(slot) = self.free.state.get_mut(k) {
            *slot = state;
        }
    }
}
