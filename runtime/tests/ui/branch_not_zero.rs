//! A branch invariant compared with something other than 0; only its sign is an invariant,
//! so the error points at the right-hand side and asks for `> 0` or `< 0`.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism SliderCrank {
        param omega = 10.0;
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body rod near (1, 0, 0);
        body slider near (3, 0, 0);
        joint pivot: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (1, 0), rod);
        joint wrist_pin: revolute(rod @ (2, 0), slider);
        joint slide: prismatic(frame, slider, along (1, 0));
        driver spin: angle(crank) = omega * t;

        branch outboard: dot(frame -> slider, crank -> rod @ (2, 0)) > 1.5;
    }
}

fn main() {}
