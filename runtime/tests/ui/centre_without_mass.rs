//! A centre of mass without a mass; the error points at `centre`.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0) inertia 0.5 centre (0.5, 0);
        joint pivot: revolute(frame, arm);
        driver spin: angle(arm) = t;
    }
}

fn main() {}
