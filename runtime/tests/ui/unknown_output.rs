use mechgen_runtime::mechanism;

mechanism! {
    mechanism Posed {
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        joint pivot: revolute(frame, crank);
        driver spin: angle(crank) = t;
        outputs positions, accelerations;
    }
}

fn main() {}
