//! Joints that remove more freedom than the bodies have (a pendulum pinned twice, at two
//! points): neither pin repeats the other, so the error points at the last joint involved.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Pendulum {
        ground frame at (0, 0, 0);
        body bob near (1, 0, 0);
        joint pivot: revolute(frame, bob @ (-1, 0));
        joint stop: revolute(frame @ (1, 0), bob);
    }
}

fn main() {}
