//! A negative distance: the error says a distance cannot be negative and gives its magnitude.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism SliderCrank {
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body slider near (3, 0, 0);
        joint pivot: revolute(frame, crank);
        joint rod: distance(crank @ (1, 0), slider, -2.5);
        joint slide: prismatic(frame, slider, along (1, 0));
        driver spin: angle(crank) = t;
    }
}

fn main() {}
