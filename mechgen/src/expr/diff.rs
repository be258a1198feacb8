//! Symbolic differentiation on the expression DAG.
//!
//! Results are built with the arena's simplifying constructors, so a derivative that is
//! identically zero comes back as [`Arena::zero`] and the Jacobian's sparsity falls out of it.
//! Derivatives are memoised per (node, variable): shared sub-expressions are differentiated once
//! and their derivatives are shared too.

use std::collections::HashMap;

use crate::expr::{Arena, Func, Func2, Id, Node, Var};

/// Differentiates expressions of one arena, remembering what it has done.
#[derive(Debug, Default)]
pub struct Differentiator {
    memo: HashMap<(Id, Var), Id>,
}

impl Differentiator {
    /// A differentiator with an empty memo.
    pub fn new() -> Self {
        Self::default()
    }

    /// ∂e/∂var.
    // Kept whole: one arm per node kind, each its derivative rule.
    pub fn diff(&mut self, arena: &mut Arena, e: Id, var: Var) -> Id {
        if let Some(&d) = self.memo.get(&(e, var)) {
            return d;
        }
        let d = match arena.node(e) {
            Node::Const(_) | Node::Param(_) => arena.zero(),
            Node::Var(v) if v == var => arena.one(),
            Node::Var(_) => arena.zero(),
            Node::Neg(a) => {
                let da = self.diff(arena, a, var);
                arena.neg(da)
            }
            Node::Add(a, b) => {
                let (da, db) = (self.diff(arena, a, var), self.diff(arena, b, var));
                arena.add(da, db)
            }
            Node::Sub(a, b) => {
                let (da, db) = (self.diff(arena, a, var), self.diff(arena, b, var));
                arena.sub(da, db)
            }
            Node::Mul(a, b) => {
                let (da, db) = (self.diff(arena, a, var), self.diff(arena, b, var));
                let left = arena.mul(da, b);
                let right = arena.mul(a, db);
                arena.add(left, right)
            }
            Node::Div(a, b) => {
                // d(a/b) = da/b − (a/b)·db/b keeps a/b (already computed) shared.
                let (da, db) = (self.diff(arena, a, var), self.diff(arena, b, var));
                let first = arena.div(da, b);
                let ratio = arena.div(e, b);
                let second = arena.mul(ratio, db);
                arena.sub(first, second)
            }
            Node::Powi(a, n) => {
                let da = self.diff(arena, a, var);
                let n_const = arena.constant(f64::from(n));
                let lowered = arena.powi(a, n - 1);
                let factor = arena.mul(n_const, lowered);
                arena.mul(factor, da)
            }
            Node::Call(f, a) => {
                let da = self.diff(arena, a, var);
                if arena.is_zero(da) && arena.simplifies() {
                    arena.zero()
                } else {
                    let outer = outer_derivative(arena, f, a, e);
                    arena.mul(outer, da)
                }
            }
            Node::Call2(f, a, b) => {
                let (da, db) = (self.diff(arena, a, var), self.diff(arena, b, var));
                binary_derivative(arena, f, [a, b], [da, db], e)
            }
            // The selected branch's derivative: at a = b, the `x` branch's (one-sided).
            Node::Select(a, b, x, y) => {
                let (dx, dy) = (self.diff(arena, x, var), self.diff(arena, y, var));
                arena.select(a, b, dx, dy)
            }
            Node::Spline { table, order, x } => {
                let dx = self.diff(arena, x, var);
                if arena.is_zero(dx) && arena.simplifies() {
                    arena.zero()
                } else {
                    let outer = arena.spline(table, order.saturating_add(1), x);
                    arena.mul(outer, dx)
                }
            }
            // d/dt raises the order; the acceleration's derivative is zero (`Arena::free`):
            // a driver's value is differentiated at most twice (γ needs Φ_tt), so no kernel
            // ever reads a third derivative of the state.
            Node::Free { dof, order, t } => {
                let dt = self.diff(arena, t, var);
                if arena.is_zero(dt) && arena.simplifies() {
                    arena.zero()
                } else {
                    let rate = arena.free(dof, order.saturating_add(1), t);
                    arena.mul(rate, dt)
                }
            }
        };
        self.memo.insert((e, var), d);
        d
    }

    /// The time derivative of `e` along the motion, `Σ ∂e/∂q_k q̇_k + Σ ∂e/∂q̇_k q̈_k + ∂e/∂t`
    /// (q, q̇ and t independent symbols; `e` reads no q̈ or λ).
    pub fn time_derivative(&mut self, arena: &mut Arena, e: Id) -> Id {
        let mut total = arena.zero();
        for var in arena.variables(e) {
            let rate = match var {
                Var::Q(k) => arena.var(Var::Qd(k)),
                Var::Qd(k) => arena.var(Var::Qdd(k)),
                Var::T => arena.one(),
                Var::Qdd(_) | Var::Lambda(_) => continue,
            };
            let partial = self.diff(arena, e, var);
            let term = arena.mul(partial, rate);
            total = arena.add(total, term);
        }
        total
    }
}

/// f'(a) for `e = f(a)`, written in terms of nodes that usually exist already.
fn outer_derivative(arena: &mut Arena, f: Func, a: Id, e: Id) -> Id {
    match f {
        Func::Sin => arena.cos(a),
        Func::Cos => {
            let s = arena.sin(a);
            arena.neg(s)
        }
        Func::Tan => {
            let squared = arena.powi(e, 2);
            let one = arena.one();
            arena.add(one, squared)
        }
        Func::Exp => e,
        Func::Ln => {
            let one = arena.one();
            arena.div(one, a)
        }
        Func::Sqrt => {
            let two = arena.constant(2.0);
            let twice = arena.mul(two, e);
            let one = arena.one();
            arena.div(one, twice)
        }
        // ±1/√(1 − a²): infinite at ±1, where the solver then reports a non-finite Jacobian.
        Func::Asin | Func::Acos => {
            let one = arena.one();
            let square = arena.powi(a, 2);
            let rest = arena.sub(one, square);
            let root = arena.call(Func::Sqrt, rest);
            let inverse = arena.div(one, root);
            if f == Func::Asin {
                inverse
            } else {
                arena.neg(inverse)
            }
        }
    }
}

/// d f(a, b) for `e = f(a, b)`, given `da` and `db`.
fn binary_derivative(arena: &mut Arena, f: Func2, [a, b]: [Id; 2], [da, db]: [Id; 2], e: Id) -> Id {
    match f {
        // atan2(y, x): (x dy − y dx) / (x² + y²).
        Func2::Atan2 => {
            let (x_dy, y_dx) = (arena.mul(b, da), arena.mul(a, db));
            let numerator = arena.sub(x_dy, y_dx);
            let (xx, yy) = (arena.powi(b, 2), arena.powi(a, 2));
            let denominator = arena.add(xx, yy);
            arena.div(numerator, denominator)
        }
        // a^b: b a^(b−1) da, plus a^b ln(a) db when the exponent varies.
        Func2::Pow => {
            let one = arena.one();
            let lowered_exponent = arena.sub(b, one);
            let lowered = arena.call2(Func2::Pow, a, lowered_exponent);
            let factor = arena.mul(b, lowered);
            let base_term = arena.mul(factor, da);
            if arena.is_zero(db) && arena.simplifies() {
                base_term
            } else {
                let log = arena.call(Func::Ln, a);
                let scaled = arena.mul(e, log);
                let exponent_term = arena.mul(scaled, db);
                arena.add(base_term, exponent_term)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::tape::{Env, eval};

    /// Central difference of `e` in `var` at the environment, for checking rules numerically.
    fn numeric(arena: &Arena, e: Id, env: &Env, var: Var) -> f64 {
        let h = 1e-6;
        let shifted = |delta: f64| {
            let mut env = env.clone();
            match var {
                Var::Q(k) => env.q[k as usize] += delta,
                Var::Qd(k) => env.qd[k as usize] += delta,
                Var::Qdd(k) => env.qdd[k as usize] += delta,
                Var::Lambda(_) => unreachable!("no multipliers in these expressions"),
                Var::T => env.t += delta,
            }
            eval(arena, e, &env)
        };
        (shifted(h) - shifted(-h)) / (2.0 * h)
    }

    #[test]
    fn every_rule_matches_central_differences() {
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let y = a.var(Var::Q(1));
        let t = a.var(Var::T);
        let mut cases = Vec::new();
        for f in Func::ALL {
            let inner = a.mul(x, y);
            cases.push(a.call(f, inner));
        }
        let quotient = a.div(x, y);
        cases.push(quotient);
        let small = a.constant(0.3);
        let scaled = a.mul(small, x);
        cases.push(a.call(Func::Asin, scaled));
        cases.push(a.call(Func::Acos, scaled));
        cases.push(a.call2(Func2::Atan2, y, x));
        cases.push(a.call2(Func2::Pow, x, y));
        let half = a.constant(2.5);
        cases.push(a.call2(Func2::Pow, y, half));
        cases.push(a.select(x, y, quotient, scaled));
        let table = crate::expr::spline::SplineTable::natural(
            &[0.0, 0.5, 1.0, 2.0],
            &[1.0, 0.2, 0.4, -1.0],
        )
        .expect("a valid spline");
        let table = a.add_spline(table);
        let product = a.mul(x, y);
        cases.push(a.spline(table, 0, product));
        cases.push(a.powi(x, 3));
        cases.push(a.powi(y, -2));
        let st = a.sin(t);
        cases.push(a.sub(st, x));
        let env = Env {
            q: vec![0.7, 1.3],
            qd: vec![0.0, 0.0],
            qdd: vec![],
            t: 0.4,
            params: vec![],
            free: Vec::new(),
        };
        let mut d = Differentiator::new();
        for &e in &cases {
            for var in [Var::Q(0), Var::Q(1), Var::T] {
                let de = d.diff(&mut a, e, var);
                let exact = eval(&a, de, &env);
                let approx = numeric(&a, e, &env, var);
                assert!(
                    (exact - approx).abs() <= 1e-7 * (1.0 + exact.abs()),
                    "{:?} wrt {var:?}: {exact} vs {approx}",
                    a.node(e)
                );
            }
        }
    }

    #[test]
    fn time_derivatives_follow_the_motion() {
        // d/dt (x sin θ + t²) = ẋ sin θ + x cos θ θ̇ + 2t, and once more with ẍ and θ̈.
        let mut a = Arena::new();
        let (x, th, t) = (a.var(Var::Q(0)), a.var(Var::Q(1)), a.var(Var::T));
        let s = a.sin(th);
        let xs = a.mul(x, s);
        let t2 = a.powi(t, 2);
        let e = a.add(xs, t2);
        let mut d = Differentiator::new();
        let rate = d.time_derivative(&mut a, e);
        let second = d.time_derivative(&mut a, rate);
        let env = Env {
            q: vec![1.5, 0.3],
            qd: vec![-0.7, 2.0],
            qdd: vec![0.4, -1.1],
            t: 0.8,
            params: vec![],
            free: Vec::new(),
        };
        let [x, th] = [1.5_f64, 0.3];
        let [xd, thd] = [-0.7_f64, 2.0];
        let [xdd, thdd] = [0.4_f64, -1.1];
        let exact_rate = xd * th.sin() + x * th.cos() * thd + 2.0 * 0.8;
        let exact_second = xdd * th.sin() + 2.0 * xd * th.cos() * thd - x * th.sin() * thd * thd
            + x * th.cos() * thdd
            + 2.0;
        assert!((eval(&a, rate, &env) - exact_rate).abs() < 1e-14);
        assert!((eval(&a, second, &env) - exact_second).abs() < 1e-14);
    }

    #[test]
    fn derivative_of_sin_shares_cos_and_zero_is_structural() {
        let mut a = Arena::new();
        let th = a.var(Var::Q(2));
        let s = a.sin(th);
        let mut d = Differentiator::new();
        let ds = d.diff(&mut a, s, Var::Q(2));
        assert_eq!(ds, a.cos(th));
        let dx = d.diff(&mut a, s, Var::Q(0));
        let dt = d.diff(&mut a, s, Var::T);
        assert!(a.is_zero(dx) && a.is_zero(dt));
    }

    #[test]
    fn a_free_state_differentiates_along_time_to_its_rate_then_acceleration() {
        // Φ = x − u(t) for a free u: Φ_t = −u̇, Φ_tt = −ü, and ü's own derivative is zero (the
        // integrator's state ends at the acceleration).
        let mut a = Arena::new();
        let (x, t) = (a.var(Var::Q(0)), a.var(Var::T));
        let u = a.free(1, 0, t);
        let phi = a.sub(x, u);
        let mut d = Differentiator::new();
        let phi_t = d.diff(&mut a, phi, Var::T);
        let phi_tt = d.diff(&mut a, phi_t, Var::T);
        let (rate, acceleration) = (a.free(1, 1, t), a.free(1, 2, t));
        assert_eq!(phi_t, a.neg(rate));
        assert_eq!(phi_tt, a.neg(acceleration));
        let (third, by_q) = (
            d.diff(&mut a, acceleration, Var::T),
            d.diff(&mut a, u, Var::Q(0)),
        );
        assert!(a.is_zero(third) && a.is_zero(by_q));
        // It depends on time: no rule may treat it as a constant.
        assert!(a.depends_on(u, Var::T) && !a.is_invariant(u));
        // Along the motion: d/dt (x u) = ẋ u + x u̇, evaluated with the state by hand.
        let xu = a.mul(x, u);
        let rate_of_xu = d.time_derivative(&mut a, xu);
        let env = Env {
            q: vec![2.0],
            qd: vec![-0.5],
            qdd: vec![],
            t: 0.1,
            params: vec![],
            free: vec![[f64::NAN; 3], [0.3, 1.7, -4.0]],
        };
        let exact = -0.5 * 0.3 + 2.0 * 1.7;
        assert!((eval(&a, rate_of_xu, &env) - exact).abs() < 1e-15);
        assert_eq!(eval(&a, phi_tt, &env), 4.0);
    }
}
