//! Derived parameters computed from one another in a cycle (`span` from `reach`, `reach` from
//! `span`): the first use of one not yet computed is refused, asking to declare it earlier.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        param l = 2;
        param span = reach + l;
        param reach = 2 * span;
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0);
        joint pivot: revolute(frame, arm @ (-reach, 0));
        driver spin: angle(arm) = t;
    }
}

fn main() {}
