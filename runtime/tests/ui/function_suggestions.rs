//! Functions of other languages and typos: each call points at what to write instead
//! (`atan2(y, x)` for `atan`, the power operator for `pow`, `sin` for `sinn`).
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Pendulum {
        ground frame at (0, 0, 0);
        body bob near (1, 0, 0);
        joint pivot: revolute(frame, bob @ (-1, 0));
        driver swing: angle(bob) = atan(t) + pow(t, 2) + sinn(t);
    }
}

fn main() {}
