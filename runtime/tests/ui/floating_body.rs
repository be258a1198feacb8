//! A body that no joint joins and no driver moves: the error names it and suggests a joint,
//! instead of a degree-of-freedom count that blames the drivers.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Pendulum {
        ground frame at (0, 0, 0);
        body rod near (1, 0, 0);
        body stray near (5, 5, 0);
        joint pivot: revolute(frame, rod);
        driver swing: angle(rod) = t;
    }
}

fn main() {}
