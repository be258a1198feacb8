//! The seed piston-crank, the crank-rocker four-bar and the quick-return written out by hand:
//! positions, velocities and accelerations in closed form, every derivative derived on paper,
//! no dual numbers, no iteration. This is the strongest baseline a generated solver can be measured
//! against (what an engineer would write for one mechanism), and the benchmark's reference.
//!
//! The seed needs one `sin_cos` (the crank), one `sqrt` (the piston pin on its line) and one
//! `atan2` (the rod's angle, the only angle that is an output, from its sine and cosine, which
//! come from the pin positions). The four-bar needs one `sin_cos`, one `sqrt` (the circle–circle
//! intersection) and two `atan2`s; its rates come from the loop equation
//! `a e^{iθ₂} + b e^{iθ₃} − c e^{iθ₄} − d = 0` solved for `ω₃, ω₄`, then `α₃, α₄`.
//!
//! The quick-return ([`QuickReturn`], the scene `quick_return.mech`) needs one `sin_cos`, two
//! `sqrt`s and two `atan2`s (lever and link).
//!
//! The elementary functions are `libm`'s, as in generated code: on the x86-64 machines we
//! measure on, its `sincos` and `atan2` are faster than the C library's behind `f64::sin_cos`
//! and `f64::atan2` (which computes the sine and cosine separately), so this is the faster
//! baseline of the two.
//!
//! Coordinates and branches are those of [`crate::closed_form`], which checks the seed's and
//! the four-bar's formulas; the quick-return's are checked against the generated solve, with
//! and without its closed-form groups (tests in `tests/tests/written_out.rs`).

use crate::closed_form::{FourBar, PistonCrank};

/// `q`, `q̇`, `q̈` of one instant, written in place.
pub type Step<const N: usize> = ([f64; N], [f64; N], [f64; N]);

impl PistonCrank {
    /// `q`, `q̇`, `q̈` at time `t`, by the written-out closed form (crank at `ω t`, piston pin
    /// on the +x side of the crank pin).
    pub fn written_out(&self, t: f64, out: &mut Step<15>) {
        let s = self.scale;
        let (r, e, h, p) = (
            self.crank_radius * s,
            self.rod_crank_pin * s,
            self.rod_piston_pin * s,
            self.piston_pin * s,
        );
        let w_crank = self.omega;
        let (sin, cos) = libm::sincos(w_crank * t);
        // Crank pin P = (−r sin φ, r cos φ) and its rates (φ̈ = 0).
        let (px, py) = (-r * sin, r * cos);
        let (vx, vy) = (-r * cos * w_crank, -r * sin * w_crank);
        let (ax, ay) = (-px * w_crank * w_crank, -py * w_crank * w_crank);
        // Piston pin Q = (P_x + w, 0), w = √(L² − P_y²): w ẇ = −P_y Ṗ_y, and once more
        // ẇ² + w ẅ = −Ṗ_y² − P_y P̈_y.
        let l2 = e * e + h * h;
        let w = (l2 - py * py).sqrt();
        let wd = -py * vy / w;
        let wdd = -(vy * vy + py * ay + wd * wd) / w;
        // Rod: Q − P = (w, −P_y) = A(θ) (−e, h), so |Q − P|² = L² and
        // θ̇ = (d_x ḋ_y − d_y ḋ_x) / L², θ̈ = (d_x d̈_y − d_y d̈_x) / L² (the ḋ × ḋ terms cancel).
        let (dx, dy) = (w, -py);
        // A(θ) = A(β) A(−α), cos α = −e/L, sin α = h/L, cos β = d_x/L, sin β = d_y/L.
        let (cos_r, sin_r) = ((-e * dx + h * dy) / l2, (-e * dy - h * dx) / l2);
        let theta = libm::atan2(sin_r, cos_r);
        let theta_d = (-dx * vy + py * wd) / l2;
        let theta_dd = (-dx * ay + py * wdd) / l2;
        // Rod reference point: P − A(θ) (e, 0).
        let (xc, yc) = (px - e * cos_r, py - e * sin_r);
        let (xc_d, yc_d) = (vx + e * sin_r * theta_d, vy - e * cos_r * theta_d);
        let td2 = theta_d * theta_d;
        let xc_dd = ax + e * (cos_r * td2 + sin_r * theta_dd);
        let yc_dd = ay + e * (sin_r * td2 - cos_r * theta_dd);
        let (q, qd, qdd) = out;
        *q = [
            self.liner_x * s,
            0.0,
            0.0,
            px + w + p,
            0.0,
            0.0,
            xc,
            yc,
            theta,
            0.0,
            0.0,
            w_crank * t,
            0.0,
            0.0,
            0.0,
        ];
        *qd = [
            0.0,
            0.0,
            0.0,
            vx + wd,
            0.0,
            0.0,
            xc_d,
            yc_d,
            theta_d,
            0.0,
            0.0,
            w_crank,
            0.0,
            0.0,
            0.0,
        ];
        *qdd = [
            0.0,
            0.0,
            0.0,
            ax + wdd,
            0.0,
            0.0,
            xc_dd,
            yc_dd,
            theta_dd,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ];
    }
}

impl FourBar {
    /// `q`, `q̇`, `q̈` at time `t`, by the written-out closed form (crank at `ω t`, the
    /// documented branch).
    pub fn written_out(&self, t: f64, out: &mut Step<12>) {
        let (a, b, c, d, w2) = (
            self.crank,
            self.coupler,
            self.rocker,
            self.ground,
            self.omega,
        );
        let theta2 = w2 * t;
        let (sin2, cos2) = libm::sincos(theta2);
        let (pax, pay) = (a * cos2, a * sin2);
        // Circle–circle intersection, as in `FourBar::pin_b_generic`.
        let (ex, ey) = (d - pax, -pay);
        let e2 = ex * ex + ey * ey;
        let k = (e2 + b * b - c * c) / (2.0 * e2);
        let m = (b * b / e2 - k * k).sqrt();
        let (bx, by) = (pax + k * ex - m * ey, pay + k * ey + m * ex);
        let (cos3, sin3) = ((bx - pax) / b, (by - pay) / b);
        let (cos4, sin4) = ((bx - d) / c, by / c);
        // sin(θ₃ − θ₄) ≠ 0 away from the toggle; the loop equation's rates.
        let s34 = sin3 * cos4 - cos3 * sin4;
        let s24 = sin2 * cos4 - cos2 * sin4;
        let s23 = sin2 * cos3 - cos2 * sin3;
        let w3 = -a * w2 * s24 / (b * s34);
        let w4 = -a * w2 * s23 / (c * s34);
        // R = −a ω₂² u₂ − b ω₃² u₃ + c ω₄² u₄; α₃ = Re(R ū₄) / (b sin(θ₃ − θ₄)),
        // α₄ = Re(R ū₃) / (c sin(θ₃ − θ₄)).
        let (rx, ry) = (
            -a * w2 * w2 * cos2 - b * w3 * w3 * cos3 + c * w4 * w4 * cos4,
            -a * w2 * w2 * sin2 - b * w3 * w3 * sin3 + c * w4 * w4 * sin4,
        );
        let alpha3 = (rx * cos4 + ry * sin4) / (b * s34);
        let alpha4 = (rx * cos3 + ry * sin3) / (c * s34);
        let (q, qd, qdd) = out;
        *q = [
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            theta2,
            pax,
            pay,
            libm::atan2(by - pay, bx - pax),
            d,
            0.0,
            libm::atan2(by, bx - d),
        ];
        *qd = [
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            w2,
            -pay * w2,
            pax * w2,
            w3,
            0.0,
            0.0,
            w4,
        ];
        *qdd = [
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            -pax * w2 * w2,
            -pay * w2 * w2,
            alpha3,
            0.0,
            0.0,
            alpha4,
        ];
    }
}

/// The crank and slotted lever quick-return of `examples/scenes/quick_return.mech`: its
/// dimensions (mm, rad/s), with positions, velocities and accelerations written out by hand.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuickReturn {
    /// Crank speed.
    pub omega: f64,
    /// Crank pin's distance from the crank pivot.
    pub crank: f64,
    /// Lever pivot's distance below the crank pivot.
    pub drop: f64,
    /// Lever length, pivot to tip.
    pub lever: f64,
    /// Link length, lever tip to ram.
    pub link: f64,
    /// The ram's guide's height above the crank pivot.
    pub ram_height: f64,
}

impl Default for QuickReturn {
    fn default() -> Self {
        QuickReturn {
            omega: 10.0,
            crank: 40.0,
            drop: 100.0,
            lever: 220.0,
            link: 120.0,
            ram_height: 130.0,
        }
    }
}

impl QuickReturn {
    /// One crank revolution.
    pub fn period(&self) -> f64 {
        core::f64::consts::TAU / self.omega
    }

    /// `q`, `q̇`, `q̈` at time `t` (crank at `ω t`, the lever pointing at the pin, the ram to
    /// the right of the lever's tip).
    pub fn written_out(&self, t: f64, out: &mut Step<15>) {
        let (w, r, h) = (self.omega, self.crank, self.drop);
        let phi = w * t;
        let (sin, cos) = libm::sincos(phi);
        // The pin from the lever's pivot, d = P − O, and its rates (φ̈ = 0).
        let (dx, dy) = (r * cos, r * sin + h);
        let (vx, vy) = (-r * sin * w, r * cos * w);
        let (ax, ay) = (-r * cos * w * w, -r * sin * w * w);
        // The lever points along d: θ̇ = (d × ḋ)/|d|², θ̈ = (d × d̈)/|d|² − 2 θ̇ (d · ḋ)/|d|².
        let d2 = dx * dx + dy * dy;
        let theta = libm::atan2(dy, dx);
        let theta_d = (dx * vy - dy * vx) / d2;
        let theta_dd = (dx * ay - dy * ax) / d2 - 2.0 * theta_d * (dx * vx + dy * vy) / d2;
        let d = d2.sqrt();
        let (c, s) = (dx / d, dy / d);
        // The tip T = O + L (c, s).
        let l = self.lever;
        let (tx, ty) = (l * c, -h + l * s);
        let (tx_d, ty_d) = (-l * s * theta_d, l * c * theta_d);
        let td2 = theta_d * theta_d;
        let tx_dd = -l * (s * theta_dd + c * td2);
        let ty_dd = l * (c * theta_dd - s * td2);
        // The link: T_y + k sin ψ = height, cos ψ > 0; ψ̇ = −Ṫ_y/(k cos ψ),
        // ψ̈ = (−T̈_y + k sin ψ ψ̇²)/(k cos ψ).
        let k = self.link;
        let sin_psi = (self.ram_height - ty) / k;
        let cos_psi = (1.0 - sin_psi * sin_psi).sqrt();
        let psi = libm::atan2(sin_psi, cos_psi);
        let psi_d = -ty_d / (k * cos_psi);
        let psi_dd = (-ty_dd + k * sin_psi * psi_d * psi_d) / (k * cos_psi);
        // The ram, x = T_x + k cos ψ.
        let x = tx + k * cos_psi;
        let x_d = tx_d - k * sin_psi * psi_d;
        let x_dd = tx_dd - k * (cos_psi * psi_d * psi_d + sin_psi * psi_dd);
        let (q, qd, qdd) = out;
        *q = [
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            phi,
            0.0,
            -h,
            theta,
            tx,
            ty,
            psi,
            x,
            self.ram_height,
            0.0,
        ];
        *qd = [
            0.0, 0.0, 0.0, 0.0, 0.0, w, 0.0, 0.0, theta_d, tx_d, ty_d, psi_d, x_d, 0.0, 0.0,
        ];
        *qdd = [
            0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, theta_dd, tx_dd, ty_dd, psi_dd, x_dd, 0.0, 0.0,
        ];
    }
}
