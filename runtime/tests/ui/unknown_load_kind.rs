//! A load kind that does not exist; the error lists the kinds.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0) mass 1;
        joint pivot: revolute(frame, arm);
        driver spin: angle(arm) = t;
        load push: pressure(arm) = 3;
    }
}

fn main() {}
