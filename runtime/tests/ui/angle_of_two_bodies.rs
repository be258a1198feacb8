//! `angle(a, b)` drives one body's angle only: the error suggests `relative_angle(a, b)`.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Pendulum {
        ground frame at (0, 0, 0);
        body rod near (1, 0, 0);
        joint pivot: revolute(frame, rod);
        driver swing: angle(rod, frame) = t;
    }
}

fn main() {}
