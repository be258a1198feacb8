//! Markers: outputs computed from the solved state, as expressions in q, q̇, q̈ and the
//! parameters. A tracked point is its world position `r + A(θ) s`; an angle sensor is
//! `θ_b − θ_a`. Their rates are time derivatives along the motion (q, q̇ and t independent
//! symbols, the second reading q̈), taken only as far as the scene's outputs go, so a
//! positions-only scene gets positions only.

use crate::expr::Id;
use crate::expr::diff::Differentiator;
use crate::model::frames::{Frames, ground_poses};
use crate::model::{MarkerKind, Model, Outputs};

/// Every marker's values in layout order ([`Model::marker_names`]): its positions, then their
/// velocities, then their accelerations, as the outputs go.
pub fn values(model: &mut Model) -> Vec<Id> {
    let kinds: Vec<MarkerKind> = model.markers.iter().map(|m| m.kind).collect();
    let levels = match model.outputs {
        Outputs::Positions => 1,
        Outputs::Velocities => 2,
        Outputs::Accelerations | Outputs::Forces => 3,
    };
    let poses = ground_poses(model);
    let mut f = Frames {
        arena: &mut model.arena,
        poses: &poses,
    };
    let mut d = Differentiator::new();
    let mut values = Vec::new();
    for kind in kinds {
        let mut level: Vec<Id> = match kind {
            MarkerKind::Point(p) => f.world_point(p).to_vec(),
            MarkerKind::Angle(a, b) => {
                let (tb, ta) = (f.pose(b, 2), f.pose(a, 2));
                vec![f.arena.sub(tb, ta)]
            }
        };
        for k in 0..levels {
            if k > 0 {
                level = level
                    .iter()
                    .map(|&v| d.time_derivative(f.arena, v))
                    .collect();
            }
            values.extend(&level);
        }
    }
    values
}

#[cfg(test)]
mod tests {
    use crate::expr::tape::{Env, eval};

    #[test]
    fn a_point_and_an_angle_with_their_rates() {
        let scene = crate::compile(
            crate::Input::Text(
                "mechanism M {
                ground frame at (0, 0, 0);
                body arm near (0, 0, 0);
                body hand near (2, 0, 0);
                joint shoulder: revolute(frame, arm);
                joint elbow: revolute(arm @ (2, 0), hand);
                driver lift: angle(arm) = t;
                driver bend: relative_angle(arm, hand) = t;
                marker tip: hand @ (1, 0);
                marker wrist: angle(arm, hand);
            }",
            ),
            &crate::Options::default(),
        )
        .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            scene.model.marker_names(),
            [
                "tip.x",
                "tip.y",
                "tip.x_dot",
                "tip.y_dot",
                "tip.x_ddot",
                "tip.y_ddot",
                "wrist.angle",
                "wrist.angle_dot",
                "wrist.angle_ddot"
            ]
        );
        // hand at (0, 2) turned π (the arm turned a quarter, the hand a quarter more), moving.
        let env = Env {
            q: vec![
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                std::f64::consts::FRAC_PI_2,
                0.0,
                2.0,
                std::f64::consts::PI,
            ],
            qd: vec![0.0, 0.0, 0.0, 0.0, 0.0, 1.0, -2.0, 0.0, 2.0],
            qdd: vec![0.0; 9],
            t: 0.0,
            params: vec![],
            free: Vec::new(),
        };
        let values: Vec<f64> = scene
            .kinematics
            .markers
            .iter()
            .map(|&v| eval(&scene.model.arena, v, &env))
            .collect();
        // The tip at (−1, 2), r = (−1, 0) from the hand: velocity (−2, 0) + θ̇ R r = (−2, −2),
        // acceleration −θ̇² r = (4, 0).
        let expected = [
            -1.0,
            2.0,
            -2.0,
            -2.0,
            4.0,
            0.0,
            std::f64::consts::FRAC_PI_2,
            1.0,
            0.0,
        ];
        for (v, e) in values.iter().zip(expected) {
            assert!((v - e).abs() < 1e-12, "{values:?}");
        }
    }
}
