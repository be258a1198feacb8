//! A negative mass; the error points at it and gives the positive value.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0) mass -2 inertia 0.5;
        joint pivot: revolute(frame, arm);
        driver spin: angle(arm) = t;
    }
}

fn main() {}
