//! `travel` of a joint that is not prismatic (`pivot` is revolute); the error points at `pivot`.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism SliderCrank {
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body rod near (1, 0, 0);
        body slider near (3, 0, 0);
        joint pivot: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (1, 0), rod);
        joint wrist_pin: revolute(rod @ (2, 0), slider);
        joint slide: prismatic(frame, slider, along (1, 0));
        driver stroke: travel(pivot) = 3 + sin(t);
    }
}

fn main() {}
