//! `atan2` with one argument; the error shows how it is called.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0);
        joint pivot: revolute(frame, arm);
        driver spin: angle(arm) = atan2(t);
    }
}

fn main() {}
