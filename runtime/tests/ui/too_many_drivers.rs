//! More drivers than degrees of freedom (three drivers, one degree of freedom); one error at
//! each extra driver's name (`push`, `lift`), the first driver being accepted.
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
        driver push: x(slider) = 3 + t;
        driver lift: y(rod @ (1, 0)) = 0;
    }
}

fn main() {}
