//! A pin at 1e20 mm on a 43 mm crank: double precision cannot resolve both lengths in one
//! scene, and the error points at the large one.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Pendulum {
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body rod near (40, 0, 0);
        joint pivot: revolute(frame, crank);
        joint pin: revolute(crank @ (43, 0), rod @ (1e20, 0));
        joint end: revolute(rod @ (0, 0), frame @ (100, 0));
    }
}

fn main() {}
