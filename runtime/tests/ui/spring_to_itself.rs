//! A spring between two points of one body; the error points at the second.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0) mass 1;
        joint pivot: revolute(frame, arm);
        driver spin: angle(arm) = t;
        load coil: spring(arm, arm @ (1, 0), stiffness 40, length 1);
    }
}

fn main() {}
