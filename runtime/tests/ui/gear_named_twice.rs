//! A gear pair whose driven gear is also its carrier; the error points at the repeated body.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Pair {
        ground frame at (0, 0, 0);
        body sun near (0, 0, 0);
        body planet near (3, 0, 0);
        joint sun_axle: revolute(frame, sun);
        joint planet_axle: revolute(frame @ (3, 0), planet);
        joint mesh: gear(sun, planet, ratio -2, carrier planet);
        driver spin: angle(sun) = t;
    }
}

fn main() {}
