//! A four-bar with a distance joint its loop already imposes: the error names the joint, at
//! its name, before the driver it leaves without freedom.
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
        joint extra: distance(frame @ (80, 0), rocker @ (50, 0), 50);
        driver spin: angle(crank) = t;
    }
}

fn main() {}
