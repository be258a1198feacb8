//! The example scenes, declared with `mechanism!`. Each has a `.mech` twin in `scenes/` for the
//! CLI; a test holds the two to the same tokens. `PistonCrankDynamics` is the seed with mass
//! properties and gravity: the force solve's example.

use mechgen_runtime::mechanism;

mechanism! {
    /// Piston-crank of a boxer engine: the seed mechanism (5 bodies, 15 coordinates, mm, rad, s).
    ///
    /// The crank turns at `omega`; the connecting rod drives the piston along the liner's x axis.
    pub mechanism PistonCrank {
        /// Crank speed (rad/s).
        param omega = 314.0;

        /// Cylinder liner (fixed).
        ground liner at (156.8, 0, 0);
        /// Piston, sliding in the liner.
        body piston near (130, 0, 0);
        /// Connecting rod.
        body rod near (29, 72, -2.35);
        /// Crank shaft.
        body crank near (0, 0, 0);
        /// Crank bearing (fixed).
        ground bearing at (0, 0, 0);

        joint crank_pin: revolute(rod @ (41.3, 0), crank @ (0, 43));
        joint piston_pin: revolute(piston @ (-28, 0), rod @ (0, 102.6));
        joint main_bearing: revolute(crank, bearing);
        joint slide: prismatic(liner, piston, along (1, 0));

        driver crank_angle: angle(crank) = omega * t;

        /// The piston stays on the liner's side of the crank pin: the rod, from crank pin to piston
        /// pin, points along the cylinder axis (bearing to liner).
        branch piston_outboard: dot(bearing -> liner, rod @ (41.3, 0) -> rod @ (0, 102.6)) > 0;
    }
}

mechanism! {
    /// Piston-crank of a boxer engine with its mass properties: the seed (mm, kg, rad, s), each
    /// body's reference point at its centre of mass, under gravity, for the driving torque and the
    /// loads on every pin and bearing (forces in kg·mm/s² = mN, torques in kg·mm²/s² = µN·m).
    pub mechanism PistonCrankDynamics {
        /// Crank speed (rad/s).
        param omega = 314.0;

        /// Cylinder liner (fixed).
        ground liner at (156.8, 0, 0);
        /// Piston, sliding in the liner.
        body piston near (130, 0, 0) mass 0.5 inertia 300;
        /// Connecting rod.
        body rod near (29, 72, -2.35) mass 0.4 inertia 1500;
        /// Crank shaft.
        body crank near (0, 0, 0) mass 1.2 inertia 2000;
        /// Crank bearing (fixed).
        ground bearing at (0, 0, 0);

        joint crank_pin: revolute(rod @ (41.3, 0), crank @ (0, 43));
        joint piston_pin: revolute(piston @ (-28, 0), rod @ (0, 102.6));
        joint main_bearing: revolute(crank, bearing);
        joint slide: prismatic(liner, piston, along (1, 0));

        driver crank_angle: angle(crank) = omega * t;

        /// The piston stays on the liner's side of the crank pin.
        branch piston_outboard: dot(bearing -> liner, rod @ (41.3, 0) -> rod @ (0, 102.6)) > 0;

        gravity (0, -9810);
    }
}

mechanism! {
    /// Crank-rocker four-bar (Grashof: 40 + 120 < 80 + 100), units mm, rad, s.
    ///
    /// The crank turns fully at `omega`; the rocker swings. Coupler and rocker start on the open
    /// branch (coupler pin above the line from crank pin to rocker pivot).
    pub mechanism FourBar {
        /// Crank speed (rad/s).
        param omega = 10.0;

        /// Frame (fixed), with the crank pivot at its origin and the rocker pivot at (100, 0).
        ground frame at (0, 0, 0);
        /// Crank, 40 long, pivoting at its reference point.
        body crank near (0, 0, 0);
        /// Coupler, 120 long, with its reference point at the crank pin.
        body coupler near (40, 0, 0.6);
        /// Rocker, 80 long, pivoting at its reference point.
        body rocker near (100, 0, 1.1);

        joint crank_pivot: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (40, 0), coupler);
        joint rocker_pin: revolute(coupler @ (120, 0), rocker @ (80, 0));
        joint rocker_pivot: revolute(rocker, frame @ (100, 0));

        driver crank_angle: angle(crank) = omega * t;

        /// Open, not crossed: at the rocker pin, the rocker (towards its pivot) lies anticlockwise of
        /// the coupler (towards the crank pin).
        branch open_assembly: cross(coupler @ (120, 0) -> coupler, rocker @ (80, 0) -> rocker) > 0;
    }
}

mechanism! {
    /// Offset slider-crank posed by a parameter: a positions-only, time-free scene (what an
    /// optimiser or a kinematic calibration calls millions of times). Units mm, rad.
    ///
    /// No velocities, accelerations or time derivatives are generated for it.
    pub mechanism OffsetSlider {
        /// Crank angle (rad), set before each solve.
        param crank_angle = 0.5;
        /// Offset of the slider's line above the crank pivot (mm).
        param offset = 12.0;

        ground frame at (0, 0, 0);
        body crank near (0, 0, 0.5);
        body rod near (26, 18, -0.2);
        body slider near (100, 12, 0);

        joint pivot: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (30, 0), rod);
        joint wrist_pin: revolute(rod @ (80, 0), slider);
        joint guide: prismatic(frame @ (0, offset), slider, along (1, 0));

        driver pose: angle(crank) = crank_angle;

        outputs positions;
    }
}
