//! A marker named `reactions` in a scene that computes forces: its accessor would clash.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0) mass 1 inertia 0.1;
        joint pivot: revolute(frame, arm);
        driver spin: angle(arm) = t;
        marker reactions: arm @ (1, 0);
    }
}

fn main() {}
