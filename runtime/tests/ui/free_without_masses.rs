//! A free degree of freedom in a scene without masses; the error points at `free`.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0);
        joint pivot: revolute(frame, arm @ (-1, 0));
        free swing: angle(arm) from 0.3;
        gravity (0, -9.81);
    }
}

fn main() {}
