//! A mass on a ground body, which never moves; the error points at the clause.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        ground frame at (0, 0, 0) mass 1;
        body arm near (1, 0, 0) mass 1;
        joint pivot: revolute(frame, arm);
        driver spin: angle(arm) = t;
    }
}

fn main() {}
