//! A positions-only scene has no velocities: asking for them does not compile.
use mechgen_runtime::{Simulation, Solver, mechanism};

mechanism! {
    mechanism Posed {
        param angle = 0.3;
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        joint pivot: revolute(frame, crank);
        driver pose: angle(crank) = angle;
        outputs positions;
    }
}

fn main() {
    let mut simulation = Simulation::new(Solver::new(Posed::default()), 0.0).unwrap();
    let state = simulation.step_to(1.0).unwrap();
    let _ = state.qd();
    let _ = state.crank().x_dot;
    let mut qd = state.q;
    let _ = simulation.solver_mut().solve_velocity(&state.q, 1.0, &mut qd);
}
