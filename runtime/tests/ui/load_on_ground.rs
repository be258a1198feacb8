//! A force on a ground body, which never moves; the error points at the body.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0) mass 1;
        joint pivot: revolute(frame, arm);
        driver spin: angle(arm) = t;
        load push: force(frame @ (1, 0)) = (t, 0);
    }
}

fn main() {}
