//! Where an error's message finds its names: the tables the error carries, or the accessors
//! of the mechanism it is described with.

use core::fmt;

use nalgebra::DefaultAllocator;

use crate::mechanism::{Mechanism, Storage};
use crate::names::Names;

/// Where an error's indices find their names: its own [`Names`], or a mechanism.
pub(super) trait Lookup {
    fn equation(&self, index: usize) -> Option<&str>;
    fn coordinate(&self, index: usize) -> Option<&str>;
    fn parameter(&self, index: usize) -> Option<&str>;
    fn branch(&self, index: usize) -> Option<&str>;
    fn marker(&self, index: usize) -> Option<&str>;
    fn load(&self, index: usize) -> Option<&str>;
}

impl Lookup for Names {
    fn equation(&self, index: usize) -> Option<&str> {
        Names::equation(self, index)
    }
    fn coordinate(&self, index: usize) -> Option<&str> {
        Names::coordinate(self, index)
    }
    fn parameter(&self, index: usize) -> Option<&str> {
        Names::parameter(self, index)
    }
    fn branch(&self, index: usize) -> Option<&str> {
        Names::branch(self, index)
    }
    fn marker(&self, index: usize) -> Option<&str> {
        Names::marker(self, index)
    }
    fn load(&self, index: usize) -> Option<&str> {
        Names::load(self, index)
    }
}

/// A mechanism's own names first, then those the error carries.
pub(super) struct FromMechanism<'a, M>(pub(super) &'a M, pub(super) &'static Names);

impl<M: Mechanism> Lookup for FromMechanism<'_, M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    fn equation(&self, index: usize) -> Option<&str> {
        self.0.equation_name(index).or(self.1.equation(index))
    }
    fn coordinate(&self, index: usize) -> Option<&str> {
        self.0.coordinate_name(index).or(self.1.coordinate(index))
    }
    fn parameter(&self, index: usize) -> Option<&str> {
        self.0.parameter_name(index).or(self.1.parameter(index))
    }
    fn branch(&self, index: usize) -> Option<&str> {
        self.0.branch_name(index).or(self.1.branch(index))
    }
    fn marker(&self, index: usize) -> Option<&str> {
        self.0.marker_name(index).or(self.1.marker(index))
    }
    fn load(&self, index: usize) -> Option<&str> {
        self.0.names().load(index).or(self.1.load(index))
    }
}

/// Writes `` `name` `` when known, `#index` otherwise.
pub(super) fn write_name(
    f: &mut fmt::Formatter<'_>,
    name: Option<&str>,
    index: usize,
) -> fmt::Result {
    match name {
        Some(name) => write!(f, "`{name}`"),
        None => write!(f, "#{index}"),
    }
}
