//! Closed-form inverse dynamics of the seed piston-crank with mass properties (the
//! `PistonCrankDynamics` scene): Newton–Euler body by body along the closed-form motion, the
//! reference the force solve is measured against.
//!
//! Each body's reference point is its centre of mass. With the motion known exactly
//! ([`crate::closed_form::PistonCrank`]), the unknown forces follow by elimination, no linear
//! system solver involved: the piston's x balance gives the piston pin's x force, the rod's
//! three balances its y force and the crank pin force, the piston's y and moment balances the
//! liner's normal force and torque, the crank's balances the main bearing force and the
//! driving torque. Signs follow the reported reactions (`mechgen_runtime::Mechanism::reactions`):
//! a revolute joint's force is what its second body exerts on its first.

use crate::closed_form::{Kinematics, PistonCrank};

/// Masses (kg) and moments of inertia about the centres of mass (kg·mm²) of the moving bodies,
/// and gravity (mm/s²): the `PistonCrankDynamics` scene's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProperties {
    /// Piston mass and inertia.
    pub piston: (f64, f64),
    /// Connecting rod mass and inertia.
    pub rod: (f64, f64),
    /// Crank mass and inertia.
    pub crank: (f64, f64),
    /// Gravity in world axes.
    pub gravity: [f64; 2],
}

impl Default for MassProperties {
    /// Piston 0.5 kg, 300 kg·mm²; rod 0.4 kg, 1500 kg·mm²; crank 1.2 kg, 2000 kg·mm²;
    /// gravity (0, −9810) mm/s².
    fn default() -> Self {
        Self {
            piston: (0.5, 300.0),
            rod: (0.4, 1500.0),
            crank: (1.2, 2000.0),
            gravity: [0.0, -9810.0],
        }
    }
}

/// The seed's reactions at one instant, named as the scene reports them (forces in kg·mm/s²,
/// torques in kg·mm²/s²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reactions {
    /// Force on the rod from the crank at the crank pin.
    pub crank_pin: [f64; 2],
    /// Force on the piston from the rod at the piston pin.
    pub piston_pin: [f64; 2],
    /// Force on the crank from the bearing.
    pub main_bearing: [f64; 2],
    /// Normal force (along world y) and torque on the liner from the piston.
    pub slide: [f64; 2],
    /// Driving torque on the crank.
    pub crank_angle: f64,
    /// Force and torque (about its reference point) the mechanism puts on the liner.
    pub liner: [f64; 3],
    /// Force and torque the mechanism puts on the bearing.
    pub bearing: [f64; 3],
}

impl Reactions {
    /// The reactions in the scene's equation order (`REACTIONS`): liner, piston… (ground rows
    /// first: liner; then the joints, the driver), matching `state.constraint_forces()`.
    pub fn in_equation_order(&self) -> [f64; 15] {
        let [lx, ly, lt] = self.liner;
        let [bx, by, bt] = self.bearing;
        [
            lx,
            ly,
            lt,
            bx,
            by,
            bt,
            self.crank_pin[0],
            self.crank_pin[1],
            self.piston_pin[0],
            self.piston_pin[1],
            self.main_bearing[0],
            self.main_bearing[1],
            self.slide[0],
            self.slide[1],
            self.crank_angle,
        ]
    }
}

/// z component of the cross product `a × b`.
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// `A(θ) s`.
fn rotate(theta: f64, s: [f64; 2]) -> [f64; 2] {
    let (sin, cos) = theta.sin_cos();
    [cos * s[0] - sin * s[1], sin * s[0] + cos * s[1]]
}

/// The seed's reactions along its exact motion `k` (from [`PistonCrank::kinematics`]).
pub fn seed_reactions(seed: &PistonCrank, mass: &MassProperties, k: &Kinematics<15>) -> Reactions {
    let (q, qdd) = (&k.q, &k.qdd);
    let g = mass.gravity;
    let s = seed.scale;
    let ((mp, jp), (mr, jr), (mc, jc)) = (mass.piston, mass.rod, mass.crank);
    // Offsets of the joint points from the bodies' reference points (= centres of mass).
    let pin_on_piston = rotate(q[5], [-seed.piston_pin * s, 0.0]);
    let crank_pin_on_rod = rotate(q[8], [seed.rod_crank_pin * s, 0.0]);
    let piston_pin_on_rod = rotate(q[8], [0.0, seed.rod_piston_pin * s]);
    let crank_pin_on_crank = rotate(q[11], [0.0, seed.crank_radius * s]);

    // Piston, x: the slide's normal is along y, so only the pin pushes it along the liner.
    let pin_x = mp * (qdd[3] - g[0]);
    // Rod: m a = F_cp − F_pp + m g, J α = r1 × F_cp − r2 × F_pp, with F_cp.y = F_pp.y + k.
    let crank_pin_x = mr * (qdd[6] - g[0]) + pin_x;
    let lift = mr * (qdd[7] - g[1]);
    let (r1, r2) = (crank_pin_on_rod, piston_pin_on_rod);
    let pin_y =
        (jr * qdd[8] - r1[0] * lift + r1[1] * crank_pin_x - r2[1] * pin_x) / (r1[0] - r2[0]);
    let crank_pin = [crank_pin_x, pin_y + lift];
    let piston_pin = [pin_x, pin_y];
    // Piston, y and moment: the liner holds it on its axis and keeps it from turning.
    let normal = pin_y + mp * (g[1] - qdd[4]);
    let slide_torque = cross(pin_on_piston, piston_pin) - jp * qdd[5];
    // Crank: m a = −F_cp + F_mb + m g, J α = r × (−F_cp) + τ.
    let main_bearing = [
        mc * (qdd[9] - g[0]) + crank_pin[0],
        mc * (qdd[10] - g[1]) + crank_pin[1],
    ];
    let torque = jc * qdd[11] + cross(crank_pin_on_crank, crank_pin);
    // Loads on the frame: the normal force acts at the piston's point on the liner's axis.
    let at = [q[3] - q[0], q[4] - q[1]];
    let liner = [0.0, normal, cross(at, [0.0, normal]) + slide_torque];
    let bearing = [-main_bearing[0], -main_bearing[1], 0.0];
    Reactions {
        crank_pin,
        piston_pin,
        main_bearing,
        slide: [normal, slide_torque],
        crank_angle: torque,
        liner,
        bearing,
    }
}
