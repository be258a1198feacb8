//! A parameter computed from itself (with another, so that it is a derived parameter).
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        param l = 2;
        param reach = reach + l;
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0);
        joint pivot: revolute(frame, arm @ (-reach, 0));
        driver spin: angle(arm) = t;
    }
}

fn main() {}
