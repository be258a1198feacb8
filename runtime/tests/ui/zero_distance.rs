//! Zero distance (a slider-crank whose rod is a `distance` link of length 0): degenerate;
//! the error points at the `0`.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism SliderCrank {
        param omega = 10.0;
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body slider near (3, 0, 0);
        joint pivot: revolute(frame, crank);
        joint rod: distance(crank @ (1, 0), slider, 0);
        joint slide: prismatic(frame, slider, along (1, 0));
        driver spin: angle(crank) = omega * t;
    }
}

fn main() {}
