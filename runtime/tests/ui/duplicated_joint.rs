//! A four-bar whose rocker is pinned to the frame twice: the error is at the second pin's
//! name, which it names first.
use mechgen_runtime::mechanism;

mechanism! {
    pub mechanism CrankRocker {
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body coupler near (20, 0, 0.9);
        body rocker near (80, 0, 1.6);
        joint pivot: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (20, 0), coupler);
        joint rocker_pin: revolute(coupler @ (70, 0), rocker @ (50, 0));
        joint rocker_pivot: revolute(rocker, frame @ (80, 0));
        joint extra: revolute(frame @ (80, 0), rocker);
        driver spin: angle(crank) = t;
    }
}

fn main() {}
