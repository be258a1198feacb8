//! A parameter named `pi`, which means π; the error asks for another name.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        param pi = 3;
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0);
        joint pivot: revolute(frame, arm);
        driver spin: angle(arm) = t;
    }
}

fn main() {}
