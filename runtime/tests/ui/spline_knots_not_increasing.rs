//! A spline whose knots do not increase; the error points at the call and says how to write it.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Cam {
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0);
        joint pivot: revolute(frame, arm);
        driver lift: angle(arm) = spline(t, (0, 0), (1, 0.5), (0.5, 0.2));
    }
}

fn main() {}
