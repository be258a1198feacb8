//! Joints that pass the Gruebler count (12 coordinates, 12 equations, 1 degree of freedom and 1
//! driver) but are structurally redundant: `a` and `b` are pinned together twice, so with the
//! pivot and the driver 7 equations fix their 6 coordinates, while nothing fixes `c`'s angle.
//! The Jacobian is singular in every position; each constraint of the over-determined group gets
//! the error, which names them all and the body left free.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Redundant {
        ground g at (0, 0, 0);
        body a near (1, 0, 0);
        body b near (2, 0, 0);
        body c near (0, 1, 0);
        joint pivot: revolute(g, a @ (-1, 0));
        joint pin_1: revolute(a @ (1, 0), b @ (-1, 0));
        joint pin_2: revolute(a @ (1, 1), b @ (-1, 1));
        joint hinge: revolute(g, c);
        driver spin: angle(a) = t;
    }
}

fn main() {}
