//! A named point given an offset: a point of its body is written with the body's name.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0) mass 1 inertia 1;
        point tip: arm @ (2, 0);
        joint pivot: revolute(frame, arm);
        driver spin: angle(arm) = t;
        marker m: tip @ (1, 0);
    }
}

fn main() {}
