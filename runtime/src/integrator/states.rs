//! The integrator's two kinematic states, the current one and the step's iterate: accepting a
//! step flips which is which instead of swapping them (a state holds four n-vectors, 190 kB at
//! the 1000-stage scissor lift's 6,012 coordinates, and a swap moved twice that every step).

use nalgebra::DefaultAllocator;

use crate::mechanism::Storage;
use crate::state::State;
use crate::structure::Structured;

/// The current state and the iterate, in one array.
pub(crate) struct States<M: Structured>
where
    DefaultAllocator: Storage<M::Dim>,
{
    both: [State<M>; 2],
    /// Which of `both` is the current state.
    current: usize,
}

impl<M: Structured> Clone for States<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    fn clone(&self) -> Self {
        Self {
            both: self.both.clone(),
            current: self.current,
        }
    }
}

impl<M: Structured> States<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// `state` as the current state, and a copy of it as the iterate.
    pub fn new(state: State<M>) -> Self {
        Self {
            both: [state.clone(), state],
            current: 0,
        }
    }

    /// The state at the current time.
    pub fn current(&self) -> &State<M> {
        &self.both[self.current]
    }

    /// The iterate of the step being solved.
    pub fn trial(&self) -> &State<M> {
        &self.both[1 - self.current]
    }

    /// The iterate, to solve into.
    pub fn trial_mut(&mut self) -> &mut State<M> {
        &mut self.both[1 - self.current]
    }

    /// The current state and the iterate, the iterate to write.
    pub fn split(&mut self) -> (&State<M>, &mut State<M>) {
        let [first, second] = &mut self.both;
        if self.current == 0 {
            (first, second)
        } else {
            (second, first)
        }
    }

    /// Makes the iterate the current state (the old current state is the next iterate).
    pub fn accept(&mut self) {
        self.current = 1 - self.current;
    }
}
