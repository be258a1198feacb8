//! Constant geometry that folds to NaN (`sqrt` of a negative number, `ln(0)`): each is an
//! error at its tokens, not a NaN at run time.
use mechgen_runtime::mechanism;

mechanism! {
    mechanism Pendulum {
        ground frame at (0, 0, 0);
        body rod near (1, 0, 0);
        joint pivot: revolute(frame @ (sqrt(0 - 1), 0), rod @ (ln(0), 0));
        driver swing: angle(rod) = t;
    }
}

fn main() {}
