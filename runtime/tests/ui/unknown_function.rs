//! Unknown function (`cosh`); the error points at `cosh`, writes it with `exp` and lists the
//! supported functions.
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
        driver spin: angle(crank) = cosh(omega * t);
    }
}

fn main() {}
