//! Spline knots closer than double precision can use: 1e-300 apart (the slopes would
//! overflow, a NaN at run time) and 1e-8 apart at 1e6 (only rounding tells them apart); each
//! error is at the later knot.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Pendulum {
        ground frame at (0, 0, 0);
        body bob near (1, 0, 0);
        body arm near (1, 0, 0);
        joint pivot: revolute(frame, bob @ (-1, 0));
        joint elbow: revolute(frame, arm @ (-1, 0));
        driver swing: angle(bob) = spline(t, (0, 0), (1e-300, 1));
        driver reach: angle(arm) = spline(t, (1e6, 0), (1000000.00000001, 1), (2e6, 2));
    }
}

fn main() {}
