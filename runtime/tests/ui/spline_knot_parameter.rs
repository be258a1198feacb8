//! A spline knot written with a parameter: knots fix the spline's table at compile time.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Cam {
        param rise = 0.5;
        ground frame at (0, 0, 0);
        body follower near (0, 0, 0);
        joint pivot: revolute(frame, follower);
        driver lift: angle(follower) = spline(t, (0, 0), (rise, 1), (1, 0));
    }
}

fn main() {}
