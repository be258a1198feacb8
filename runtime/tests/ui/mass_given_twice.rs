//! A mass given twice; the error points at the second.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0) mass 1 inertia 2 mass 3;
        joint pivot: revolute(frame, arm);
        driver spin: angle(arm) = t;
    }
}

fn main() {}
