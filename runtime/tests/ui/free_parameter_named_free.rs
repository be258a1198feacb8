//! A parameter named `free` in a scene with a free degree of freedom (whose state the struct
//! keeps in a field named `free`); the error points at the parameter.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        /// Initial angle.
        param free = 0.3;
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0) mass 1 inertia 0.1;
        joint pivot: revolute(frame, arm @ (-1, 0));
        free swing: angle(arm) from free;
        gravity (0, -9.81);
    }
}

fn main() {}
