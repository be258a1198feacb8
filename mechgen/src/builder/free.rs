//! The builder's `free` statements: a degree of freedom left to the equations of motion,
//! declared where a driver would go (`free NAME: angle(body) from VALUE speed RATE;`).

use super::{SceneBuilder, Value};

impl SceneBuilder {
    /// `free NAME: angle(body) from FROM speed SPEED;`: the body's angle is a free degree of
    /// freedom, at `from` (rad) and turning at `speed` (rad/s) when the integrator starts. Both
    /// are numbers or expressions in parameters (not `t`: the checker says so).
    pub fn free_angle(
        &mut self,
        name: &str,
        body: &str,
        from: impl Into<Value>,
        speed: impl Into<Value>,
    ) -> &mut Self {
        let what = format!("free `{name}`");
        self.check_name(name, &what);
        let body = self.body_ref(body, name);
        let (from, speed) = (
            self.value(from.into(), &what),
            self.value(speed.into(), &what),
        );
        self.push(format!(
            "free {name}: angle({body}) from {from} speed {speed};"
        ))
    }
}

#[cfg(test)]
mod tests {
    use crate::builder::SceneBuilder;

    #[test]
    fn a_free_angle_is_declared_where_a_driver_would_go() {
        let mut scene = SceneBuilder::new("Pendulum");
        scene.param("start", 0.5);
        scene.ground("frame", [0.0, 0.0, 0.0]);
        scene.body_with_mass("bob", [1.0, 0.0, 0.0], 2.0, 0.1, [0.0, 0.0]);
        scene.revolute("pivot", "frame", ("bob", [-1.0, 0.0]));
        scene
            .free_angle("swing", "bob", "2.0 * start", -1.5)
            .item_doc("Released at twice `start`.");
        let text = scene.build().expect("valid statements");
        assert!(
            text.contains(
                "    /// Released at twice `start`.\n    \
                 free swing: angle(bob) from 2.0 * start speed -1.5;\n"
            ),
            "{text}"
        );
    }

    #[test]
    fn bad_names_and_values_of_a_free_angle_are_reported() {
        let mut scene = SceneBuilder::new("Pendulum");
        scene.free_angle("t", "bob", f64::NAN, "1 +");
        let message = scene.build().expect_err("three errors").to_string();
        for expected in ["`t` is time", "not a finite number", "expression \"1 +\""] {
            assert!(message.contains(expected), "{message}");
        }
    }
}
