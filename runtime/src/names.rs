//! A scene's name tables, `'static` so that a [`crate::SolveError`] can carry them (one pointer,
//! the error stays `Copy`) and name what failed in its `Display` and `Debug` wherever it ends
//! up: returned from `main`, boxed as `dyn Error`, or logged long after the solver is gone.

/// The names a scene gives its coordinates, equations, parameters, branch invariants, marker
/// values and loads, in index order: what a [`crate::SolveError`]'s indices refer to.
///
/// A generated scene has one as the constant `NAMES` (its `COORDINATES`, `EQUATIONS`, …
/// tables); an interpreted one builds its own (the `mechgen` CLI keeps one per distinct scene
/// for the life of the process). [`crate::Mechanism::names`] hands it to the solver, which
/// attaches it to every error it returns; a table shorter than an index leaves that index
/// unnamed (`#7`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Names {
    /// The mechanism's name (`PistonCrank`); empty when unknown.
    pub mechanism: &'static str,
    /// Coordinate names in q order (`piston.x`).
    pub coordinates: &'static [&'static str],
    /// Equation names in Φ order (`crank_pin.x`, `crank_angle`).
    pub equations: &'static [&'static str],
    /// Run-time parameter names, in declaration order.
    pub parameters: &'static [&'static str],
    /// Branch invariant names, in declaration order.
    pub branches: &'static [&'static str],
    /// Marker value names (`tip.x`, …, `swing.angle`), in the order of the marker values.
    pub markers: &'static [&'static str],
    /// Load names (`gas`, `valve`), in declaration order.
    pub loads: &'static [&'static str],
}

impl Names {
    /// No names: errors show indices (a mechanism that does not provide its names).
    pub const NONE: Names = Names {
        mechanism: "",
        coordinates: &[],
        equations: &[],
        parameters: &[],
        branches: &[],
        markers: &[],
        loads: &[],
    };

    /// Coordinate `index`'s name, if known.
    pub fn coordinate(&self, index: usize) -> Option<&'static str> {
        self.coordinates.get(index).copied()
    }

    /// Equation `index`'s name, if known.
    pub fn equation(&self, index: usize) -> Option<&'static str> {
        self.equations.get(index).copied()
    }

    /// Parameter `index`'s name, if known.
    pub fn parameter(&self, index: usize) -> Option<&'static str> {
        self.parameters.get(index).copied()
    }

    /// Branch invariant `index`'s name, if known.
    pub fn branch(&self, index: usize) -> Option<&'static str> {
        self.branches.get(index).copied()
    }

    /// Marker value `index`'s name, if known.
    pub fn marker(&self, index: usize) -> Option<&'static str> {
        self.markers.get(index).copied()
    }

    /// Load `index`'s name, if known.
    pub fn load(&self, index: usize) -> Option<&'static str> {
        self.loads.get(index).copied()
    }
}

impl Default for &'static Names {
    fn default() -> Self {
        &Names::NONE
    }
}
