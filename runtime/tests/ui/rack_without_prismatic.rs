//! A rack on a joint that is not prismatic; the error points at the joint and says what a rack
//! needs.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Rack {
        ground frame at (0, 0, 0);
        body pinion near (0, 0, 0);
        body bar near (0, -1, 0);
        joint axle: revolute(frame, pinion);
        joint hinge: revolute(frame @ (0, -1), bar);
        joint teeth: rack(hinge, pinion, ratio 0.5);
        driver spin: angle(pinion) = t;
    }
}

fn main() {}
