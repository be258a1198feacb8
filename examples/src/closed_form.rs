//! Closed-form kinematics of the example mechanisms: the exact reference that accuracy tests compare solvers against.
//!
//! Coordinates are Cartesian body coordinates `(x, y, θ)` per body, in the body order stated for each
//! mechanism; units are mm, rad and s. The rotation is `A(θ) = [[cos θ, −sin θ], [sin θ, cos θ]]`, so a
//! body-fixed point `s` of body `i` is at `r_i + A(θ_i) s`.
//!
//! Each position function is written once, generic over [`DualNum`], and evaluated with second-order
//! dual numbers ([`Dual2_64`]). That yields `q`, `q̇` and `q̈` in one pass and *exactly* (to round-off),
//! with no finite-difference truncation error and no hand-derived formulas that could drift from the
//! position formula.

use num_dual::{Dual2_64, DualNum, second_derivative};

/// Exact positions, velocities and accelerations of a mechanism at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kinematics<const N: usize> {
    /// Time the state was evaluated at, s.
    pub t: f64,
    /// Generalised coordinates `q` (mm and rad).
    pub q: [f64; N],
    /// Velocities `q̇` (mm/s and rad/s).
    pub qd: [f64; N],
    /// Accelerations `q̈` (mm/s² and rad/s²).
    pub qdd: [f64; N],
}

/// Evaluates a position function generic over dual numbers at `t` with a second-order dual number,
/// splitting the result into `q`, `q̇`, `q̈`.
pub fn differentiate<const N: usize>(
    f: impl Fn(Dual2_64) -> [Dual2_64; N],
    t: f64,
) -> Kinematics<N> {
    let parts: [(f64, f64, f64); N] = second_derivative(f, t);
    Kinematics {
        t,
        q: parts.map(|p| p.0),
        qd: parts.map(|p| p.1),
        qdd: parts.map(|p| p.2),
    }
}

/// Coordinate names of the seed piston-crank, in vector order (bodies liner, piston, rod, crank, bearing).
pub const PISTON_CRANK_COORDS: &[&str] = &[
    "liner.x",
    "liner.y",
    "liner.theta",
    "piston.x",
    "piston.y",
    "piston.theta",
    "rod.x",
    "rod.y",
    "rod.theta",
    "crank.x",
    "crank.y",
    "crank.theta",
    "bearing.x",
    "bearing.y",
    "bearing.theta",
];

/// Geometry and drive of the seed piston-crank (one cylinder of a boxer engine).
///
/// Bodies, in coordinate order: liner (ground, pose `(liner_x, 0, 0)`), piston, rod, crank, bearing
/// (ground, pose `(0, 0, 0)`). Joints:
/// - crank pin: revolute rod@`(rod_crank_pin, 0)` – crank@`(0, crank_radius)`;
/// - piston pin: revolute piston@`(−piston_pin, 0)` – rod@`(0, rod_piston_pin)`;
/// - main bearing: revolute crank@`(0, 0)` – bearing@`(0, 0)`;
/// - prismatic liner–piston along the liner's x axis through both reference points, no relative rotation;
/// - driver `θ_crank = ω t`.
///
/// Every length is multiplied by [`scale`](Self::scale), so the same mechanism can be exercised at
/// very small or very large length scales without changing its shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PistonCrank {
    /// Crank radius (distance main bearing → crank pin), mm. Seed: 43.
    pub crank_radius: f64,
    /// x offset of the crank pin in rod coordinates, mm. Seed: 41.3.
    pub rod_crank_pin: f64,
    /// y offset of the piston pin in rod coordinates, mm. Seed: 102.6.
    pub rod_piston_pin: f64,
    /// Distance from the piston reference point back (−x) to the piston pin, mm. Seed: 28.
    pub piston_pin: f64,
    /// x position of the (grounded) liner, mm. Seed: 156.8.
    pub liner_x: f64,
    /// Crank angular velocity ω, rad/s. Seed: 314.
    pub omega: f64,
    /// Uniform factor applied to every length above. Seed: 1.
    pub scale: f64,
}

impl Default for PistonCrank {
    /// The seed geometry: crank 43, rod pin offsets 41.3 and 102.6, piston pin 28, liner at 156.8,
    /// ω = 314 rad/s, scale 1.
    fn default() -> Self {
        Self {
            crank_radius: 43.0,
            rod_crank_pin: 41.3,
            rod_piston_pin: 102.6,
            piston_pin: 28.0,
            liner_x: 156.8,
            omega: 314.0,
            scale: 1.0,
        }
    }
}

impl PistonCrank {
    /// Number of coordinates (5 bodies × 3).
    pub const N: usize = 15;

    /// Coordinate names in vector order, e.g. `"piston.x"`, `"rod.theta"`.
    pub fn coordinate_names(&self) -> &'static [&'static str] {
        PISTON_CRANK_COORDS
    }

    /// Positions `q(t)` for any dual-number type (or plain `f64`).
    ///
    /// Branch: the piston pin lies on the +X side of the crank pin (the assembled seed configuration).
    pub fn positions_generic<D: DualNum<Primitive = f64> + Copy>(&self, t: D) -> [D; 15] {
        self.positions_at_angle(t * self.omega)
    }

    /// Positions with the crank at angle `th_d` (any drive law: pass `θ(t)` as a dual number).
    pub fn positions_at_angle<D: DualNum<Primitive = f64> + Copy>(&self, th_d: D) -> [D; 15] {
        let s = self.scale;
        let r = self.crank_radius * s;
        let e = self.rod_crank_pin * s; // rod: crank pin at (e, 0)
        let h = self.rod_piston_pin * s; // rod: piston pin at (0, h)
        let p = self.piston_pin * s;
        let zero = D::from(0.0);

        let (sin_d, cos_d) = th_d.sin_cos();
        // Crank pin: crank@(0, r) rotated by the crank angle about the bearing at the origin.
        let px = sin_d * (-r);
        let py = cos_d * r;
        // Piston pin on the x axis at the rod's pin distance L from the crank pin, +X branch.
        let l2 = e * e + h * h;
        let qx = px + (-(py * py) + l2).sqrt();
        let qy = zero;
        // Rod angle: Q − P = A(θ_C)·(−e, h), so θ_C = angle(Q − P) − angle((−e, h)).
        let th_c = (qy - py).atan2(qx - px) - h.atan2(-e);
        let (sin_c, cos_c) = th_c.sin_cos();
        // Rod reference point: r_C = P − A(θ_C)·(e, 0).
        let xc = px - cos_c * e;
        let yc = py - sin_c * e;
        // Piston reference point: the pin is at piston@(−p, 0) and the piston does not rotate.
        let xb = qx + p;

        [
            D::from(self.liner_x * s),
            zero,
            zero,
            xb,
            zero,
            zero,
            xc,
            yc,
            th_c,
            zero,
            zero,
            th_d,
            zero,
            zero,
            zero,
        ]
    }

    /// Exact `q(t)`.
    pub fn q(&self, t: f64) -> [f64; 15] {
        self.positions_generic(t)
    }

    /// Exact `q`, `q̇`, `q̈` at time `t` (one second-order dual evaluation).
    pub fn kinematics(&self, t: f64) -> Kinematics<15> {
        differentiate(|t| self.positions_generic(t), t)
    }

    /// Exact `q̇(t)`.
    pub fn qd(&self, t: f64) -> [f64; 15] {
        self.kinematics(t).qd
    }

    /// Exact `q̈(t)`.
    pub fn qdd(&self, t: f64) -> [f64; 15] {
        self.kinematics(t).qdd
    }

    /// Time of one crank revolution, `2π/ω`, s.
    pub fn period(&self) -> f64 {
        core::f64::consts::TAU / self.omega
    }
}

/// An in-line slider-crank with its reference points at the joints, for toggle-position tests.
///
/// Bodies, in coordinate order: frame (ground at the origin), crank (reference point at the
/// pivot), rod (reference point at the crank pin, slider pin at rod@`(l, 0)`), slider (on the
/// frame's x axis, not rotating). Driver `θ_crank = ω t`. Branch: the slider ahead of the crank
/// pin, `x_slider > x_pin`. With `l > r` the crank turns fully; with `l = r` the rod folds onto
/// the crank at `θ = π/2` (a toggle position, where Φ_q is singular).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SliderCrank {
    /// Crank radius r.
    pub crank: f64,
    /// Rod length l.
    pub rod: f64,
    /// Crank speed ω, rad/s.
    pub omega: f64,
}

impl SliderCrank {
    /// Positions with the crank at angle `theta`.
    pub fn positions_at_angle<D: DualNum<Primitive = f64> + Copy>(&self, theta: D) -> [D; 12] {
        let (r, l) = (self.crank, self.rod);
        let zero = D::from(0.0);
        let (sin, cos) = theta.sin_cos();
        let (px, py) = (cos * r, sin * r);
        // l² − (r sin θ)² written as (l − r sin θ)(l + r sin θ): no cancellation near the toggle.
        let reach = ((-(py) + l) * (py + l)).sqrt();
        let x = px + reach;
        let phi = (-py).atan2(reach);
        [
            zero, zero, zero, zero, zero, theta, px, py, phi, x, zero, zero,
        ]
    }

    /// Exact `q`, `q̇`, `q̈` at time `t`.
    pub fn kinematics(&self, t: f64) -> Kinematics<12> {
        differentiate(|t| self.positions_at_angle(t * self.omega), t)
    }

    /// Time of one crank revolution, `2π/ω`.
    pub fn period(&self) -> f64 {
        core::f64::consts::TAU / self.omega
    }
}

/// The offset slider-crank of `scenes::OffsetSlider`, posed by its crank angle (positions only).
///
/// Bodies, in coordinate order: frame (ground at the origin), crank (reference point at the
/// pivot), rod (reference point at the crank pin, slider pin at rod@`(rod, 0)`), slider (on the
/// line `y = offset`, not rotating). Branch: the slider ahead of the crank pin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OffsetSlider {
    /// Crank radius (mm). Scene: 30.
    pub crank: f64,
    /// Rod length (mm). Scene: 80.
    pub rod: f64,
    /// Height of the slider's line above the crank pivot (mm). Scene: 12.
    pub offset: f64,
}

impl Default for OffsetSlider {
    fn default() -> Self {
        Self {
            crank: 30.0,
            rod: 80.0,
            offset: 12.0,
        }
    }
}

impl OffsetSlider {
    /// Positions with the crank at angle `theta`.
    pub fn q(&self, theta: f64) -> [f64; 12] {
        let (sin, cos) = theta.sin_cos();
        let (px, py) = (self.crank * cos, self.crank * sin);
        // The rod spans the height from the pin to the slider's line.
        let rise = self.offset - py;
        let reach = ((self.rod - rise) * (self.rod + rise)).sqrt();
        let phi = rise.atan2(reach);
        [
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            theta,
            px,
            py,
            phi,
            px + reach,
            self.offset,
            0.0,
        ]
    }
}

/// Coordinate names of the crank-rocker four-bar, in vector order (bodies frame, crank, coupler, rocker).
pub const FOUR_BAR_COORDS: &[&str] = &[
    "frame.x",
    "frame.y",
    "frame.theta",
    "crank.x",
    "crank.y",
    "crank.theta",
    "coupler.x",
    "coupler.y",
    "coupler.theta",
    "rocker.x",
    "rocker.y",
    "rocker.theta",
];

/// Geometry and drive of a crank-rocker four-bar.
///
/// Bodies, in coordinate order: frame (ground, pose `(0, 0, 0)`), crank, coupler, rocker. Joints:
/// - revolute frame@`(0, 0)` – crank@`(0, 0)`;
/// - revolute crank@`(a, 0)` – coupler@`(0, 0)` (pin A);
/// - revolute coupler@`(b, 0)` – rocker@`(c, 0)` (pin B);
/// - revolute rocker@`(0, 0)` – frame@`(d, 0)` (pivot O4);
/// - driver `θ_crank = ω t`.
///
/// Assembly branch: B lies to the **left** of the directed line from A to O4,
/// `cross(O4 − A, B − A) > 0` (at `θ2 = 0`, `B ≈ (136.67, 71.10)`, i.e. `B_y > 0`).
///
/// Angle representation: the crank angle `θ2 = ω t` is not wrapped. The coupler and rocker angles are
/// the `atan2` values. For the default geometry no wrap jump can occur: the rocker swings within
/// about [54.9°, 128.7°] (the two crank–coupler collinear positions), so `B_y ≥ 80·sin 54.9° ≈ 65.5`
/// while `A_y ≤ 40`, hence `B − A` always points into the upper half plane and `θ3 ∈ (0, π)`. The
/// tests check this over a revolution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FourBar {
    /// Crank length a (O2 → A), mm. Default: 40.
    pub crank: f64,
    /// Coupler length b (A → B), mm. Default: 120.
    pub coupler: f64,
    /// Rocker length c (O4 → B), mm. Default: 80.
    pub rocker: f64,
    /// Ground length d (O2 → O4), mm. Default: 100.
    pub ground: f64,
    /// Crank angular velocity ω, rad/s. Default: 10.
    pub omega: f64,
}

impl Default for FourBar {
    /// Grashof crank-rocker: a = 40, b = 120, c = 80, d = 100, ω = 10 rad/s.
    fn default() -> Self {
        Self {
            crank: 40.0,
            coupler: 120.0,
            rocker: 80.0,
            ground: 100.0,
            omega: 10.0,
        }
    }
}

impl FourBar {
    /// Number of coordinates (4 bodies × 3).
    pub const N: usize = 12;

    /// Coordinate names in vector order, e.g. `"coupler.theta"`.
    pub fn coordinate_names(&self) -> &'static [&'static str] {
        FOUR_BAR_COORDS
    }

    /// Position of the coupler–rocker pin B at time `t` (on the documented branch), for any dual type.
    pub fn pin_b_generic<D: DualNum<Primitive = f64> + Copy>(&self, t: D) -> (D, D) {
        let (a, b, c, d) = (self.crank, self.coupler, self.rocker, self.ground);
        let (sin2, cos2) = (t * self.omega).sin_cos();
        let (ax, ay) = (cos2 * a, sin2 * a);
        // e = O4 − A; |e| ≥ d − a > 0 on a crank-rocker, so the divisions below are safe.
        let (ex, ey) = (-ax + d, -ay);
        let e2 = ex * ex + ey * ey;
        // Circle–circle intersection: B = A + k·e + m·perp(e), with perp(e) = (−e_y, e_x) (left of e).
        // k = (b² − c² + |e|²) / (2|e|²) places the foot on line A→O4; m = h/|e| with h² = b² − k²|e|².
        let k = (e2 + (b * b - c * c)) / (e2 * 2.0);
        let m = (-(k * k) + (e2.recip() * (b * b))).sqrt();
        (ax + ex * k - ey * m, ay + ey * k + ex * m)
    }

    /// Positions `q(t)` for any dual-number type (or plain `f64`).
    pub fn positions_generic<D: DualNum<Primitive = f64> + Copy>(&self, t: D) -> [D; 12] {
        let zero = D::from(0.0);
        let th2 = t * self.omega;
        let (sin2, cos2) = th2.sin_cos();
        let (ax, ay) = (cos2 * self.crank, sin2 * self.crank);
        let (bx, by) = self.pin_b_generic(t);
        let th3 = angle_of(by - ay, bx - ax);
        let th4 = angle_of(by, bx - self.ground);
        [
            zero,
            zero,
            zero,
            zero,
            zero,
            th2,
            ax,
            ay,
            th3,
            D::from(self.ground),
            zero,
            th4,
        ]
    }

    /// Exact `q(t)`.
    pub fn q(&self, t: f64) -> [f64; 12] {
        self.positions_generic(t)
    }

    /// Exact `q`, `q̇`, `q̈` at time `t` (one second-order dual evaluation).
    pub fn kinematics(&self, t: f64) -> Kinematics<12> {
        differentiate(|t| self.positions_generic(t), t)
    }

    /// Exact `q̇(t)`.
    pub fn qd(&self, t: f64) -> [f64; 12] {
        self.kinematics(t).qd
    }

    /// Exact `q̈(t)`.
    pub fn qdd(&self, t: f64) -> [f64; 12] {
        self.kinematics(t).qdd
    }

    /// Time of one crank revolution, `2π/ω`, s.
    pub fn period(&self) -> f64 {
        core::f64::consts::TAU / self.omega
    }
}

/// Exact `q`, `q̇`, `q̈` of the seed piston-crank ([`PistonCrank::default`]) at time `t`.
pub fn seed_piston_crank(t: f64) -> Kinematics<15> {
    PistonCrank::default().kinematics(t)
}

/// Exact `q`, `q̇`, `q̈` of the default crank-rocker four-bar ([`FourBar::default`]) at time `t`.
pub fn four_bar(t: f64) -> Kinematics<12> {
    FourBar::default().kinematics(t)
}

/// `atan2(y, x)` for dual numbers, exact in its derivatives everywhere: num-dual's `atan2`
/// divides by `x` and loses its derivatives where `x` crosses zero (a rocker standing
/// vertical), so there the angle is measured from the y axis instead.
fn angle_of<D: DualNum<Primitive = f64> + Copy>(y: D, x: D) -> D {
    if x.re().abs() >= y.re().abs() {
        y.atan2(x)
    } else {
        let turned = (-x).atan2(y) + core::f64::consts::FRAC_PI_2;
        if turned.re() > core::f64::consts::PI {
            turned - core::f64::consts::TAU
        } else {
            turned
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SEED_CSV: &str = include_str!("../../tests/data/seed_reference.csv");

    /// Parses the reference table: rows of `t, q[15], qd[15], qdd[15]`.
    fn seed_rows() -> Vec<Kinematics<15>> {
        let mut lines = SEED_CSV.lines();
        let header = lines.next().expect("header");
        assert_eq!(header.split(',').count(), 46);
        lines
            .filter(|l| !l.trim().is_empty())
            .map(|l| {
                let v: Vec<f64> = l
                    .split(',')
                    .map(|x| x.trim().parse::<f64>().expect("number"))
                    .collect();
                assert_eq!(v.len(), 46, "row width");
                let block = |k: usize| -> [f64; 15] { core::array::from_fn(|i| v[1 + 15 * k + i]) };
                Kinematics {
                    t: v[0],
                    q: block(0),
                    qd: block(1),
                    qdd: block(2),
                }
            })
            .collect()
    }

    /// Max over rows and coordinates of |computed − reference| / (largest |reference| of that column),
    /// for q, q̇, q̈ separately. Columns that are identically zero in the table must be exactly zero.
    /// Also returns the error relative to the largest magnitude of the whole block.
    fn seed_errors() -> ([f64; 3], [f64; 3]) {
        let rows = seed_rows();
        assert_eq!(rows.len(), 1000);
        let pc = PistonCrank::default();
        let mut col_max = [[0.0f64; 15]; 3];
        for row in &rows {
            for (k, blk) in [&row.q, &row.qd, &row.qdd].into_iter().enumerate() {
                for i in 0..15 {
                    col_max[k][i] = col_max[k][i].max(blk[i].abs());
                }
            }
        }
        let blk_max = col_max.map(|c| c.iter().copied().fold(0.0, f64::max));
        let mut per_col = [0.0f64; 3];
        let mut per_blk = [0.0f64; 3];
        for row in &rows {
            let t = row.t;
            let kin = pc.kinematics(t);
            for (k, (got, want)) in [(&kin.q, &row.q), (&kin.qd, &row.qd), (&kin.qdd, &row.qdd)]
                .into_iter()
                .enumerate()
            {
                for i in 0..15 {
                    let err = (got[i] - want[i]).abs();
                    if col_max[k][i] == 0.0 {
                        assert_eq!(got[i], 0.0, "t={t} block {k} coord {i} must be 0");
                    } else {
                        per_col[k] = per_col[k].max(err / col_max[k][i]);
                    }
                    per_blk[k] = per_blk[k].max(err / blk_max[k]);
                }
            }
        }
        (per_col, per_blk)
    }

    #[test]
    fn seed_matches_reference_table() {
        let (per_col, per_blk) = seed_errors();
        eprintln!("seed vs reference, per-column relative max error (q, qd, qdd): {per_col:?}");
        eprintln!("seed vs reference, per-block relative max error (q, qd, qdd): {per_blk:?}");
        for (k, err) in per_col.iter().enumerate() {
            assert!(*err <= 1e-13, "block {k}: {err}");
        }
    }

    #[test]
    fn seed_initial_state_is_the_assembled_configuration() {
        let k = seed_piston_crank(0.0);
        // Crank pin straight up at (0, 43); piston pin at sqrt(L² − 43²) on the x axis.
        let l2: f64 = 41.3 * 41.3 + 102.6 * 102.6;
        let qx = (l2 - 43.0 * 43.0).sqrt();
        assert!((k.q[3] - (qx + 28.0)).abs() < 1e-12);
        assert_eq!(k.qd[11], 314.0);
        assert_eq!(k.qdd[11], 0.0);
        assert_eq!(k.q[0], 156.8);
        assert_eq!(PistonCrank::default().coordinate_names()[8], "rod.theta");
        assert_eq!(PISTON_CRANK_COORDS.len(), PistonCrank::N);
    }

    /// Revolute pairs and the prismatic of the seed hold along the motion (geometry self-check).
    #[test]
    fn seed_constraints_hold() {
        let pc = PistonCrank::default();
        let rot = |th: f64, (x, y): (f64, f64)| {
            (th.cos() * x - th.sin() * y, th.sin() * x + th.cos() * y)
        };
        for i in 0..200 {
            let t = pc.period() * i as f64 / 200.0;
            let q = pc.q(t);
            let pt = |b: usize, s: (f64, f64)| {
                let (dx, dy) = rot(q[3 * b + 2], s);
                (q[3 * b] + dx, q[3 * b + 1] + dy)
            };
            let pairs = [
                (pt(2, (41.3, 0.0)), pt(3, (0.0, 43.0))),
                (pt(1, (-28.0, 0.0)), pt(2, (0.0, 102.6))),
                (pt(3, (0.0, 0.0)), pt(4, (0.0, 0.0))),
            ];
            for (a, b) in pairs {
                assert!(
                    (a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12,
                    "t={t}"
                );
            }
            assert!(q[4].abs() < 1e-12 && q[5] == 0.0);
        }
    }

    #[test]
    fn scaled_seed_is_the_seed_scaled() {
        let base = PistonCrank::default();
        for scale in [1e-3, 1e-6, 1e4] {
            let scaled = PistonCrank { scale, ..base };
            for i in 0..100 {
                let t = base.period() * i as f64 / 100.0;
                let (a, b) = (base.kinematics(t), scaled.kinematics(t));
                let pairs = [(&a.q, &b.q), (&a.qd, &b.qd), (&a.qdd, &b.qdd)];
                for (want, got) in pairs {
                    let m = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                    for i in 0..15 {
                        // Angles (θ components) do not scale; lengths do.
                        let f = if i % 3 == 2 { 1.0 } else { scale };
                        let err = (got[i] / f - want[i]).abs() / m;
                        assert!(err < 1e-13, "scale {scale} t {t} coord {i}: {err}");
                    }
                }
            }
        }
    }

    /// Raising ω only rescales time: q(t·ω₁/ω₂) is unchanged, q̇ scales by ω₂/ω₁ and q̈ by (ω₂/ω₁)².
    #[test]
    fn fast_seed_is_the_seed_in_rescaled_time() {
        let base = PistonCrank::default();
        for omega in [1e5, 1.0] {
            let fast = PistonCrank { omega, ..base };
            let r = omega / base.omega;
            for i in 0..100 {
                let t = base.period() * (i as f64 + 0.5) / 100.0;
                let (a, b) = (base.kinematics(t), fast.kinematics(t / r));
                for (k, (want, got, f)) in [
                    (&a.q, &b.q, 1.0),
                    (&a.qd, &b.qd, r),
                    (&a.qdd, &b.qdd, r * r),
                ]
                .into_iter()
                .enumerate()
                {
                    let m = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                    for i in 0..15 {
                        let err = (got[i] / f - want[i]).abs() / m;
                        assert!(err < 1e-13, "ω {omega} t {t} block {k} coord {i}: {err}");
                    }
                }
            }
        }
    }

    /// Central differences (step h) of a function of time.
    fn central<const N: usize>(f: impl Fn(f64) -> [f64; N], t: f64, h: f64) -> [f64; N] {
        let (p, m) = (f(t + h), f(t - h));
        core::array::from_fn(|i| (p[i] - m[i]) / (2.0 * h))
    }

    fn rel_err<const N: usize>(got: &[f64; N], want: &[f64; N]) -> f64 {
        let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
        got.iter()
            .zip(want)
            .fold(0.0f64, |m, (g, w)| m.max((g - w).abs() / scale))
    }

    #[test]
    fn seed_derivatives_match_finite_differences() {
        let pc = PistonCrank::default();
        let h = pc.period() * 1e-6;
        for i in 0..50 {
            let t = pc.period() * (i as f64 + 0.3) / 50.0;
            let k = pc.kinematics(t);
            assert!(rel_err(&central(|t| pc.q(t), t, h), &k.qd) < 1e-6);
            assert!(rel_err(&central(|t| pc.qd(t), t, h), &k.qdd) < 1e-6);
        }
    }

    #[test]
    fn four_bar_constraints_hold_and_branch_is_left() {
        let fb = FourBar::default();
        let (a, b, c, d) = (fb.crank, fb.coupler, fb.rocker, fb.ground);
        let rot = |th: f64, (x, y): (f64, f64)| {
            (th.cos() * x - th.sin() * y, th.sin() * x + th.cos() * y)
        };
        let n = 2000;
        let mut prev: Option<[f64; 12]> = None;
        for i in 0..=n {
            let t = fb.period() * i as f64 / n as f64;
            let q = fb.q(t);
            let pt = |body: usize, s: (f64, f64)| {
                let (dx, dy) = rot(q[3 * body + 2], s);
                (q[3 * body] + dx, q[3 * body + 1] + dy)
            };
            let pairs = [
                (pt(0, (0.0, 0.0)), pt(1, (0.0, 0.0))),
                (pt(1, (a, 0.0)), pt(2, (0.0, 0.0))),
                (pt(2, (b, 0.0)), pt(3, (c, 0.0))),
                (pt(3, (0.0, 0.0)), pt(0, (d, 0.0))),
            ];
            for (p1, p2) in pairs {
                assert!(
                    (p1.0 - p2.0).abs() < 1e-12 && (p1.1 - p2.1).abs() < 1e-12,
                    "t={t}"
                );
            }
            // Driver.
            assert!((q[5] - fb.omega * t).abs() < 1e-15 * (1.0 + q[5].abs()));
            // Branch: B left of the directed line A → O4.
            let (pa, pb) = (pt(1, (a, 0.0)), pt(2, (b, 0.0)));
            let cross = (d - pa.0) * (pb.1 - pa.1) - (0.0 - pa.1) * (pb.0 - pa.0);
            assert!(cross > 0.0, "t={t}: B on wrong branch");
            // Documented angle ranges (no atan2 wrap): θ3 ∈ (0, π), θ4 ∈ [54.9°, 128.7°].
            assert!(
                q[8] > 0.0 && q[8] < core::f64::consts::PI,
                "t={t}: θ3 = {}",
                q[8]
            );
            let th4 = q[11].to_degrees();
            assert!((54.8..=128.8).contains(&th4), "t={t}: θ4 = {th4}°");
            // Continuity: no jump between neighbouring samples.
            if let Some(p) = prev {
                for j in [8, 11] {
                    assert!((q[j] - p[j]).abs() < 0.05, "t={t}: jump in coordinate {j}");
                }
            }
            prev = Some(q);
        }
        // The documented initial pin position.
        let (bx, by): (f64, f64) = fb.pin_b_generic(0.0);
        assert!((bx - 136.6666666666667).abs() < 1e-9 && (by - 71.10243002567).abs() < 1e-9);
    }

    #[test]
    fn four_bar_velocity_constraints_hold() {
        // d/dt of each revolute pair: ṙ_i + Ȧ(θ_i) s_i θ̇_i equal for both bodies.
        let fb = FourBar::default();
        let (a, b, c, d) = (fb.crank, fb.coupler, fb.rocker, fb.ground);
        for i in 0..100 {
            let t = fb.period() * (i as f64 + 0.5) / 100.0;
            let k = fb.kinematics(t);
            let vel = |body: usize, (sx, sy): (f64, f64)| {
                let (th, w) = (k.q[3 * body + 2], k.qd[3 * body + 2]);
                (
                    k.qd[3 * body] - w * (th.sin() * sx + th.cos() * sy),
                    k.qd[3 * body + 1] + w * (th.cos() * sx - th.sin() * sy),
                )
            };
            let pairs = [
                (vel(0, (0.0, 0.0)), vel(1, (0.0, 0.0))),
                (vel(1, (a, 0.0)), vel(2, (0.0, 0.0))),
                (vel(2, (b, 0.0)), vel(3, (c, 0.0))),
                (vel(3, (0.0, 0.0)), vel(0, (d, 0.0))),
            ];
            for (v1, v2) in pairs {
                assert!(
                    (v1.0 - v2.0).abs() < 1e-10 && (v1.1 - v2.1).abs() < 1e-10,
                    "t={t}"
                );
            }
            assert_eq!(k.qd[5], fb.omega);
        }
    }

    #[test]
    fn four_bar_derivatives_match_finite_differences() {
        let fb = FourBar::default();
        let h = fb.period() * 1e-6;
        let mut worst = [0.0f64; 2];
        for i in 0..100 {
            let t = fb.period() * (i as f64 + 0.3) / 100.0;
            let k = four_bar(t);
            worst[0] = worst[0].max(rel_err(&central(|t| fb.q(t), t, h), &k.qd));
            worst[1] = worst[1].max(rel_err(&central(|t| fb.qd(t), t, h), &k.qdd));
        }
        assert!(worst[0] < 1e-6 && worst[1] < 1e-6, "{worst:?}");
        assert_eq!(FOUR_BAR_COORDS.len(), FourBar::N);
    }
}
