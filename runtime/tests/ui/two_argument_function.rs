//! `atan2(y, x)` is not supported: the error lists the functions that are.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Pendulum {
        ground frame at (0, 0, 0);
        body rod near (1, 0, 0);
        joint pivot: revolute(frame, rod);
        driver swing: angle(rod) = atan2(t, 1);
    }
}

fn main() {}
