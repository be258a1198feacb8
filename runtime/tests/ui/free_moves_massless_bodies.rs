//! A free degree of freedom that moves only a massless body while another body has mass; the
//! error points at its name and names the body.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism TwoArms {
        ground frame at (0, 0, 0);
        body heavy near (1, 0, 0) mass 2 inertia 0.1;
        body light near (0, 1, 0);
        joint left: revolute(frame, heavy @ (-1, 0));
        joint right: revolute(frame, light @ (0, -1));
        free swing: angle(heavy);
        free flap: angle(light) from 0.1;
        gravity (0, -9.81);
    }
}

fn main() {}
