//! A stiffness without its free length; the error points at the stiffness.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0) mass 1;
        joint pivot: revolute(frame, arm);
        driver spin: angle(arm) = t;
        load coil: spring(frame @ (0, 2), arm, stiffness 40);
    }
}

fn main() {}
