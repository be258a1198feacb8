//! A hand-written slider-crank (3 bodies, 9 coordinates) with its closed-form kinematics.
//!
//! The crank turns about the origin (`θ₁ = θ₀ + ω t`), the rod joins the crank pin at distance
//! `r` to the slider at distance `l`, and the slider runs along the x-axis. Every body's
//! reference point is at the joint it hangs from: crank at the pivot, rod at the crank pin.

use mechgen_runtime::codegen::math::{cos, sin};
use mechgen_runtime::nalgebra::Const;
use mechgen_runtime::{
    Accelerations, Dense, Matrix, Mechanism, Outputs, ParameterError, Unit, Vector, Velocities,
};

/// The slider-crank solved by the runtime: only textbook functions, so as one dense block.
pub type Reference = Dense<SliderCrank>;

/// The reference solve of a slider-crank.
pub fn reference(scene: SliderCrank) -> Reference {
    Dense::new(scene)
}

pub type Q = Vector<Const<9>>;

#[derive(Debug, Clone)]
pub struct SliderCrank {
    /// r, l, ω, θ₀
    pub parameters: [f64; 4],
}

impl Default for SliderCrank {
    fn default() -> Self {
        Self {
            parameters: [1.0, 3.0, 2.0, 0.3],
        }
    }
}

pub const COORDINATES: [&str; 9] = [
    "crank.x",
    "crank.y",
    "crank.theta",
    "rod.x",
    "rod.y",
    "rod.theta",
    "slider.x",
    "slider.y",
    "slider.theta",
];
pub const EQUATIONS: [&str; 9] = [
    "crank_pivot.x",
    "crank_pivot.y",
    "crank_drive",
    "crank_pin.x",
    "crank_pin.y",
    "wrist_pin.x",
    "wrist_pin.y",
    "slider_guide.y",
    "slider_guide.theta",
];
const PARAMETERS: [&str; 4] = ["r", "l", "omega", "theta0"];

impl SliderCrank {
    /// Closed-form `(q, q̇, q̈)` at `t`, on the branch with the slider right of the crank.
    pub fn exact(&self, t: f64) -> [Q; 3] {
        let [r, l, w, theta0] = self.parameters;
        let th1 = theta0 + w * t;
        let (s1, c1) = (sin(th1), cos(th1));
        let th2 = -libm::asin(r * s1 / l);
        let (s2, c2) = (sin(th2), cos(th2));
        // From differentiating the wrist pin's y-equation r sin θ₁ + l sin θ₂ = 0 twice.
        let th2_d = -r * c1 * w / (l * c2);
        let th2_dd = (r * s1 * w * w + l * s2 * th2_d * th2_d) / (l * c2);
        let x3_d = -r * s1 * w - l * s2 * th2_d;
        let x3_dd = -r * c1 * w * w - l * c2 * th2_d * th2_d - l * s2 * th2_dd;
        [
            Q::from([
                0.0,
                0.0,
                th1,
                r * c1,
                r * s1,
                th2,
                r * c1 + l * c2,
                0.0,
                0.0,
            ]),
            Q::from([0.0, 0.0, w, -r * s1 * w, r * c1 * w, th2_d, x3_d, 0.0, 0.0]),
            Q::from([
                0.0,
                0.0,
                0.0,
                -r * c1 * w * w,
                -r * s1 * w * w,
                th2_dd,
                x3_dd,
                0.0,
                0.0,
            ]),
        ]
    }
}

impl Mechanism for SliderCrank {
    type Dim = Const<9>;
    type Markers = [f64; 0];

    fn marker_storage(&self) -> [f64; 0] {
        []
    }

    fn dim(&self) -> Const<9> {
        Const
    }

    fn coordinate_name(&self, index: usize) -> Option<&str> {
        COORDINATES.get(index).copied()
    }

    fn equation_name(&self, index: usize) -> Option<&str> {
        EQUATIONS.get(index).copied()
    }

    fn parameter_count(&self) -> usize {
        PARAMETERS.len()
    }

    fn parameter_name(&self, index: usize) -> Option<&str> {
        PARAMETERS.get(index).copied()
    }

    fn parameter(&self, index: usize) -> Option<f64> {
        self.parameters.get(index).copied()
    }

    fn set_parameter<'a>(
        &'a mut self,
        name: &'a str,
        value: f64,
    ) -> Result<(), ParameterError<'a>> {
        let index = PARAMETERS
            .iter()
            .position(|&p| p == name)
            .ok_or(ParameterError::Unknown {
                name,
                declared: &PARAMETERS,
            })?;
        if !value.is_finite() {
            return Err(ParameterError::NonFinite { name, value });
        }
        self.parameters[index] = value;
        Ok(())
    }

    fn coordinate_unit(&self, index: usize) -> Unit {
        if index % 3 == 2 {
            Unit::Angle
        } else {
            Unit::Length
        }
    }

    fn equation_unit(&self, index: usize) -> Unit {
        if index == 2 || index == 8 {
            Unit::Angle
        } else {
            Unit::Length
        }
    }

    fn length_scale(&self) -> f64 {
        self.parameters[0].abs().max(self.parameters[1].abs())
    }

    fn initial_guess(&self, q: &mut Q) {
        let [r, l, _, theta0] = self.parameters;
        *q = Q::from([0.0, 0.0, theta0, r, 0.0, 0.0, r + l, 0.0, 0.0]);
    }

    fn phi(&self, q: &Q, t: f64, out: &mut Q) {
        let [r, l, w, theta0] = self.parameters;
        let (th1, th2) = (q[2], q[5]);
        *out = Q::from([
            q[0],
            q[1],
            th1 - theta0 - w * t,
            q[0] + r * cos(th1) - q[3],
            q[1] + r * sin(th1) - q[4],
            q[3] + l * cos(th2) - q[6],
            q[4] + l * sin(th2) - q[7],
            q[7],
            q[8],
        ]);
    }

    fn jacobian(&self, q: &Q, _: f64, out: &mut Matrix<Const<9>>) {
        let [r, l, ..] = self.parameters;
        let (th1, th2) = (q[2], q[5]);
        out.fill(0.0);
        for (row, column, value) in [
            (0, 0, 1.0),
            (1, 1, 1.0),
            (2, 2, 1.0),
            (3, 0, 1.0),
            (3, 2, -r * sin(th1)),
            (3, 3, -1.0),
            (4, 1, 1.0),
            (4, 2, r * cos(th1)),
            (4, 4, -1.0),
            (5, 3, 1.0),
            (5, 5, -l * sin(th2)),
            (5, 6, -1.0),
            (6, 4, 1.0),
            (6, 5, l * cos(th2)),
            (6, 7, -1.0),
            (7, 7, 1.0),
            (8, 8, 1.0),
        ] {
            out[(row, column)] = value;
        }
    }

    fn outputs(&self) -> Outputs {
        Outputs::Accelerations
    }

    fn nu(&self, _: &Q, _: f64, out: &mut Q) {
        *out = Q::zeros();
        out[2] = self.parameters[2];
    }

    fn gamma(&self, q: &Q, qd: &Q, _: f64, out: &mut Q) {
        let [r, l, ..] = self.parameters;
        let (th1, th2, w1, w2) = (q[2], q[5], qd[2], qd[5]);
        *out = Q::zeros();
        out[3] = r * cos(th1) * w1 * w1;
        out[4] = r * sin(th1) * w1 * w1;
        out[5] = l * cos(th2) * w2 * w2;
        out[6] = l * sin(th2) * w2 * w2;
    }
}

impl Velocities for SliderCrank {}
impl Accelerations for SliderCrank {}
