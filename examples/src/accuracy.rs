//! The accuracy measure every example, test and report uses: the maximum error of q, q̇ and q̈
//! over a motion, each relative to that quantity's largest magnitude over the same motion.
//!
//! Relative to the largest magnitude (not entry by entry) because coordinates pass through zero:
//! a per-entry relative error is meaningless there, while this measure has the units-free reading
//! "digits correct at the scale of the motion".

use crate::closed_form::Kinematics;

/// Maximum errors of one motion, each relative to the quantity's largest exact magnitude.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RelativeErrors {
    /// Positions q.
    pub q: f64,
    /// Velocities q̇.
    pub qd: f64,
    /// Accelerations q̈.
    pub qdd: f64,
}

impl RelativeErrors {
    /// The worst of the three.
    pub fn max(&self) -> f64 {
        self.q.max(self.qd).max(self.qdd)
    }
}

/// Accumulates solved states against the closed form.
#[derive(Debug, Clone, Copy, Default)]
pub struct ErrorTracker {
    error: [f64; 3],
    magnitude: [f64; 3],
    /// Set when a solved value was not finite: the errors are then reported as infinite.
    non_finite: bool,
}

impl ErrorTracker {
    /// An empty tracker.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one solved state (q, q̇, q̈ in the closed form's coordinate order).
    pub fn add<const N: usize>(
        &mut self,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        exact: &Kinematics<N>,
    ) {
        for (k, (solved, reference)) in [(q, &exact.q), (qd, &exact.qd), (qdd, &exact.qdd)]
            .into_iter()
            .enumerate()
        {
            for (s, r) in solved.iter().zip(reference.iter()) {
                if !s.is_finite() {
                    self.non_finite = true;
                }
                self.error[k] = self.error[k].max((s - r).abs());
                self.magnitude[k] = self.magnitude[k].max(r.abs());
            }
        }
    }

    /// The relative errors so far (a quantity that is zero throughout reports its absolute error).
    pub fn errors(&self) -> RelativeErrors {
        if self.non_finite {
            return RelativeErrors {
                q: f64::INFINITY,
                qd: f64::INFINITY,
                qdd: f64::INFINITY,
            };
        }
        let rel = |k: usize| {
            if self.magnitude[k] > 0.0 {
                self.error[k] / self.magnitude[k]
            } else {
                self.error[k]
            }
        };
        RelativeErrors {
            q: rel(0),
            qd: rel(1),
            qdd: rel(2),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_are_relative_to_the_largest_magnitude() {
        let exact = Kinematics {
            t: 0.0,
            q: [10.0, 0.0],
            qd: [1.0, -2.0],
            qdd: [0.0, 0.0],
        };
        let mut tracker = ErrorTracker::new();
        tracker.add(&[10.0, 0.01], &[1.0, -2.0], &[0.5, 0.0], &exact);
        let e = tracker.errors();
        assert_eq!(e.q, 0.01 / 10.0);
        assert_eq!(e.qd, 0.0);
        assert_eq!(e.qdd, 0.5);
        tracker.add(&[f64::NAN, 0.0], &[1.0, -2.0], &[0.0, 0.0], &exact);
        assert!(tracker.errors().max().is_infinite());
    }
}
