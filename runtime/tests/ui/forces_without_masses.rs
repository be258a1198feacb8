//! The `forces` output in a scene where nothing produces a force; the error points at `forces`.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Arm {
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0);
        joint pivot: revolute(frame, arm);
        driver spin: angle(arm) = t;
        gravity (0, -9.81);
        outputs positions, velocities, accelerations, forces;
    }
}

fn main() {}
