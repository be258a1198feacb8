//! The example scenes, declared with `mechanism!`. Each has a `.mech` twin in `scenes/` for the
//! CLI; a test holds the two to the same tokens. `PistonCrankDynamics` is the seed with mass
//! properties and gravity: the force solve's example; `PistonCrankFree` the same with its crank
//! free, moving under gravity (forward dynamics); `Hoeken` and `Planetary` show markers
//! and gears.

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
    /// Piston-crank of a boxer engine, free: the seed with the mass properties of
    /// `piston_crank_dynamics.mech` (mm, kg, rad, s), each body's reference point at its centre of
    /// mass, its crank not driven but released from rest at 0.3 rad and moving under gravity alone
    /// (forward dynamics: the integrator sets the crank angle, rate and acceleration).
    pub mechanism PistonCrankFree {
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

        /// The crank's degree of freedom, left to the equations of motion: at 0.3 rad and at rest
        /// when released (its effort `crank_angle.effort` vanishes along the motion).
        free crank_angle: angle(crank) from 0.3;

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

mechanism! {
    /// Hoeken's straight-line linkage: a crank-rocker four-bar (crank 1, frame 2, rocker 2.5,
    /// coupler 2.5) whose coupler, extended to 5, carries a tracer (lengths in crank lengths, s).
    ///
    /// Over the half turn of the crank from 90° to 270° the tracer runs nearly straight along
    /// y = 4, from x = 4 back to x = 0, at nearly constant speed.
    pub mechanism Hoeken {
        /// Crank speed (rad/s).
        param omega = 1.0;

        /// Frame, with the crank pivot at its origin and the rocker pivot at (2, 0).
        ground frame at (0, 0, 0);
        /// Crank, pivoting at its reference point.
        body crank near (0, 0, 0);
        /// Coupler, with its reference point at the crank pin.
        body coupler near (1, 0, 1.4);
        /// Rocker, pivoting at its reference point.
        body rocker near (2, 0, 1.8);

        joint crank_pivot: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (1, 0), coupler);
        joint rocker_pin: revolute(coupler @ (2.5, 0), rocker @ (2.5, 0));
        joint rocker_pivot: revolute(rocker, frame @ (2, 0));

        driver crank_angle: angle(crank) = omega * t;

        /// The tracer at the end of the coupler's extension.
        marker tracer: coupler @ (5, 0);
        /// The transmission angle at the rocker pin: the rocker's angle less the coupler's.
        marker transmission: angle(coupler, rocker);

        /// Open, not crossed: at the rocker pin, the rocker (towards its pivot) lies anticlockwise of
        /// the coupler (towards the crank pin).
        branch open_assembly: cross(coupler @ (2.5, 0) -> coupler, rocker @ (2.5, 0) -> rocker) > 0;
    }
}

mechanism! {
    /// A planetary gear set with its ring fixed in the frame: the sun (24 teeth) drives, one planet
    /// (24) rolls inside the ring (72) on the carrier, which is the output (module 2: pitch radii
    /// 24, 24 and 72 mm; mm, rad, s). More planets would add only redundant constraints.
    ///
    /// Willis: (ω_sun − ω_carrier) / (ω_ring − ω_carrier) = −72 / 24, so with the ring fixed the
    /// carrier turns at a quarter of the sun's speed.
    pub mechanism Planetary {
        /// Sun speed (rad/s).
        param omega = 10.0;

        /// Frame, carrying the ring gear; every axle is at its origin.
        ground frame at (0, 0, 0);
        /// Sun gear, on the frame's axis.
        body sun near (0, 0, 0);
        /// Carrier, on the frame's axis, with the planet's axle at (48, 0).
        body carrier near (0, 0, 0);
        /// Planet gear, centred on its reference point.
        body planet near (48, 0, 0);

        joint sun_axle: revolute(frame, sun);
        joint carrier_axle: revolute(frame, carrier);
        joint planet_axle: revolute(carrier @ (48, 0), planet);
        /// External mesh: relative to the carrier the planet turns against the sun, 24 : 24.
        joint sun_mesh: gear(sun, planet, ratio -24 / 24, carrier carrier);
        /// Internal mesh with the ring (the frame): the same sense relative to the carrier, 24 : 72.
        joint ring_mesh: gear(planet, frame, ratio 24 / 72, carrier carrier);

        driver input: angle(sun) = omega * t;

        /// A point of the planet's pitch circle: it rolls along the ring, tracing a hypocycloid.
        marker tooth: planet @ (24, 0);
        /// The carrier's turn, the gear set's output.
        marker output: angle(frame, carrier);
    }
}

mechanism! {
    /// Crank and slotted lever quick-return (a shaper's drive), units mm, rad, s.
    ///
    /// The crank's pin slides in a slot along the lever, which pivots 100 below the crank; the
    /// lever's tip drives the ram along a horizontal guide through a link. The lever swings
    /// through 2 asin(0.4) while the crank turns: its return stroke is the quicker.
    pub mechanism QuickReturn {
        /// Crank speed (rad/s).
        param omega = 10.0;

        /// Frame (fixed), with the crank pivot at its origin.
        ground frame at (0, 0, 0);
        /// Crank, its pin 40 from the pivot.
        body crank near (0, 0, 0);
        /// Slotted lever, 220 long, pivoting at its reference point.
        body lever near (0, -100, 1.19);
        /// Link, 120 long, from the lever's tip to the ram.
        body link near (82, 104, 0.22);
        /// Ram, sliding 130 above the crank pivot.
        body ram near (199, 130, 0);

        joint crank_pivot: revolute(frame, crank);
        joint lever_pivot: revolute(frame @ (0, -100), lever);
        joint pin: slot(lever, crank @ (40, 0), along (1, 0));
        joint tip: revolute(lever @ (220, 0), link);
        joint ram_pin: revolute(link @ (120, 0), ram);
        joint guide: prismatic(frame @ (0, 130), ram, along (1, 0));

        driver crank_angle: angle(crank) = omega * t;
    }
}
