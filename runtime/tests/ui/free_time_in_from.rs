//! A free degree of freedom's initial value written in time; the error points at `t`.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0) mass 1 inertia 0.1;
        joint pivot: revolute(frame, arm @ (-1, 0));
        free swing: angle(arm) from 2 * t;
        gravity (0, -9.81);
    }
}

fn main() {}
