//! Several semantic errors in one scene are all reported together, each at its own span, in the
//! order the checker finds them: duplicate name, unknown name, self-joint, unknown body, driver
//! on a ground body, unknown function.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism SliderCrank {
        param omega = 10.0;
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body rod near (1, 0, 0);
        body slider near (3, 0, 0);
        joint crank: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (len, 0), rod);
        joint wrist_pin: revolute(rod @ (2, 0), rod);
        joint slide: prismatic(frame, wheel, along (1, 0));
        driver spin: angle(frame) = omega * tanh(t);
    }
}

fn main() {}
