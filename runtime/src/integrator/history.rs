//! The free accelerations of the last accepted steps, for the predictor: `ü_{n+1}`
//! extrapolated by the polynomial through `ü_n` and up to [`DEPTH`] earlier values (Newton's
//! form over the steps' times, so uneven steps are fine).
//!
//! On a smooth motion a polynomial through `k + 1` points is `O((ωh)^{k+1})` off relative to
//! `ü`: the cubic's `(ωh)⁴`, 1e-12 on the free seed at 0.1 ms, is below the Newton tolerance,
//! so a step ends at its first evaluation (the correction it calls for already below the
//! tolerance) where the linear extrapolation, `(ωh)²` off, needed a second one. Extrapolating
//! amplifies the values' own errors (the cubic's weights at even steps are 4, −6, 4, −1), so
//! the values kept are the accepted accelerations plus the Newton correction their step still
//! called for (not applied: the step was accepted without it), which is what brings the
//! free seed to one evaluation per step (with the bare accelerations, 1.7).

use nalgebra::{DefaultAllocator, Dim, OVector, U1};

use crate::mechanism::Storage;

/// How many accelerations before `ü_n` the predictor uses at most (3: a cubic).
pub(crate) const DEPTH: usize = 3;

/// The best estimate of the current `ü` and its values at the last [`DEPTH`] accepted steps
/// before, newest first, with how far each lies behind the current time.
pub(crate) struct History<F: Dim>
where
    DefaultAllocator: Storage<F>,
{
    /// The current accelerations with the Newton correction their step still called for (not
    /// applied: the step was accepted without it), a better value to extrapolate from.
    current: OVector<f64, F>,
    past: [OVector<f64, F>; DEPTH],
    /// `t_n − t_{n−j−1}` of `past[j]`.
    ages: [f64; DEPTH],
    /// How many of `past` hold values (0 after a restart).
    count: usize,
}

impl<F: Dim> Clone for History<F>
where
    DefaultAllocator: Storage<F>,
{
    fn clone(&self) -> Self {
        Self {
            current: self.current.clone(),
            past: self.past.clone(),
            ages: self.ages,
            count: self.count,
        }
    }
}

impl<F: Dim> History<F>
where
    DefaultAllocator: Storage<F>,
{
    /// An empty history for `f` free degrees of freedom.
    pub fn new(f: F) -> Self {
        Self {
            current: OVector::zeros_generic(f, U1),
            past: core::array::from_fn(|_| OVector::zeros_generic(f, U1)),
            ages: [0.0; DEPTH],
            count: 0,
        }
    }

    /// Starts over from accelerations `udd` (a restart: the motion before it does not
    /// continue).
    pub fn restart(&mut self, udd: &OVector<f64, F>) {
        self.current.copy_from(udd);
        self.count = 0;
    }

    /// Records an accepted step of size `h` to accelerations `udd`, whose last Newton
    /// correction was `correction`.
    pub fn accept(&mut self, udd: &OVector<f64, F>, correction: &OVector<f64, F>, h: f64) {
        // Rotating moves the vectors (for `Dyn` ones, their pointers): nothing allocates.
        self.past.rotate_right(1);
        self.ages.rotate_right(1);
        core::mem::swap(&mut self.past[0], &mut self.current);
        self.ages[0] = 0.0;
        for age in &mut self.ages {
            *age += h;
        }
        self.count = (self.count + 1).min(DEPTH);
        self.current.copy_from(udd);
        self.current += correction;
    }

    /// Writes into `out` the accelerations extrapolated to `h` past the current time, each
    /// free degree of freedom's by the polynomial in Newton's form through its current value
    /// and its history, term by term while the terms shrink: on a resolved motion each is
    /// about `ωh` times the last, and a term that grows says the history does not resolve the
    /// motion, where a higher order would only extrapolate further off (the linear term is
    /// always taken, as the predictor has always done).
    pub fn extrapolate(&self, h: f64, out: &mut OVector<f64, F>) {
        // Nodes relative to the current time: 0, then −ages.
        let mut nodes = [0.0; DEPTH + 1];
        for (node, age) in nodes[1..].iter_mut().zip(&self.ages) {
            *node = -age;
        }
        let points = self.count + 1;
        for k in 0..out.len() {
            // Divided differences, in place: `table[j]` becomes f[x_0, …, x_j].
            let mut table = [0.0; DEPTH + 1];
            table[0] = self.current[k];
            for (entry, past) in table[1..points].iter_mut().zip(&self.past) {
                *entry = past[k];
            }
            for order in 1..points {
                for j in (order..points).rev() {
                    table[j] = (table[j] - table[j - 1]) / (nodes[j] - nodes[j - order]);
                }
            }
            let (mut value, mut span, mut last) = (table[0], 1.0, f64::INFINITY);
            for order in 1..points {
                span *= h - nodes[order - 1];
                let term = table[order] * span;
                // A growing term stops; so does a NaN.
                let shrinks = term.abs() <= last;
                if !shrinks {
                    break;
                }
                value += term;
                last = term.abs();
            }
            out[k] = value;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Const, Vector1};

    /// A cubic in time is extrapolated exactly from four values at uneven steps, a line from
    /// two; a history whose terms grow stops at the linear one; a restart drops to "ü
    /// unchanged".
    #[test]
    fn polynomials_up_to_the_depth_are_extrapolated_exactly() {
        let cubic = |t: f64| 2.0 - 3.0 * t + 0.5 * t * t - 0.2 * t * t * t;
        let none = Vector1::zeros();
        let mut history = History::new(Const::<1>);
        history.restart(&Vector1::new(cubic(0.0)));
        let mut t = 0.0;
        for h in [0.1, 0.07, 0.13] {
            t += h;
            history.accept(&Vector1::new(cubic(t)), &none, h);
        }
        let mut out = Vector1::zeros();
        let h = 0.09;
        history.extrapolate(h, &mut out);
        assert!(
            (out[0] - cubic(t + h)).abs() < 1e-12,
            "{} {}",
            out[0],
            cubic(t + h)
        );
        // One value behind: a line; the correction counts in the value extrapolated from.
        let line = |t: f64| 1.0 + 4.0 * t;
        let mut history = History::new(Const::<1>);
        history.restart(&Vector1::new(line(0.0)));
        history.accept(&Vector1::new(line(0.2) - 0.5), &Vector1::new(0.5), 0.2);
        history.extrapolate(0.05, &mut out);
        assert!((out[0] - line(0.25)).abs() < 1e-14);
        // A history that does not resolve the motion (an alternation, each term larger than
        // the last) is extrapolated linearly, from the last two values only.
        let mut history = History::new(Const::<1>);
        history.restart(&Vector1::new(0.0));
        for (value, h) in [(5.0, 0.1), (-5.0, 0.1), (1.0, 0.1)] {
            history.accept(&Vector1::new(value), &none, h);
        }
        history.extrapolate(0.1, &mut out);
        assert!((out[0] - 7.0).abs() < 1e-12, "{}", out[0]);
        // After a restart: the accelerations unchanged.
        history.restart(&Vector1::new(line(0.2)));
        history.extrapolate(0.05, &mut out);
        assert_eq!(out[0], line(0.2));
    }
}
