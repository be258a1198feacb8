//! A marker of an unknown kind; the error lists the two kinds.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0);
        joint pivot: revolute(frame, arm);
        driver spin: angle(arm) = t;
        marker tip: distance(frame, arm);
    }
}

fn main() {}
