//! An integer exponent beyond what differentiation can lower: the error is at the exponent
//! and says how to write a real power instead.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Pendulum {
        ground frame at (0, 0, 0);
        body bob near (1, 0, 0);
        joint pivot: revolute(frame, bob @ (-1, 0));
        driver swing: angle(bob) = t^2147483648;
    }
}

fn main() {}
