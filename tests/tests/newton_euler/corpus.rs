//! Scenes for the force tests, each both generated (`mechanism!`) and as text for the
//! interpreter: together they use every joint kind (revolute, prismatic, distance, slot, weld,
//! gear with and without a carrier, rack), every driver kind (angle, relative_angle, x, y,
//! travel, distance, slide) and every load kind (force, local_force, torque, spring with and
//! without damping, gravity, offset centres of mass), with every joint carrying load. The
//! issue-20 scenes hold a prismatic joint, a weld and a driver in the fixed stage of the plan.

// Each test file uses some of the generated items (accessor structs, traits) and not others.
#![allow(dead_code)]

use mechgen_tests::twin;

/// A corpus scene's generated type, with its text and how long its motion runs.
pub trait Scene: Default + Clone {
    /// The `.mech` text of the same scene.
    const TEXT: &'static str;
    /// The motion is solved (and sampled) over `0..=T_END`.
    const T_END: f64;
}

macro_rules! scene {
    ($text:ident, $t_end:expr, mechanism $name:ident $body:tt) => {
        twin! { $text, pub mechanism $name $body }
        impl Scene for $name {
            const TEXT: &'static str = $text;
            const T_END: f64 = $t_end;
        }
    };
}

// Revolute, distance and prismatic joints, a rotated frame, offset centres of mass, world and
// body-axis forces, a torque, a spring-damper, drivers relative to the frame and between bodies.
scene! {
    SINK, 2.0,
    mechanism Sink {
        param omega = 3.0;
        ground frame at (0, 0, 0.1);
        body crank near (4.8, 2.5, 0) mass 1.5 inertia 40 centre (10, 3);
        body slider near (110, 5, 0.1) mass 0.8 inertia 5 centre (2, -1);
        body arm near (115, 5, 0.1) mass 0.6 inertia 30 centre (0, 10);
        joint pivot: revolute(frame @ (5, 2), crank);
        joint rod: distance(crank @ (30, 0), slider @ (0, 3), 80);
        joint guide: prismatic(frame @ (0, -10), slider, along (2, 0.3));
        joint hinge: revolute(slider @ (5, 0), arm);
        driver spin: relative_angle(frame, crank) = omega * t;
        driver wave: relative_angle(slider, arm) = 0.3 * sin(5 * t);
        gravity (0.5, -9.81);
        load push: force(slider @ (1, 1)) = (3 * sin(t), 2);
        load thrust: local_force(arm @ (0, 20)) = (0, 4);
        load brake: torque(crank) = -0.2 * t;
        load coil: spring(frame @ (50, 40), arm @ (0, 20), stiffness 2, length 30, damping 0.05);
    }
}

// A travel driver and an x driver, a damper alone, a frame turned the other way: two blocks.
scene! {
    CARRIAGE, 3.0,
    mechanism Carriage {
        ground frame at (3, -2, -0.2);
        body carriage near (3, -2, -0.2) mass 2 inertia 10 centre (1, 0.5);
        body pendulum near (3, -2, -0.2) mass 0.5 inertia 8 centre (0, -15);
        joint guide: prismatic(frame, carriage, along (1, 1));
        joint hinge: revolute(carriage, pendulum);
        driver stroke: travel(guide) = 20 * sin(2 * t);
        driver sway: x(pendulum @ (0, -30)) = 3 - 5 * sin(1.5 * t) + 12 * sin(2 * t);
        gravity (0, -9.81);
        load drag: spring(frame @ (0, 40), pendulum @ (0, -30), damping 0.3);
    }
}

// A scotch yoke: a slot, a weld off both reference points at an angle, a rack and pinion, the
// yoke's prismatic joint in the fixed stage (all explicit: no Newton block).
scene! {
    YOKE, 2.0,
    mechanism Yoke {
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0) mass 1 inertia 0.5 centre (0.5, 0.1);
        body yoke near (2, 0, 0) mass 2 inertia 1 centre (0.2, -0.3);
        body arm near (2.3, 0.6, 0.3) mass 0.5 inertia 0.2 centre (0.4, 0.1);
        body pinion near (0, 3, -3.8) mass 0.3 inertia 0.05 centre (0.05, 0);
        joint pivot: revolute(frame, crank);
        joint guide: prismatic(frame, yoke, along (1, 0));
        joint pin: slot(yoke, crank @ (2, 0), along (0, 1));
        joint fixed: weld(yoke @ (0.5, 0.5), arm @ (0.2, -0.1), angle 0.3);
        joint axle: revolute(frame @ (0, 3), pinion);
        joint teeth: rack(guide, pinion, ratio -0.5, phase 0.1);
        driver spin: angle(crank) = 0.4 * sin(3 * t) + 0.25 * t^2;
        gravity (0, -9.81);
        load brake: torque(pinion) = 2 + sin(t);
        load tip: local_force(arm @ (1, 0)) = (0, -3);
    }
}

// A planetary set (gears on a carrier) driving an idler (a gear pair on the frame); the ring
// held by a y driver, the carrier loaded.
scene! {
    GEARS, 2.0,
    mechanism GearTrain {
        ground frame at (0, 0, 0);
        body sun near (0, 0, 0) mass 1 inertia 2 centre (0.1, 0);
        body carrier near (0, 0, 0) mass 0.5 inertia 3 centre (20, 1);
        body planet near (60, 0, 0) mass 0.4 inertia 1 centre (0, 0.5);
        body ring near (0, 0, 0) mass 2 inertia 50;
        body idler near (200, 0, 0) mass 0.2 inertia 0.4;
        joint sun_axle: revolute(frame, sun);
        joint carrier_axle: revolute(frame, carrier);
        joint planet_axle: revolute(carrier @ (60, 0), planet);
        joint ring_axle: revolute(frame, ring);
        joint idler_axle: revolute(frame @ (200, 0), idler);
        joint sun_planet: gear(sun, planet, ratio -1, carrier carrier);
        joint planet_ring: gear(planet, ring, ratio 30 / 90, carrier carrier);
        joint ring_idler: gear(ring, idler, ratio -3, phase 0.2);
        driver input: angle(sun) = 0.4 * sin(3 * t) + 0.25 * t^2;
        driver brake: y(ring @ (90, 0)) = 90 * sin(0.2 * t);
        gravity (0, -9.81);
        load output: torque(carrier) = -5 - t;
        load drag: torque(idler) = 40 + 10 * sin(t);
    }
}

// A boom raised by a linear actuator (a distance driver) and a cart on an inclined rail
// positioned along another line (a slide driver), a spring-damper between them.
scene! {
    ACTUATORS, 2.0,
    mechanism Actuators {
        ground frame at (0, 0, 0.1);
        body boom near (0, 0, 0.5) mass 3 inertia 4 centre (1, 0.2);
        body cart near (0, 0, 0) mass 1.5 inertia 0.3 centre (0.1, 0.05);
        joint hinge: revolute(frame, boom);
        joint rail: prismatic(frame, cart, along (1, 0.5));
        driver ram: distance(frame @ (1, -1), boom @ (2, 0)) = 2 + 0.4 * sin(3 * t) + 0.25 * t^2;
        driver push: slide(frame @ (0, 1), cart @ (0.2, 0), along (1, 0))
            = 0.4 * sin(3 * t) + 0.25 * t^2;
        gravity (0.3, -9.81);
        load coil: spring(boom @ (3, 0), cart @ (0.5, 0.2), stiffness 40, length 2, damping 1.5);
        load wind: force(boom @ (2.5, 0.3)) = (1, -2 * t);
    }
}

// Issue 20: a prismatic joint's torque in the fixed stage (statics: normal 100 t, torque 600 t).
scene! {
    PRISMATIC_TORQUE, 3.0,
    mechanism PrismaticTorque {
        ground frame at (0, 0, 0);
        body slider near (6, 0, 0);
        joint slide: prismatic(frame, slider @ (-6, 0), along (1, 0));
        driver s: travel(slide) = t;
        load push: force(slider) = (0, 100 * t);
    }
}

// Issue 20: a weld off the body's reference point (statics: torque 250 t).
scene! {
    WELD_TORQUE, 3.0,
    mechanism WeldTorque {
        ground frame at (0, 0, 0);
        body bracket near (7, -4, 0);
        joint w: weld(frame @ (10, 0), bracket @ (3, 4));
        load push: force(bracket) = (100 * t, 50 * t);
    }
}

// Issue 20: a driver's effort on a pinned post (statics: 1000 t).
scene! {
    HELD_POST, 3.0,
    mechanism HeldPost {
        ground frame at (0, 0, 0);
        body post near (0, 10, 0);
        joint pin: revolute(frame, post @ (0, -10));
        driver hold: angle(post) = 0;
        load push: force(post) = (100 * t, 0);
    }
}

// Issue 20: a prismatic joint on a prismatic body, declared carriage first and tool first
// (the fixed stage, ordered by coordinate, then listed the joints in another order).
scene! {
    STACKED, 2.0,
    mechanism Stacked {
        ground frame at (0, 0, 0);
        body carriage near (5, 0, 0) mass 2 inertia 0.5 centre (0.3, 0.2);
        body tool near (7, 3, 0) mass 1 inertia 0.2 centre (-0.1, 0.4);
        joint rail: prismatic(frame, carriage, along (1, 0));
        joint lift: prismatic(carriage @ (2, 0), tool, along (0, 1));
        driver x: travel(rail) = 5 + sin(2 * t);
        driver y: travel(lift) = 3 + t^2;
        gravity (0, -9.81);
        load push: force(tool @ (1, 1)) = (10 * t, 20 * t);
    }
}

scene! {
    STACKED_REVERSED, 2.0,
    mechanism StackedReversed {
        ground frame at (0, 0, 0);
        body tool near (7, 3, 0) mass 1 inertia 0.2 centre (-0.1, 0.4);
        body carriage near (5, 0, 0) mass 2 inertia 0.5 centre (0.3, 0.2);
        joint rail: prismatic(frame, carriage, along (1, 0));
        joint lift: prismatic(carriage @ (2, 0), tool, along (0, 1));
        driver x: travel(rail) = 5 + sin(2 * t);
        driver y: travel(lift) = 3 + t^2;
        gravity (0, -9.81);
        load push: force(tool @ (1, 1)) = (10 * t, 20 * t);
    }
}

/// Every scene's text, for checks over the whole corpus.
pub const TEXTS: [&str; 10] = [
    SINK,
    CARRIAGE,
    YOKE,
    GEARS,
    ACTUATORS,
    PRISMATIC_TORQUE,
    WELD_TORQUE,
    HELD_POST,
    STACKED,
    STACKED_REVERSED,
];
