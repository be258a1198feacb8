//! Closed-form groups: the Newton blocks whose loop closes by an intersection the generator can
//! write out, found once per scene from the block's own equations.
//!
//! A planar linkage's loops are almost always chains of dyads (Assur groups of class II); once
//! the structure stage has assigned everything explicit, such a dyad is a block of one or two
//! equations that are *affine* in the cosines and sines of its angles and in its lengths, with
//! coefficients that earlier stages, parameters and time already know. This module recognises
//! that form symbolically, whatever joints produced it, and writes the block's solutions:
//!
//! - [`ClosedKind::CircleLine`]: one angle θ with `a cos θ + b sin θ + c = 0` (a lever whose
//!   pin runs on a line: the offset slider-crank's rod), possibly after eliminating one length
//!   that enters both equations linearly (the seed's rod: its height and angle);
//! - [`ClosedKind::CircleCircle`]: two angles whose two rows are a revolute's, `A₁u₁ + A₂u₂ +
//!   c = 0` with `uₖ = (cos θₖ, sin θₖ)` and each `Aₖ` a scaled rotation or reflection (so
//!   `|A₂u₂| = r₂` eliminates θ₂): the RRR dyad of a four-bar;
//! - [`ClosedKind::Linear`]: one length with a known coefficient.
//!
//! The roots are the intersection of the unit circle with the line `a x + b y + c = 0`:
//! `(x, y)± = (−c (a, b) ± √(a² + b² − c²) (−b, a)) / (a² + b²)`: no trigonometry of the
//! unknowns, one square root per group. Each angle is written as its unit vector
//! `(cos θ, sin θ)`: the runtime takes `atan2` of the one it keeps, and the straight step fills
//! the trig cache with it in place of a `sin_cos`. A negative discriminant (the loop cannot
//! close) makes both candidates NaN. The runtime starts the block's Newton
//! iteration from the candidate nearest its guess and Newton verifies it (one evaluation, which
//! the rates need anyway), so the closed form never lowers accuracy: near a toggle, where the
//! root is ill-conditioned, Newton refines it; where there is none, Newton runs as before.

use std::collections::HashMap;

use crate::expr::{Arena, Func, Id, Node, Var};

/// What kind of closed form a block has (named in `mechgen check --stats`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ClosedKind {
    /// One angle on a circle meeting a line (after eliminating a length, if the block has one).
    CircleLine,
    /// Two angles: the intersection of two circles.
    CircleCircle,
    /// One length with a known coefficient.
    Linear,
}

impl ClosedKind {
    /// The kind's name in tables and documentation.
    pub fn name(self) -> &'static str {
        match self {
            ClosedKind::CircleLine => "circle–line",
            ClosedKind::CircleCircle => "circle–circle",
            ClosedKind::Linear => "linear",
        }
    }
}

/// A block's closed-form solution.
#[derive(Debug, Clone)]
pub struct ClosedForm {
    /// Which intersection it is.
    pub kind: ClosedKind,
    /// Two candidate solutions of the block's coordinates (in the block's column order),
    /// candidate-major, two entries per coordinate: a length's value and 0, or an angle's
    /// cosine and sine (`[c₀ of the first (2), c₁ of the first (2), c₀ of the second, …]`). A
    /// group with one solution lists it twice.
    pub candidates: Vec<Id>,
}

/// The closed form of the block solving `coordinates` from `residuals`, if it is one of the
/// [`ClosedKind`]s.
pub fn recognize(arena: &mut Arena, coordinates: &[usize], residuals: &[Id]) -> Option<ClosedForm> {
    let n = coordinates.len();
    if n == 0 || n > 2 || residuals.len() != n {
        return None;
    }
    let mut split = Split {
        arena,
        unknowns: coordinates,
        memo: HashMap::new(),
    };
    let forms = residuals
        .iter()
        .map(|&r| split.affine(r))
        .collect::<Option<Vec<Affine>>>()?;
    let roles = roles(arena, &forms, n)?;
    let (kind, candidates) = match roles[..] {
        [Role::Angle] => (ClosedKind::CircleLine, one_angle(arena, &forms[0], 0)),
        [Role::Length] => (ClosedKind::Linear, one_length(arena, &forms[0], 0)?),
        [Role::Length, Role::Angle] => (ClosedKind::CircleLine, dyad(arena, &forms, 0, 1)?),
        [Role::Angle, Role::Length] => (ClosedKind::CircleLine, dyad(arena, &forms, 1, 0)?),
        [Role::Angle, Role::Angle] => (ClosedKind::CircleCircle, two_angles(arena, &forms)?),
        _ => return None,
    };
    Some(ClosedForm { kind, candidates })
}

/// An equation as `Σ coefficients · atoms + constant`; the atoms of unknown `j` are
/// `q_j`, `cos q_j` and `sin q_j` (indices `3j`, `3j + 1`, `3j + 2`).
#[derive(Debug, Clone)]
struct Affine {
    terms: Vec<Id>,
    constant: Id,
}

const LINEAR: usize = 0;
const COS: usize = 1;
const SIN: usize = 2;

impl Affine {
    fn known(arena: &Arena, n: usize, value: Id) -> Self {
        Affine {
            terms: vec![arena.zero(); 3 * n],
            constant: value,
        }
    }

    fn coefficient(&self, unknown: usize, atom: usize) -> Id {
        self.terms[3 * unknown + atom]
    }

    /// Applies `f` to every coefficient and the constant.
    fn map(&self, arena: &mut Arena, f: impl Fn(&mut Arena, Id) -> Id) -> Self {
        Affine {
            terms: self.terms.iter().map(|&t| f(arena, t)).collect(),
            constant: f(arena, self.constant),
        }
    }

    /// `self ± other`, term by term.
    fn combine(&self, arena: &mut Arena, other: &Affine, subtract: bool) -> Self {
        let op = |arena: &mut Arena, a: Id, b: Id| {
            if subtract {
                arena.sub(a, b)
            } else {
                arena.add(a, b)
            }
        };
        Affine {
            terms: (self.terms.iter().zip(&other.terms))
                .map(|(&a, &b)| op(arena, a, b))
                .collect(),
            constant: op(arena, self.constant, other.constant),
        }
    }
}

/// Splits expressions into [`Affine`] forms over a block's unknowns.
struct Split<'a> {
    arena: &'a mut Arena,
    unknowns: &'a [usize],
    memo: HashMap<Id, Option<Affine>>,
}

impl Split<'_> {
    fn unknown(&self, id: Id) -> Option<usize> {
        match self.arena.node(id) {
            Node::Var(Var::Q(c)) => self.unknowns.iter().position(|&u| u == c as usize),
            _ => None,
        }
    }

    fn reads_unknowns(&self, id: Id) -> bool {
        let unknowns = self.unknowns;
        self.arena.any_node(
            id,
            |node| matches!(node, Node::Var(Var::Q(c)) if unknowns.contains(&(c as usize))),
        )
    }

    /// `id` as an affine form, or `None` if the unknowns enter it any other way.
    fn affine(&mut self, id: Id) -> Option<Affine> {
        if let Some(done) = self.memo.get(&id) {
            return done.clone();
        }
        let form = self.split(id);
        self.memo.insert(id, form.clone());
        form
    }

    fn split(&mut self, id: Id) -> Option<Affine> {
        let n = self.unknowns.len();
        if !self.reads_unknowns(id) {
            return Some(Affine::known(self.arena, n, id));
        }
        let atom = |j: usize, which: usize, arena: &Arena| {
            let mut form = Affine::known(arena, n, arena.zero());
            form.terms[3 * j + which] = arena.one();
            form
        };
        match self.arena.node(id) {
            Node::Var(_) => Some(atom(self.unknown(id)?, LINEAR, self.arena)),
            Node::Call(Func::Cos, x) => Some(atom(self.unknown(x)?, COS, self.arena)),
            Node::Call(Func::Sin, x) => Some(atom(self.unknown(x)?, SIN, self.arena)),
            Node::Neg(a) => Some(self.affine(a)?.map(self.arena, Arena::neg)),
            Node::Add(a, b) | Node::Sub(a, b) => {
                let (a, b) = (self.affine(a)?, self.affine(b)?);
                let subtract = matches!(self.arena.node(id), Node::Sub(..));
                Some(a.combine(self.arena, &b, subtract))
            }
            Node::Mul(a, b) => {
                let (factor, form) = if self.reads_unknowns(a) {
                    (b, a)
                } else {
                    (a, b)
                };
                if self.reads_unknowns(factor) {
                    return None;
                }
                Some(
                    self.affine(form)?
                        .map(self.arena, |ar, t| ar.mul(factor, t)),
                )
            }
            Node::Div(a, b) if !self.reads_unknowns(b) => {
                Some(self.affine(a)?.map(self.arena, |ar, t| ar.div(t, b)))
            }
            _ => None,
        }
    }
}

/// How an unknown enters the block's equations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Role {
    /// Only through its cosine and sine.
    Angle,
    /// Only linearly.
    Length,
}

/// Each unknown's role, or `None` if one enters both ways (or not at all).
fn roles(arena: &Arena, forms: &[Affine], n: usize) -> Option<Vec<Role>> {
    (0..n)
        .map(|j| {
            let enters = |atom: usize| forms.iter().any(|f| !arena.is_zero(f.coefficient(j, atom)));
            match (enters(LINEAR), enters(COS) || enters(SIN)) {
                (true, false) => Some(Role::Length),
                (false, true) => Some(Role::Angle),
                _ => None,
            }
        })
        .collect()
}

/// The two points where the unit circle meets `a x + b y + c = 0`, as `[(x, y)+, (x, y)−]`.
fn circle_line(arena: &mut Arena, a: Id, b: Id, c: Id) -> [(Id, Id); 2] {
    let norm = {
        let (aa, bb) = (arena.mul(a, a), arena.mul(b, b));
        arena.add(aa, bb)
    };
    let cc = arena.mul(c, c);
    let discriminant = arena.sub(norm, cc);
    let root = arena.call(Func::Sqrt, discriminant);
    let (ca, cb) = (arena.mul(c, a), arena.mul(c, b));
    let (bs, as_) = (arena.mul(b, root), arena.mul(a, root));
    let (minus_ca, minus_cb) = (arena.neg(ca), arena.neg(cb));
    // One reciprocal for the four coordinates (a constant where the line's is): the
    // candidates lie on the intersection's critical path, and a product is a fraction of a
    // division's latency; the rounding it changes is the verification's to judge.
    let one = arena.one();
    let inverse = arena.div(one, norm);
    let point = |arena: &mut Arena, sign: bool| {
        let (x, y) = if sign {
            (arena.sub(minus_ca, bs), arena.add(minus_cb, as_))
        } else {
            (arena.add(minus_ca, bs), arena.sub(minus_cb, as_))
        };
        (arena.mul(x, inverse), arena.mul(y, inverse))
    };
    [point(arena, true), point(arena, false)]
}

/// A length's two entries in the candidates: its value and 0.
fn length(arena: &Arena, value: Id) -> [Id; 2] {
    [value, arena.zero()]
}

/// An angle's two entries in the candidates: its unit vector.
fn angle((cos, sin): (Id, Id)) -> [Id; 2] {
    [cos, sin]
}

/// Candidates of a 1×1 block `a cos θ + b sin θ + c = 0`.
fn one_angle(arena: &mut Arena, form: &Affine, j: usize) -> Vec<Id> {
    let (a, b) = (form.coefficient(j, COS), form.coefficient(j, SIN));
    circle_line(arena, a, b, form.constant)
        .into_iter()
        .flat_map(angle)
        .collect()
}

/// The candidate (listed twice) of a 1×1 block `k y + c = 0`; `None` if `k` is zero.
fn one_length(arena: &mut Arena, form: &Affine, j: usize) -> Option<Vec<Id>> {
    let k = form.coefficient(j, LINEAR);
    if arena.is_zero(k) {
        return None;
    }
    let minus_c = arena.neg(form.constant);
    let value = arena.div(minus_c, k);
    let y = length(arena, value);
    Some([y, y].concat())
}

/// Candidates of a 2×2 block in one length (unknown `l`) and one angle (unknown `a`): the
/// length is eliminated between the equations, the angle found, then the length from the
/// equation whose coefficient of it is a non-zero constant if there is one.
fn dyad(arena: &mut Arena, forms: &[Affine], l: usize, a: usize) -> Option<Vec<Id>> {
    let (k0, k1) = (
        forms[0].coefficient(l, LINEAR),
        forms[1].coefficient(l, LINEAR),
    );
    // k₁·e₀ − k₀·e₁ has no length term.
    let scaled0 = forms[0].map(arena, |ar, t| ar.mul(k1, t));
    let scaled1 = forms[1].map(arena, |ar, t| ar.mul(k0, t));
    let eliminated = scaled0.combine(arena, &scaled1, true);
    let (ea, eb) = (
        eliminated.coefficient(a, COS),
        eliminated.coefficient(a, SIN),
    );
    if arena.is_zero(ea) && arena.is_zero(eb) {
        return None;
    }
    let points = circle_line(arena, ea, eb, eliminated.constant);
    let constant_k = |k: Id| arena.as_const(k).is_some_and(|k| k != 0.0);
    let source = if constant_k(k0) || !constant_k(k1) {
        0
    } else {
        1
    };
    let form = &forms[source];
    let k = form.coefficient(l, LINEAR);
    if arena.is_zero(k) {
        return None;
    }
    let mut candidates = [[arena.zero(); 2]; 4];
    for (i, (x, y)) in points.into_iter().enumerate() {
        // k y + a_cos x + a_sin y + c = 0
        let (cos_term, sin_term) = (
            arena.mul(form.coefficient(a, COS), x),
            arena.mul(form.coefficient(a, SIN), y),
        );
        let rest = arena.add(cos_term, sin_term);
        let rest = arena.add(rest, form.constant);
        let minus_rest = arena.neg(rest);
        let value = arena.div(minus_rest, k);
        candidates[2 * i + l] = length(arena, value);
        candidates[2 * i + a] = angle((x, y));
    }
    Some(candidates.as_flattened().to_vec())
}

/// Candidates of a 2×2 block in two angles, `A₁u₁ + A₂u₂ + c = 0`: with `Aₖᵀ Aₖ = rₖ² I`,
/// `|A₁u₁ + c|² = r₂²` is `2 cᵀA₁ u₁ + |c|² + r₁² − r₂² = 0`, a circle–line equation in θ₁;
/// then `u₂ = −A₂ᵀ (A₁u₁ + c) / r₂²`.
fn two_angles(arena: &mut Arena, forms: &[Affine]) -> Option<Vec<Id>> {
    let matrix = |j: usize| {
        [
            [forms[0].coefficient(j, COS), forms[0].coefficient(j, SIN)],
            [forms[1].coefficient(j, COS), forms[1].coefficient(j, SIN)],
        ]
    };
    let (a1, a2) = (matrix(0), matrix(1));
    let (r1, r2) = (isometry(arena, a1)?, isometry(arena, a2)?);
    let c = [forms[0].constant, forms[1].constant];
    let two = arena.constant(2.0);
    let line = |arena: &mut Arena, column: usize| {
        let (x, y) = (
            arena.mul(c[0], a1[0][column]),
            arena.mul(c[1], a1[1][column]),
        );
        let dot = arena.add(x, y);
        arena.mul(two, dot)
    };
    let (a, b) = (line(arena, 0), line(arena, 1));
    let constant = {
        let (c0, c1) = (arena.mul(c[0], c[0]), arena.mul(c[1], c[1]));
        let cc = arena.add(c0, c1);
        let sum = arena.add(cc, r1);
        arena.sub(sum, r2)
    };
    let points = circle_line(arena, a, b, constant);
    let one = arena.one();
    let inverse_r2 = arena.div(one, r2);
    let mut candidates = Vec::with_capacity(8);
    for (x, y) in points {
        // w = A₁u₁ + c; u₂ = −A₂ᵀ w / r₂² (A₂ᵀA₂ = r₂² I), on the unit circle.
        let w: Vec<Id> = (0..2)
            .map(|row| {
                let (p, q) = (arena.mul(a1[row][0], x), arena.mul(a1[row][1], y));
                let pq = arena.add(p, q);
                arena.add(pq, c[row])
            })
            .collect();
        let minus_transposed = |arena: &mut Arena, column: usize| {
            let (p, q) = (
                arena.mul(a2[0][column], w[0]),
                arena.mul(a2[1][column], w[1]),
            );
            let pq = arena.add(p, q);
            arena.neg(pq)
        };
        let u2 = [0, 1].map(|column| {
            let scaled = minus_transposed(arena, column);
            arena.mul(scaled, inverse_r2)
        });
        candidates.extend(angle((x, y)));
        candidates.extend(angle((u2[0], u2[1])));
    }
    Some(candidates)
}

/// `r²` if the 2×2 matrix is `r` times a rotation (`[[p, −q], [q, p]]`) or a reflection
/// (`[[p, q], [q, −p]]`), so that `|A u| = r` on the unit circle; `None` otherwise (or if
/// it is zero).
fn isometry(arena: &mut Arena, m: [[Id; 2]; 2]) -> Option<Id> {
    let zero = |arena: &mut Arena, a: Id, b: Id, sum: bool| {
        let e = if sum {
            arena.add(a, b)
        } else {
            arena.sub(a, b)
        };
        arena.is_zero(e)
    };
    let rotation = zero(arena, m[0][0], m[1][1], false) && zero(arena, m[0][1], m[1][0], true);
    let reflection = zero(arena, m[0][0], m[1][1], true) && zero(arena, m[0][1], m[1][0], false);
    if !(rotation || reflection) {
        return None;
    }
    let (pp, qq) = (arena.mul(m[0][0], m[0][0]), arena.mul(m[1][0], m[1][0]));
    let r2 = arena.add(pp, qq);
    (!arena.is_zero(r2)).then_some(r2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::tape::{Env, eval};

    /// `value` at coordinates `q` (t = 0, no parameters).
    fn at(arena: &Arena, value: Id, q: &[f64]) -> f64 {
        let env = Env {
            q: q.to_vec(),
            ..Env::default()
        };
        eval(arena, value, &env)
    }

    /// Each candidate, put into `q` at `coordinates`, zeroes every residual; the two differ.
    fn assert_solves(arena: &Arena, form: &ClosedForm, coordinates: &[usize], residuals: &[Id]) {
        let n = coordinates.len();
        let known = [0.7, -1.3, 2.1, 0.4];
        let mut solutions = Vec::new();
        for candidate in form.candidates.chunks(2 * n) {
            let mut q = known.to_vec();
            for (&c, pair) in coordinates.iter().zip(candidate.chunks(2)) {
                let [first, second] = [pair[0], pair[1]].map(|p| at(arena, p, &known));
                // A length's second entry is the zero node; an angle's pair is on the unit circle.
                q[c] = if arena.is_zero(pair[1]) {
                    first
                } else {
                    let norm = first.hypot(second);
                    assert!((norm - 1.0).abs() < 1e-14, "unit vector of norm {norm}");
                    second.atan2(first)
                };
            }
            for &r in residuals {
                let value = at(arena, r, &q);
                assert!(value.abs() < 1e-12, "residual {value} at {q:?}");
            }
            solutions.push(q);
        }
        assert_ne!(solutions[0], solutions[1], "two distinct solutions");
    }

    fn q(arena: &mut Arena, k: u32) -> Id {
        arena.var(Var::Q(k))
    }

    /// `Σ cₖ · termₖ + c₀`.
    fn linear(arena: &mut Arena, constant: f64, terms: &[(f64, Id)]) -> Id {
        let mut sum = arena.constant(constant);
        for &(c, term) in terms {
            let c = arena.constant(c);
            let product = arena.mul(c, term);
            sum = arena.add(sum, product);
        }
        sum
    }

    #[test]
    fn a_lever_on_a_line_is_circle_line() {
        // 3 cos θ + 4 sin θ − 2 + q₂ = 0, θ = q₀, q₂ known.
        let mut arena = Arena::new();
        let theta = q(&mut arena, 0);
        let (cos, sin) = (arena.cos(theta), arena.sin(theta));
        let known = q(&mut arena, 2);
        let residual = linear(&mut arena, -2.0, &[(3.0, cos), (4.0, sin), (1.0, known)]);
        let form = recognize(&mut arena, &[0], &[residual]).expect("closed form");
        assert_eq!(form.kind, ClosedKind::CircleLine);
        assert_solves(&arena, &form, &[0], &[residual]);
    }

    #[test]
    fn a_length_and_an_angle_eliminate_the_length() {
        // y + 2 cos θ − q₂/2 = 0 and 3 y − sin θ + 0.5 = 0 (y = q₁, θ = q₀).
        let mut arena = Arena::new();
        let (theta, y, known) = (q(&mut arena, 0), q(&mut arena, 1), q(&mut arena, 2));
        let (cos, sin) = (arena.cos(theta), arena.sin(theta));
        let e0 = linear(&mut arena, 0.0, &[(1.0, y), (2.0, cos), (-0.5, known)]);
        let e1 = linear(&mut arena, 0.5, &[(3.0, y), (-1.0, sin)]);
        let form = recognize(&mut arena, &[1, 0], &[e0, e1]).expect("closed form");
        assert_eq!(form.kind, ClosedKind::CircleLine);
        assert_solves(&arena, &form, &[1, 0], &[e0, e1]);
    }

    #[test]
    fn two_angles_on_a_revolute_are_circle_circle() {
        // A coupler point (q₂, q₃) + A(θ₁)(1.5, 0.3) meets the rocker's A(θ₂)(1.2, −0.2) + (2, 0).
        let mut arena = Arena::new();
        let (t1, t2) = (q(&mut arena, 0), q(&mut arena, 1));
        let (x, y) = (q(&mut arena, 2), q(&mut arena, 3));
        let (c1, s1, c2, s2) = (arena.cos(t1), arena.sin(t1), arena.cos(t2), arena.sin(t2));
        let ex = linear(
            &mut arena,
            -2.0,
            &[(1.0, x), (1.5, c1), (-0.3, s1), (-1.2, c2), (-0.2, s2)],
        );
        let ey = linear(
            &mut arena,
            0.0,
            &[(1.0, y), (1.5, s1), (0.3, c1), (-1.2, s2), (0.2, c2)],
        );
        let form = recognize(&mut arena, &[0, 1], &[ex, ey]).expect("closed form");
        assert_eq!(form.kind, ClosedKind::CircleCircle);
        assert_solves(&arena, &form, &[0, 1], &[ex, ey]);
    }

    #[test]
    fn a_known_coefficient_solves_a_length() {
        // cos(q₂) · y + q₃ = 0: one solution, listed twice.
        let mut arena = Arena::new();
        let (y, angle, known) = (q(&mut arena, 0), q(&mut arena, 2), q(&mut arena, 3));
        let cos = arena.cos(angle);
        let product = arena.mul(cos, y);
        let residual = arena.add(product, known);
        let form = recognize(&mut arena, &[0], &[residual]).expect("closed form");
        assert_eq!(form.kind, ClosedKind::Linear);
        assert_eq!(form.candidates[..2], form.candidates[2..]);
        assert!(
            arena.is_zero(form.candidates[1]),
            "a length's second entry is 0"
        );
        let solution = at(&arena, form.candidates[0], &[0.7, -1.3, 2.1, 0.4]);
        assert!((solution * 2.1_f64.cos() + 0.4).abs() < 1e-12);
    }

    #[test]
    fn other_loops_stay_newton_blocks() {
        let mut arena = Arena::new();
        let (t1, t2, y) = (q(&mut arena, 0), q(&mut arena, 1), q(&mut arena, 2));
        let (c1, s1, c2, s2) = (arena.cos(t1), arena.sin(t1), arena.cos(t2), arena.sin(t2));
        // A product of the unknowns' functions.
        let product = arena.mul(c1, c2);
        let coupled = linear(&mut arena, 0.1, &[(1.0, product)]);
        let other = linear(&mut arena, 0.2, &[(1.0, s1), (1.0, s2)]);
        assert!(recognize(&mut arena, &[0, 1], &[coupled, other]).is_none());
        // An angle that also enters bare (θ + cos θ).
        let bare = linear(&mut arena, 0.3, &[(1.0, t1), (1.0, c1)]);
        assert!(recognize(&mut arena, &[0], &[bare]).is_none());
        // Two angles whose rows are not a rotation's (|A₂ u₂| not constant).
        let ex = linear(&mut arena, 0.5, &[(1.0, c1), (1.0, c2)]);
        let ey = linear(&mut arena, 0.5, &[(1.0, s1), (2.0, s2)]);
        assert!(recognize(&mut arena, &[0, 1], &[ex, ey]).is_none());
        // An angle inside a sum (cos(θ + 1)).
        let one = arena.constant(1.0);
        let shifted = arena.add(t1, one);
        let cos_shifted = arena.cos(shifted);
        let inside = linear(&mut arena, 0.3, &[(1.0, cos_shifted)]);
        assert!(recognize(&mut arena, &[0], &[inside]).is_none());
        // Three unknowns.
        let three = linear(&mut arena, 0.0, &[(1.0, y)]);
        assert!(recognize(&mut arena, &[0, 1, 2], &[three, three, three]).is_none());
    }
}
