//! A scene with a free degree of freedom that lists outputs short of forces; the error points
//! at the outputs.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0) mass 1 inertia 0.1;
        joint pivot: revolute(frame, arm @ (-1, 0));
        free swing: angle(arm);
        gravity (0, -9.81);
        outputs positions, velocities, accelerations;
    }
}

fn main() {}
