//! Closed forms of the classical and of the uniform horizontal projectile motion.
//!
//! A particle of mass `m` starts at `(0, h0)` with the velocity `(v0, 0)` in the homogeneous
//! gravitational field `(0, -g)`. The module [`classical`] gives the free motion, equations
//! (42.4)–(42.16) of the paper; the module [`uniform`] gives the motion under the isotachytonic
//! constraint `f = ẋ² + ẏ² − v0² = 0` (42.23), equations (42.29)–(42.42). [`table`] gathers the
//! kinematic parameters of both motions, i.e. the two rows of Table 42.1.
//!
//! # Scales
//!
//! Throughout, `u = g t / v0` is the dimensionless time, `L = v0² / g` the length scale and
//! `z = g h0 / v0²` ([`Params::z`]) the dimensionless initial height.
//!
//! # Numerical stability
//!
//! Every quantity is evaluated in a form whose relative error stays within a few units in the
//! last place (ulps) of the exact value for the given `f64` inputs, times the condition number
//! of the quantity, over the whole range `1e-8 ≤ z ≤ 1e6`, `1e-6 ≤ v0, h0 ≤ 1e6`, and for every
//! finite time `t` (positive or negative):
//!
//! * `ln cosh u = ln1p(2 sinh²(u/2))` for `|u| < 1` and
//!   `ln cosh u = |u| − ln 2 + ln1p(e^(−2|u|))` beyond; in the uniform height the large branch is
//!   used as `L ln cosh u = v0 |t| − L (ln 2 − ln1p(e^(−2|u|)))`, which cannot overflow;
//! * `sech u = 2 e^(−|u|) / (1 + e^(−2|u|))` for every `u` (no overflow, underflows gracefully);
//! * `2 arctan(e^u) − π/2 = gd(u) = 2 arctan(tanh(u/2))` (the Gudermannian function);
//! * `arccosh(e^z) = z + ln1p(√(−expm1(−2z)))` for every `z ≥ 0`: both terms are nonnegative and
//!   each is computed without cancellation, so no switch is needed;
//! * `arccos(e^(−z)) = atan2(√(−expm1(−2z)), e^(−z))`;
//! * `ln|cos θ| = ½ ln1p(−sin² θ)` where `|sin θ| ≤ |cos θ|`, and `ln|cos θ|` directly elsewhere;
//! * the classical length (42.16) as `s = (T v_R + (v0²/g) asinh(g T / v0)) / 2`, a sum of two
//!   positive terms.
//!
//! All functions of time stay finite for any finite `t` whenever the exact result is
//! representable (e.g. `t = 1e6` with `g / v0 = 1e4`: `sech` underflows to `0`, the height is
//! `h0 − v0 t + (v0²/g) ln 2`).
//!
//! # Inputs
//!
//! No function here validates its arguments and none returns a `Result`: the parameters `v0`,
//! `g`, `h0`, `m` are assumed finite and strictly positive and the arguments `t`, `x` finite.
//! Checking this is the responsibility of the code that builds a [`Params`] from external input.

use chetaev::model::Real;
use std::f64::consts::LN_2;

/// Physical parameters (SI units) of the horizontal projectile: the particle of mass `m` starts at
/// `(0, h0)` with the velocity `(v0, 0)` in the field `(0, -g)` (Section 42.2).
///
/// All fields are assumed finite and strictly positive; they are not validated here.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    /// Initial (horizontal) speed `v0` in m/s; for the uniform motion also the constant speed
    /// (42.22).
    pub v0: f64,
    /// Gravitational acceleration `g` in m/s², the field being `(0, -g)`.
    pub g: f64,
    /// Initial height `h0` in m.
    pub h0: f64,
    /// Mass `m` in kg (enters only the multiplier (42.40) and the Chetaev force (42.39)–(42.42)).
    pub m: f64,
}

impl Params {
    /// The data of Section 42.5 (Table 42.1): `v0 = 10 m/s`, `g = 10 m/s²`, `h0 = 5 m`, and
    /// `m = 1 kg`.
    pub const PAPER: Params = Params {
        v0: 10.0,
        g: 10.0,
        h0: 5.0,
        m: 1.0,
    };

    /// The dimensionless initial height `z = g h0 / v0²`, the exponent in the uniform kinematic
    /// parameters (42.38): `cosh(g T / v0) = e^z`, `cos α = e^(−z)`.
    pub fn z(&self) -> f64 {
        self.g * self.h0 / (self.v0 * self.v0)
    }

    /// The dimensionless time `u = g t / v0`.
    fn u(&self, t: f64) -> f64 {
        t * (self.g / self.v0)
    }

    /// The length scale `L = v0² / g`.
    fn length_scale(&self) -> f64 {
        self.v0 * (self.v0 / self.g)
    }
}

/// The kinematic parameters of one motion, one row of Table 42.1 (Sections 42.2 and 42.4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kinematics {
    /// Total time `T` of the motion, from the start to the impact `y(T) = 0`, in s: classical
    /// `√(2 h0 / g)` from (42.4), uniform `(v0 / g) arccosh e^z` from (42.29).
    pub t_impact: f64,
    /// Range `R = x(T)`, in m: classical `v0 T`, uniform `(v0² / g) arccos e^(−z)`.
    pub range: f64,
    /// Impact speed `v_R = |v(T)|`, in m/s: classical `√(v0² + 2 g h0)` from (42.7), uniform
    /// `v0` from (42.31).
    pub impact_speed: f64,
    /// Angle of impact `α` in radians, measured below the horizontal:
    /// `cos α = |v_R · i| / |v_R|` (classical `v0 / v_R`, uniform `e^(−z)`). Mathematically in
    /// `(0, π/2)`; in `f64` it rounds to `π/2` when the motion is nearly vertical at the impact
    /// (very large `z`).
    pub impact_angle: f64,
    /// Length `s = ∫₀ᵀ |v(t)| dt` of the trajectory, in m: classical (42.16), uniform
    /// `v0 T` (42.38).
    pub length: f64,
}

impl Kinematics {
    /// The angle of impact [`Kinematics::impact_angle`] in degrees, as listed in Table 42.1.
    pub fn impact_angle_deg(&self) -> f64 {
        self.impact_angle.to_degrees()
    }
}

/// Both rows of Table 42.1: the kinematic parameters of the classical and of the uniform motion
/// under the same initial conditions (Section 42.5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Table {
    /// The classical horizontal projectile, (42.4)–(42.16); see [`classical::kinematics`].
    pub classical: Kinematics,
    /// The uniform horizontal projectile, (42.29)–(42.38); see [`uniform::kinematics`].
    pub uniform: Kinematics,
}

/// Table 42.1 for the parameters `p`: [`classical::kinematics`] and [`uniform::kinematics`].
pub fn table(p: &Params) -> Table {
    Table {
        classical: classical::kinematics(p),
        uniform: uniform::kinematics(p),
    }
}

/// Below this `|u|`, `ln cosh u` is evaluated as `ln1p(2 sinh²(u/2))`; from it on as
/// `|u| − ln 2 + ln1p(e^(−2|u|))`.
///
/// The first form is accurate to about two ulps from `u = 0` up to `|u| ≈ 700` (where
/// `sinh²(u/2)` overflows); the second one loses digits in `|u| − ln 2` below `|u| ≈ 0.75` but is
/// accurate to below one ulp from `|u| = 1` on (against 50-digit references: at most 2.6 ulps for
/// the first form on `|u| < 1`, at most 0.9 ulps for the second on `|u| ≥ 1`).
const LN_COSH_SWITCH: f64 = 1.0;

/// `sech u = 1 / cosh u`, as `2 e^(−|u|) / (1 + e^(−2|u|))`, which neither overflows nor loses
/// accuracy for any `u` (it underflows to `0` for `|u| ≳ 745`).
fn sech(u: f64) -> f64 {
    let e = (-u.abs()).exp();
    2.0 * e / e.mul_add(e, 1.0)
}

/// The small-argument form `ln cosh u = ln1p(2 sinh²(u/2))`, for `|u| < 1`.
fn ln_cosh_small(u: f64) -> f64 {
    let s = (0.5 * u).sinh();
    (2.0 * s * s).ln_1p()
}

/// The bounded remainder `c(u) = |u| − ln cosh u = ln 2 − ln1p(e^(−2|u|))`, in `[0, ln 2)`, used
/// for `|u| ≥ 1`.
fn ln_cosh_deficit(u: f64) -> f64 {
    LN_2 - (-2.0 * u.abs()).exp().ln_1p()
}

/// The Gudermannian function `gd(u) = 2 arctan(e^u) − π/2 = 2 arctan(tanh(u/2))`, odd in `u`
/// and bounded by `π/2`.
fn gd(u: f64) -> f64 {
    2.0 * (0.5 * u).tanh().atan()
}

/// `√(1 − e^(−2z)) = √(−expm1(−2z))`, the sine of the uniform impact angle, for `z ≥ 0`.
///
/// This and the two functions below are written for any scalar, so that with dual numbers they
/// give the closed forms' derivatives as accurately as the values (see [`uniform::impact`]).
fn sin_impact<D: Real>(z: D) -> D {
    (-(z * -2.0).exp_m1()).sqrt()
}

/// `arccosh(e^z) = z + ln(1 + √(1 − e^(−2z)))`, evaluated as `z + ln1p(√(−expm1(−2z)))`, for
/// `z ≥ 0`. Both terms are nonnegative, so the sum is accurate for every `z`: it behaves like
/// `√(2z)` for small `z` and like `z + ln 2` for large `z`, and never overflows.
fn acosh_exp<D: Real>(z: D) -> D {
    z + sin_impact(z).ln_1p()
}

/// `arccos(e^(−z)) = atan2(√(−expm1(−2z)), e^(−z))`, for `z ≥ 0`: accurate both for small `z`
/// (where `arccos` of a number near 1 cancels) and for large `z` (where `e^(−z)` underflows and
/// the angle tends to `π/2`).
///
/// `atan2` is [`Real::atan2`], whose derivatives stay finite once `e^(−z)` underflows to 0.
fn acos_exp_neg<D: Real>(z: D) -> D {
    Real::atan2(sin_impact(z), (-z).exp())
}

/// `ln|cos θ|`: `½ ln1p(−sin² θ)` where `|sin θ| ≤ |cos θ|` (near the maxima `θ = kπ`, where
/// `cos θ` rounds to `±1`), and `ln|cos θ|` elsewhere (where `|cos θ| < 1/√2`).
fn ln_abs_cos(theta: f64) -> f64 {
    let (s, c) = theta.sin_cos();
    if s.abs() <= c.abs() {
        0.5 * (-(s * s)).ln_1p()
    } else {
        c.abs().ln()
    }
}

/// The classical horizontal projectile motion, equations (42.4)–(42.16): `m ẍ = 0`,
/// `m ÿ = −m g` (42.3).
pub mod classical {
    use super::{Kinematics, Params};

    /// The position (42.4): `x(t) = v0 t`, `y(t) = h0 − g t² / 2`.
    ///
    /// `y` is evaluated as `(−g t / 2) · t + h0` with one fused multiply–add.
    pub fn position(p: &Params, t: f64) -> [f64; 2] {
        [p.v0 * t, (-0.5 * p.g * t).mul_add(t, p.h0)]
    }

    /// The velocity (42.6): `ẋ(t) = v0`, `ẏ(t) = −g t`.
    pub fn velocity(p: &Params, t: f64) -> [f64; 2] {
        [p.v0, -p.g * t]
    }

    /// The acceleration (42.8): `ẍ = 0`, `ÿ = −g` (independent of `t`).
    pub fn acceleration(p: &Params, _t: f64) -> [f64; 2] {
        [0.0, -p.g]
    }

    /// The curvature of the trajectory (42.13): `κ(t) = v0 g / (v0² + g² t²)^(3/2)`.
    ///
    /// Evaluated as `(g / v0²) / h³` with `h = hypot(1, g t / v0)`, dividing by `h` three times so
    /// that the result underflows gradually instead of overflowing in `h³` for huge `t`.
    pub fn curvature(p: &Params, t: f64) -> f64 {
        let h = 1.0_f64.hypot(p.u(t));
        p.g / (p.v0 * p.v0) / h / h / h
    }

    /// The kinematic parameters of the classical motion (Section 42.2):
    ///
    /// * total time `T = √(2 h0 / g)`,
    /// * range `R = v0 T`,
    /// * impact speed `v_R = √(v0² + 2 g h0)`,
    /// * angle of impact `α` with `cos α = v0 / v_R`, evaluated as `atan2(√(2 g h0), v0)`,
    /// * length (42.16)
    ///   `s = √(h0 / 2g) √(v0² + 2 g h0) + (v0² / 2g) ln((√(2 g h0) + √(v0² + 2 g h0)) / v0)`,
    ///   evaluated as `s = (T v_R + (v0² / g) asinh(√(2 g h0) / v0)) / 2`.
    pub fn kinematics(p: &Params) -> Kinematics {
        let t_impact = (2.0 * p.h0 / p.g).sqrt();
        // |ẏ(T)| = g T = √(2 g h0).
        let fall_speed = (2.0 * p.g * p.h0).sqrt();
        let impact_speed = p.v0.hypot(fall_speed);
        let length =
            0.5 * (t_impact * impact_speed + p.length_scale() * (fall_speed / p.v0).asinh());
        Kinematics {
            t_impact,
            range: p.v0 * t_impact,
            impact_speed,
            impact_angle: fall_speed.atan2(p.v0),
            length,
        }
    }
}

/// The uniform horizontal projectile motion, equations (42.29)–(42.42).
///
/// The particle is subject to the isotachytonic constraint `f = ẋ² + ẏ² − v0² = 0` (42.23) and
/// moves by the Chetaev equations in Newton form `m q̈ = F + μ ∂f/∂q̇` (42.26):
/// `m ẍ = 2 μ ẋ`, `m ÿ = 2 μ ẏ − m g`. With `u = g t / v0` and `L = v0² / g` the solution is
/// `x = L gd(u)`, `y = h0 − L ln cosh u`: `x` is odd and `y` even in `t`, and the formulas hold
/// for every real `t`, before the start and after the impact alike.
pub mod uniform {
    use super::{
        acos_exp_neg, acosh_exp, gd, ln_abs_cos, ln_cosh_deficit, ln_cosh_small, sech, Kinematics,
        Params, Real, LN_COSH_SWITCH,
    };

    /// The position (42.29):
    /// `x(t) = −π v0² / 2g + (2 v0² / g) arctan e^(g t / v0)`,
    /// `y(t) = h0 − (v0² / g) ln cosh(g t / v0)`.
    ///
    /// `x` is evaluated as `L gd(u) = 2 L arctan(tanh(u / 2))`. `y` is evaluated as
    /// `h0 − L ln1p(2 sinh²(u/2))` for `|u| < 1` and as
    /// `h0 + L (ln 2 − ln1p(e^(−2|u|))) − v0 |t|` beyond, which is finite for every finite `t`
    /// whenever `v0 |t|` is.
    pub fn position(p: &Params, t: f64) -> [f64; 2] {
        let u = p.u(t);
        let l = p.length_scale();
        let y = if u.abs() < LN_COSH_SWITCH {
            (-l).mul_add(ln_cosh_small(u), p.h0)
        } else {
            p.v0.mul_add(-t.abs(), l.mul_add(ln_cosh_deficit(u), p.h0))
        };
        [l * gd(u), y]
    }

    /// The velocity (42.30): `ẋ(t) = v0 / cosh(g t / v0)`, `ẏ(t) = −v0 tanh(g t / v0)`; its
    /// magnitude is `v0` (42.31).
    pub fn velocity(p: &Params, t: f64) -> [f64; 2] {
        let u = p.u(t);
        [p.v0 * sech(u), -p.v0 * u.tanh()]
    }

    /// The acceleration (42.32): `ẍ(t) = −g tanh(g t / v0) / cosh(g t / v0)`,
    /// `ÿ(t) = −g / cosh²(g t / v0)`; its magnitude is `g / cosh(g t / v0)` (42.33).
    pub fn acceleration(p: &Params, t: f64) -> [f64; 2] {
        let u = p.u(t);
        let sh = sech(u);
        [-p.g * u.tanh() * sh, -p.g * sh * sh]
    }

    /// The curvature of the trajectory (42.36): `κ(t) = g / (v0² cosh(g t / v0))`.
    pub fn curvature(p: &Params, t: f64) -> f64 {
        p.g / (p.v0 * p.v0) * sech(p.u(t))
    }

    /// The Lagrange multiplier (42.40):
    /// `μ(t) = −m ẏ ÿ / (2 (v0² − ẏ²)) = (m g / 2 v0²) ẏ = −(m g / 2 v0) tanh(g t / v0)`,
    /// in the sign convention of the Newton form (42.26), `m q̈ = F + μ ∂f/∂q̇`.
    pub fn multiplier(p: &Params, t: f64) -> f64 {
        -0.5 * p.m * (p.g / p.v0) * p.u(t).tanh()
    }

    /// The Chetaev constraint force (42.25), (42.39): `Φ = μ (∂f/∂ẋ, ∂f/∂ẏ) = 2 μ (ẋ, ẏ)`,
    /// i.e. `Φ(t) = −m g tanh(g t / v0) (sech(g t / v0), −tanh(g t / v0))`, directed against
    /// the velocity for `t > 0`.
    pub fn chetaev_force(p: &Params, t: f64) -> [f64; 2] {
        let u = p.u(t);
        let th = u.tanh();
        let mg = p.m * p.g;
        [-mg * th * sech(u), mg * th * th]
    }

    /// The magnitude of the Chetaev force (42.42): `|Φ(t)| = 2 v0 |μ(t)| = m g tanh(g t / v0)`
    /// for `t ≥ 0`, and `m g |tanh(g t / v0)|` for every `t`.
    pub fn chetaev_force_magnitude(p: &Params, t: f64) -> f64 {
        p.m * p.g * p.u(t).tanh().abs()
    }

    /// The explicit trajectory (42.37): `y(x) = h0 + (v0² / g) ln|cos(g x / v0²)|`.
    ///
    /// The motion itself covers `|x| < π v0² / 2g` (the positive part `0 ≤ x ≤ R` up to the
    /// impact); the formula is evaluated for any `x`, periodically, with
    /// `ln|cos θ| = ½ ln1p(−sin² θ)` where `|sin θ| ≤ |cos θ|` and `ln|cos θ|` elsewhere. The
    /// value is very large and negative next to the asymptotes `g x / v0² = π/2 + kπ` (it would be
    /// `−∞` only exactly on them, which no `f64` argument reaches), and `NaN` if `g x / v0²`
    /// overflows.
    pub fn trajectory_y(p: &Params, x: f64) -> f64 {
        let l = p.length_scale();
        l.mul_add(ln_abs_cos(x / l), p.h0)
    }

    /// The kinematic parameters of the uniform motion (Section 42.4), with `z = g h0 / v0²`:
    ///
    /// * total time `T = (v0 / g) arccosh e^z`,
    /// * range `R = (v0² / g) arccos e^(−z) = (v0² / g) α`,
    /// * impact speed `v_R = v0`,
    /// * angle of impact `α` with `cos α = e^(−z)`,
    /// * length (42.38) `s = v0 T = (v0² / g) arccosh e^z`.
    ///
    /// `arccosh e^z` is evaluated as `z + ln1p(√(−expm1(−2z)))` and `arccos e^(−z)` as
    /// `atan2(√(−expm1(−2z)), e^(−z))`, accurate for every `z ≥ 0`.
    pub fn kinematics(p: &Params) -> Kinematics {
        let z = p.z();
        let t_impact = (p.v0 / p.g) * acosh_exp(z);
        let impact_angle = acos_exp_neg(z);
        Kinematics {
            t_impact,
            range: p.length_scale() * impact_angle,
            impact_speed: p.v0,
            impact_angle,
            length: p.v0 * t_impact,
        }
    }

    /// The impact time `T = (v0/g) arccosh e^z` and range `R = (v0²/g) arccos e^(−z)`,
    /// `z = g h0 / v0²` (Section 42.4), written for any scalar: with dual numbers they give the
    /// closed forms' own derivatives, `∂T/∂v0`, `∂R/∂g`, ..., against which the library's
    /// sensitivities are checked. They are evaluated as in [`kinematics`], accurate for every
    /// `z > 0` (the plain `arccosh(e^z)` loses the derivative's digits to cancellation at small
    /// `z`: a relative error of about `1e-3` in `∂T/∂v0` at `z = 5e-7`).
    pub fn impact<D: Real>(v0: D, g: D, h0: D) -> (D, D) {
        let z = g * h0 / (v0 * v0);
        let length = v0 * (v0 / g);
        (v0 / g * acosh_exp(z), length * acos_exp_neg(z))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::{FRAC_PI_2, LN_2, PI};

    const EPS: f64 = f64::EPSILON;

    /// Allowed error against the 50-digit references, in units of `EPS × (1 + condition)`.
    ///
    /// Each closed form is a short chain of correctly rounded operations and libm calls that are
    /// accurate to about one ulp (`exp`, `expm1`, `ln1p`, `sinh`, `tanh`, `atan`, `atan2`,
    /// `hypot`, `asinh`), with no cancellation left in it, so its error is a few ulps of the
    /// result plus the propagation of the rounding of `u = t (g / v0)`, `z = g h0 / v0²` and
    /// `L = v0 (v0 / g)` (about one ulp each) through the condition number of the quantity with
    /// respect to them. The largest error observed is `0.95 EPS (1 + condition)` (printed by
    /// `reference_values` with `--nocapture`); `4` leaves a margin for other libm
    /// implementations. For `condition ≤ 1` this is a relative tolerance of `8 EPS ≈ 1.8e-15`;
    /// the largest condition numbers occur for `sech(u)` at `u = 400`, where the rounding of `u`
    /// alone makes relative errors of about `400 EPS` unavoidable.
    const ULPS: f64 = 4.0;

    /// One time sample of a reference case.
    struct Sample {
        /// The time `t` (exactly the `f64` the references were computed at).
        t: f64,
        /// Uniform motion: `x, y, ẋ, ẏ, ẍ, ÿ, κ, μ, Φx, Φy, |Φ|`.
        uniform: [f64; 11],
        /// Classical motion: `x, y, κ`.
        classical: [f64; 3],
    }

    /// One parameter set with its references.
    struct Case {
        p: Params,
        /// Classical `T, R, v_R, α, s`.
        classical: [f64; 5],
        /// Uniform `T, R, v_R, α, s`.
        uniform: [f64; 5],
        samples: &'static [Sample],
        /// Pairs `(x, y(x))` of the trajectory (42.37).
        trajectory: &'static [[f64; 2]],
    }

    // Reference values, computed at 50 significant digits by the following Python script
    // (mpmath 1.3), from the exact binary values of the `f64` inputs and with the formulas of the
    // paper as printed (no stable rewriting); its output, indented, is the constant `CASES`
    // below, each value rounded to the nearest `f64`:
    //
    // import mpmath as mp
    // mp.mp.dps = 50
    // F = lambda x: repr(float(x))
    // SETS = [(10.0, 10.0, 5.0, 1.0), (1e3, 10.0, 1e-3, 1.0), (1e2, 10.0, 0.1, 2.5),
    //         (1e-6, 1e-6, 1e-6, 1e-3), (1.0, 10.0, 100.0, 1.0), (1e-2, 10.0, 10.0, 1.0),
    //         (1e-3, 9.81, 1.0, 1.0), (1e6, 1e-2, 1e6, 70.0)]
    // for v0, g, h0, m in SETS:
    //     V, G, H, M = map(mp.mpf, (v0, g, h0, m))  # the exact binary values of the f64 inputs
    //     z, L, a = G * H / V**2, V**2 / G, G / V
    //     vR = mp.sqrt(V**2 + 2 * G * H)
    //     cl = [mp.sqrt(2 * H / G), V * mp.sqrt(2 * H / G), vR, mp.acos(V / vR),
    //           mp.sqrt(H / (2 * G)) * vR + V**2 / (2 * G) * mp.log((mp.sqrt(2 * G * H) + vR) / V)]
    //     Tu, al = V / G * mp.acosh(mp.exp(z)), mp.acos(mp.exp(-z))
    //     un = [Tu, L * al, V, al, V * Tu]
    //     print(f"Case {{ p: Params {{ v0: {F(V)}, g: {F(G)}, h0: {F(H)}, m: {F(M)} }},")
    //     print(f"  classical: [{', '.join(map(F, cl))}],")
    //     print(f"  uniform: [{', '.join(map(F, un))}],")
    //     print("  samples: &[")
    //     for t in [float(uu * V / G) for uu in (1e-7, 0.3, 2, 30, 400, -1.5)] + [float(Tu)]:
    //         T = mp.mpf(t); u = a * T
    //         sh, th = mp.sech(u), mp.tanh(u)
    //         mu = -M * G / (2 * V) * th
    //         uni = [-mp.pi * L / 2 + 2 * L * mp.atan(mp.exp(u)), H - L * mp.log(mp.cosh(u)),
    //                V * sh, -V * th, -G * th * sh, -G * sh**2, G / V**2 * sh, mu,
    //                2 * mu * V * sh, 2 * mu * (-V * th), M * G * abs(th)]
    //         cla = [V * T, H - G * T**2 / 2, V * G / mp.sqrt(V**2 + G**2 * T**2)**3]
    //         print(f"    Sample {{ t: {F(T)}, uniform: [{', '.join(map(F, uni))}],")
    //         print(f"      classical: [{', '.join(map(F, cla))}] }},")
    //     print("  ],")
    //     print("  trajectory: &[", end="")
    //     for x in [float(f * L * al) for f in (0.5, 1, -0.3)] + [float(3 * L)]:
    //         X = mp.mpf(x)
    //         print(f"[{F(X)}, {F(H + L * mp.log(abs(mp.cos(X / L))))}], ", end="")
    //     print("],\n},")
    //
    // The sets are the data of the paper (z = 0.5), z = 1e-8, 1e-4, 1 (with v0 = g = h0 = 1e-6),
    // 1e3, 1e6, the set v0 = 1e-3, g = 9.81, h0 = 1 (z = 9.81e6), and z = 1e-8 with
    // v0 = h0 = 1e6. The times are u = g t / v0 = 1e-7, 0.3, 2, 30, 400, -1.5 and the uniform
    // impact time T.
    #[rustfmt::skip]
    #[allow(clippy::approx_constant)] // the references include π/2 and π/4 rounded to f64
    const CASES: &[Case] = &[
        Case { p: Params { v0: 10.0, g: 10.0, h0: 5.0, m: 1.0 },
          classical: [1.0, 10.0, 14.142135623730951, 0.7853981633974483, 11.47793574696319],
          uniform: [1.0850385019483877, 9.191066572935885, 10.0, 0.9191066572935884, 10.850385019483877],
          samples: &[
            Sample { t: 1e-07, uniform: [9.999999999999983e-07, 4.99999999999995, 9.99999999999995, -9.999999999999966e-07, -9.999999999999917e-07, -9.9999999999999, 0.0999999999999995, -4.999999999999983e-08, -9.999999999999917e-07, 9.999999999999932e-14, 9.999999999999966e-07],
              classical: [1e-06, 4.99999999999995, 0.0999999999999985] },
            Sample { t: 0.3, uniform: [2.9559867598460414, 4.556592300740597, 9.566279119002482, -2.913126124515909, -2.7867777615977167, -9.151369618266292, 0.09566279119002483, -0.14565630622579545, -2.7867777615977167, 0.8486303817337079, 2.913126124515909],
              classical: [3.0, 4.55, 0.08787397112120655] },
            Sample { t: 2.0, uniform: [13.017603360460152, -8.250027473578644, 2.658022288340797, -9.640275800758168, -2.5624067944167637, -0.7065082485316446, 0.02658022288340797, -0.48201379003790845, -2.5624067944167637, 9.293491751468355, 9.640275800758168],
              classical: [20.0, -15.0, 0.00894427190999916] },
            Sample { t: 30.0, uniform: [15.707963267947095, -288.0685281944005, 1.871524593768035e-12, -10.0, -1.871524593768035e-12, -3.5026043050786082e-25, 1.871524593768035e-14, -0.5, -1.871524593768035e-12, 10.0, 10.0],
              classical: [300.0, -4495.0, 3.6975394264859575e-06] },
            Sample { t: 400.0, uniform: [15.707963267948966, -3988.0685281944006, 3.830339193428011e-173, -10.0, -3.830339193428011e-173, -0.0, 3.8303391934280115e-175, -0.5, -3.830339193428011e-173, 10.0, 10.0],
              classical: [4000.0, -799995.0, 1.5624853516769402e-09] },
            Sample { t: -1.5, uniform: [-11.317283452505091, -3.5544017101379675, 4.2509603494228045, 9.051482536448665, 3.8477493365936226, -1.8070663892364853, 0.04250960349422805, 0.4525741268224332, 3.8477493365936226, 8.192933610763514, 9.051482536448665],
              classical: [-15.0, -6.25, 0.017067698345391666] },
            Sample { t: 1.0850385019483877, uniform: [9.191066572935883, 6.359038449584797e-16, 6.065306597126335, -7.950600976206501, -4.822283255210436, -3.678794411714424, 0.06065306597126335, -0.39753004881032505, -4.822283255210436, 6.321205588285577, 7.950600976206501],
              classical: [10.850385019483877, -0.8865427535520066, 0.03112576489968415] },
          ],
          trajectory: &[[4.595533286467942, 3.9046490181008067], [9.191066572935885, -6.196805977899709e-16], [-2.757319971880765, 4.614942461391791], [30.0, 4.899420849263071], ],
        },
        Case { p: Params { v0: 1000.0, g: 10.0, h0: 0.001, m: 1.0 },
          classical: [0.01414213562373095, 14.142135623730951, 1000.00001, 0.00014142135529450047, 14.142135670871403],
          uniform: [0.014142135647301176, 14.142135600160724, 1000.0, 0.00014142135600160724, 14.142135647301176],
          samples: &[
            Sample { t: 9.999999999999999e-06, uniform: [0.009999999999999983, 0.0009999995, 999.999999999995, -9.999999999999965e-05, -9.999999999999915e-07, -9.9999999999999, 9.99999999999995e-06, -4.999999999999983e-10, -9.999999999999915e-07, 9.999999999999932e-14, 9.999999999999966e-07],
              classical: [0.009999999999999998, 0.0009999995, 9.99999999999985e-06] },
            Sample { t: 30.0, uniform: [29559.867598460412, -4434.075992594032, 956.6279119002483, -291.3126124515909, -2.7867777615977167, -9.151369618266292, 9.566279119002482e-06, -0.0014565630622579546, -2.7867777615977167, 0.848630381733708, 2.9131261245159092],
              classical: [30000.0, -4499.999, 8.787397112120655e-06] },
            Sample { t: 200.0, uniform: [130176.03360460151, -132500.27373578644, 265.8022288340797, -964.0275800758169, -2.5624067944167637, -0.7065082485316446, 2.658022288340797e-06, -0.004820137900379084, -2.5624067944167637, 9.293491751468355, 9.640275800758168],
              classical: [200000.0, -199999.999, 8.944271909999158e-07] },
            Sample { t: 3000.0, uniform: [157079.63267947096, -2930685.2809440056, 1.871524593768035e-10, -1000.0, -1.871524593768035e-12, -3.5026043050786082e-25, 1.871524593768035e-18, -0.005, -1.871524593768035e-12, 10.0, 10.0],
              classical: [3000000.0, -44999999.999, 3.697539426485958e-10] },
            Sample { t: 40000.0, uniform: [157079.63267948967, -39930685.280944005, 3.8303391934280113e-171, -1000.0, -3.830339193428011e-173, -0.0, 3.830339193428011e-179, -0.005, -3.830339193428011e-173, 10.0, 10.0],
              classical: [40000000.0, -7999999999.999, 1.5624853516769401e-13] },
            Sample { t: -150.0, uniform: [-113172.83452505092, -85544.01610137968, 425.0960349422805, 905.1482536448665, 3.8477493365936226, -1.8070663892364853, 4.250960349422805e-06, 0.004525741268224332, 3.8477493365936226, 8.192933610763514, 9.051482536448665],
              classical: [-150000.0, -112499.999, 1.7067698345391665e-06] },
            Sample { t: 0.014142135647301176, uniform: [14.142135600160724, 5.129457685617492e-20, 999.99999, -0.1414213555302027, -0.0014142135411598917, -9.999999800000001, 9.999999900000001e-06, -7.071067776510136e-07, -0.0014142135411598917, 1.99999998e-07, 0.0014142135553020273],
              classical: [14.142135647301176, -3.3333332864832005e-12, 9.999999700000006e-06] },
          ],
          trajectory: &[[7.071067800080362, 0.0007500000006250001], [14.142135600160724, 3.622088082886612e-20], [-4.2426406800482175, 0.000910000000273], [300000.0, -1005.7905073692893], ],
        },
        Case { p: Params { v0: 100.0, g: 10.0, h0: 0.1, m: 2.5 },
          classical: [0.1414213562373095, 14.142135623730951, 100.00999950005, 0.014141192927810294, 14.142607014110617],
          uniform: [0.14142371327169814, 14.14189992264911, 100.0, 0.01414189992264911, 14.142371327169815],
          samples: &[
            Sample { t: 1e-06, uniform: [9.999999999999983e-05, 0.099999999995, 99.9999999999995, -9.999999999999967e-06, -9.999999999999917e-07, -9.9999999999999, 0.000999999999999995, -1.2499999999999958e-08, -2.499999999999979e-06, 2.4999999999999833e-13, 2.4999999999999917e-06],
              classical: [9.999999999999999e-05, 0.099999999995, 0.000999999999999985] },
            Sample { t: 3.0, uniform: [295.59867598460414, -44.24076992594032, 95.66279119002483, -29.13126124515909, -2.7867777615977167, -9.151369618266292, 0.0009566279119002483, -0.03641407655644886, -6.966944403994292, 2.12157595433427, 7.282815311289773],
              classical: [300.0, -44.9, 0.0008787397112120655] },
            Sample { t: 20.0, uniform: [1301.760336046015, -1324.9027473578644, 26.58022288340797, -96.40275800758168, -2.5624067944167637, -0.7065082485316446, 0.0002658022288340797, -0.12050344750947711, -6.406016986041909, 23.233729378670887, 24.10068950189542],
              classical: [2000.0, -1999.9, 8.944271909999159e-05] },
            Sample { t: 300.0, uniform: [1570.7963267947096, -29306.752819440055, 1.8715245937680348e-11, -100.0, -1.871524593768035e-12, -3.5026043050786082e-25, 1.871524593768035e-16, -0.125, -4.678811484420087e-12, 25.0, 25.0],
              classical: [30000.0, -449999.9, 3.697539426485958e-08] },
            Sample { t: 4000.0, uniform: [1570.7963267948967, -399306.75281944004, 3.830339193428011e-172, -100.0, -3.830339193428011e-173, -0.0, 3.8303391934280115e-177, -0.125, -9.575847983570028e-173, 25.0, 25.0],
              classical: [400000.0, -79999999.9, 1.56248535167694e-11] },
            Sample { t: -15.0, uniform: [-1131.7283452505092, -855.3401710137967, 42.509603494228045, 90.51482536448664, 3.8477493365936226, -1.8070663892364853, 0.0004250960349422805, 0.1131435317056083, 9.619373341484057, 20.482334026908788, 22.62870634112166],
              classical: [-1500.0, -1124.9, 0.00017067698345391664] },
            Sample { t: 0.14142371327169814, uniform: [14.141899922649108, 1.89879920141969e-17, 99.99000049998334, -1.414142854641166, -0.14140014474261806, -9.998000199986667, 0.0009999000049998334, -0.0017676785683014577, -0.35350036185654515, 0.004999500033331666, 0.3535357136602915],
              classical: [14.142371327169814, -3.333377777441316e-06, 0.000999700064987369] },
          ],
          trajectory: &[[7.070949961324555, 0.07500062499999974], [14.14189992264911, -1.1306494790479531e-17], [-4.242569976794733, 0.09100027299767033], [3000.0, -9.957915073692893], ],
        },
        Case { p: Params { v0: 1e-06, g: 1e-06, h0: 1e-06, m: 0.001 },
          classical: [1.4142135623730951, 1.414213562373095e-06, 1.7320508075688771e-06, 0.9553166181245093, 1.7978527887818834e-06],
          uniform: [1.6574544541530774, 1.1940688187363216e-06, 1e-06, 1.1940688187363215, 1.6574544541530772e-06],
          samples: &[
            Sample { t: 1e-07, uniform: [9.999999999999983e-14, 9.999999999999949e-07, 9.999999999999949e-07, -9.999999999999966e-14, -9.999999999999916e-14, -9.9999999999999e-07, 999999.999999995, -4.9999999999999834e-11, -9.999999999999916e-17, 9.999999999999932e-24, 9.999999999999967e-17],
              classical: [9.999999999999999e-14, 9.999999999999949e-07, 999999.9999999851] },
            Sample { t: 0.3, uniform: [2.955986759846041e-07, 9.556592300740596e-07, 9.566279119002482e-07, -2.913126124515909e-07, -2.786777761597717e-07, -9.151369618266292e-07, 956627.9119002484, -0.00014565630622579546, -2.7867777615977166e-10, 8.486303817337079e-11, 2.9131261245159086e-10],
              classical: [3e-07, 9.55e-07, 878739.7112120655] },
            Sample { t: 2.0, uniform: [1.301760336046015e-06, -3.250027473578644e-07, 2.658022288340797e-07, -9.640275800758167e-07, -2.5624067944167633e-07, -7.065082485316446e-08, 265802.2288340797, -0.00048201379003790846, -2.5624067944167637e-10, 9.293491751468355e-10, 9.64027580075817e-10],
              classical: [2e-06, -1e-06, 89442.71909999159] },
            Sample { t: 30.0, uniform: [1.5707963267947095e-06, -2.8306852819440053e-05, 1.8715245937680347e-19, -1e-06, -1.8715245937680347e-19, -3.502604305078608e-32, 1.871524593768035e-07, -0.0005, -1.8715245937680348e-22, 1e-09, 1e-09],
              classical: [2.9999999999999997e-05, -0.00044899999999999996, 36.97539426485958] },
            Sample { t: 400.0, uniform: [1.5707963267948965e-06, -0.00039830685281944003, 3.8303391934280114e-180, -1e-06, -3.8303391934280114e-180, -0.0, 3.8303391934280117e-168, -0.0005, -3.830339193428011e-183, 1e-09, 1e-09],
              classical: [0.00039999999999999996, -0.079999, 0.015624853516769401] },
            Sample { t: -1.5, uniform: [-1.131728345250509e-06, 1.4455982898620324e-07, 4.2509603494228045e-07, 9.051482536448664e-07, 3.847749336593623e-07, -1.8070663892364852e-07, 425096.0349422805, 0.0004525741268224332, 3.847749336593623e-10, 8.192933610763514e-10, 9.051482536448664e-10],
              classical: [-1.5e-06, -1.25e-07, 170676.98345391665] },
            Sample { t: 1.6574544541530774, uniform: [1.1940688187363216e-06, -7.201758019250458e-23, 3.678794411714423e-07, -9.298734950321938e-07, -3.420813417125794e-07, -1.3533528323661265e-07, 367879.44117144233, -0.0004649367475160969, -3.420813417125794e-10, 8.646647167633874e-10, 9.298734950321937e-10],
              classical: [1.6574544541530772e-06, -3.735776337959378e-07, 137862.91802153972] },
          ],
          trajectory: &[[5.970344093681608e-07, 8.100572534791387e-07], [1.1940688187363216e-06, -1.8719195571411375e-22], [-3.5822064562089643e-07, 9.344179078379855e-07], [3e-06, 9.89942084926307e-07], ],
        },
        Case { p: Params { v0: 1.0, g: 10.0, h0: 100.0, m: 1.0 },
          classical: [4.47213595499958, 4.47213595499958, 44.73253849269008, 1.5484393726822263, 100.249683045126],
          uniform: [100.06931471805599, 0.15707963267948966, 1.0, 1.5707963267948966, 100.06931471805599],
          samples: &[
            Sample { t: 1e-08, uniform: [9.999999999999984e-09, 100.0, 0.999999999999995, -9.999999999999966e-08, -9.999999999999917e-07, -9.9999999999999, 9.99999999999995, -4.999999999999984e-07, -9.999999999999917e-07, 9.999999999999933e-14, 9.999999999999968e-07],
              classical: [1e-08, 100.0, 9.99999999999985] },
            Sample { t: 0.03, uniform: [0.029559867598460413, 99.9955659230074, 0.9566279119002483, -0.2913126124515909, -2.7867777615977167, -9.151369618266292, 9.566279119002482, -1.4565630622579544, -2.7867777615977167, 0.8486303817337079, 2.913126124515909],
              classical: [0.03, 99.9955, 8.787397112120654] },
            Sample { t: 0.2, uniform: [0.1301760336046015, 99.86749972526421, 0.26580222883407967, -0.9640275800758169, -2.5624067944167632, -0.7065082485316445, 2.6580222883407965, -4.820137900379084, -2.5624067944167632, 9.293491751468355, 9.640275800758168],
              classical: [0.2, 99.8, 0.8944271909999157] },
            Sample { t: 3.0, uniform: [0.15707963267947095, 97.06931471805599, 1.871524593768035e-13, -1.0, -1.871524593768035e-12, -3.5026043050786082e-25, 1.871524593768035e-12, -5.0, -1.871524593768035e-12, 10.0, 10.0],
              classical: [3.0, 55.0, 0.00036975394264859575] },
            Sample { t: 40.0, uniform: [0.15707963267948966, 60.06931471805599, 3.8303391934280114e-174, -1.0, -3.830339193428011e-173, -0.0, 3.830339193428011e-173, -5.0, -3.830339193428011e-173, 10.0, 10.0],
              classical: [40.0, -7900.0, 1.5624853516769401e-07] },
            Sample { t: -0.15, uniform: [-0.1131728345250509, 99.91445598289862, 0.4250960349422805, 0.9051482536448664, 3.847749336593623, -1.8070663892364855, 4.2509603494228045, 4.5257412682243325, 3.847749336593623, 8.192933610763514, 9.051482536448665],
              classical: [-0.15, 99.8875, 1.7067698345391666] },
            Sample { t: 100.06931471805599, uniform: [0.15707963267948966, 2.6557520756679706e-15, 0.0, -1.0, -0.0, -0.0, 0.0, -5.0, -0.0, 10.0, 10.0],
              classical: [100.06931471805599, -49969.33874070669, 9.979219430392935e-09] },
          ],
          trajectory: &[[0.07853981633974483, 99.965342640972], [0.15707963267948966, 96.26681438067311], [-0.047123889803846894, 99.98845964707833], [0.3, 99.99899420849263], ],
        },
        Case { p: Params { v0: 0.01, g: 10.0, h0: 10.0, m: 1.0 },
          classical: [1.4142135623730951, 0.01414213562373095, 14.142139159264415, 1.5700892201315613, 10.000042237380562],
          uniform: [1000.0006931471805, 1.5707963267948967e-05, 0.01, 1.5707963267948966, 10.000006931471805],
          samples: &[
            Sample { t: 1e-10, uniform: [9.999999999999984e-13, 10.0, 0.00999999999999995, -9.999999999999968e-10, -9.999999999999917e-07, -9.9999999999999, 99999.99999999949, -4.999999999999983e-05, -9.999999999999917e-07, 9.999999999999933e-14, 9.999999999999968e-07],
              classical: [1e-12, 10.0, 99999.9999999985] },
            Sample { t: 0.0003, uniform: [2.955986759846041e-06, 9.9999995565923, 0.009566279119002484, -0.0029131261245159087, -2.7867777615977167, -9.151369618266292, 95662.79119002483, -145.65630622579545, -2.7867777615977167, 0.8486303817337078, 2.913126124515909],
              classical: [2.9999999999999997e-06, 9.99999955, 87873.97112120654] },
            Sample { t: 0.002, uniform: [1.3017603360460152e-05, 9.999986749972527, 0.002658022288340797, -0.009640275800758168, -2.5624067944167637, -0.7065082485316446, 26580.22288340797, -482.01379003790845, -2.5624067944167637, 9.293491751468355, 9.640275800758168],
              classical: [2e-05, 9.99998, 8944.27190999916] },
            Sample { t: 0.03, uniform: [1.5707963267947094e-05, 9.999706931471806, 1.8715245937680383e-15, -0.01, -1.871524593768038e-12, -3.50260430507862e-25, 1.871524593768038e-08, -500.0, -1.871524593768038e-12, 10.0, 10.0],
              classical: [0.0003, 9.9955, 3.697539426485958] },
            Sample { t: 0.4, uniform: [1.5707963267948967e-05, 9.996006931471806, 3.830339193427958e-176, -0.01, -3.830339193427958e-173, -0.0, 3.830339193427958e-169, -500.0, -3.830339193427958e-173, 10.0, 10.0],
              classical: [0.004, 9.2, 0.00156248535167694] },
            Sample { t: -0.0015, uniform: [-1.1317283452505091e-05, 9.99999144559829, 0.004250960349422805, 0.009051482536448665, 3.8477493365936226, -1.8070663892364853, 42509.603494228046, 452.5741268224332, 3.8477493365936226, 8.192933610763514, 9.051482536448665],
              classical: [-1.5e-05, 9.99998875, 17067.698345391665] },
            Sample { t: 1000.0006931471805, uniform: [1.5707963267948967e-05, 1.175274753587182e-16, 0.0, -0.01, -0.0, -0.0, 0.0, -500.0, -0.0, 10.0, 10.0],
              classical: [10.000006931471805, -4999996.931474208, 9.999979205598411e-14] },
          ],
          trajectory: &[[7.853981633974484e-06, 9.999996534264097], [1.5707963267948967e-05, 9.999627068300539], [-4.7123889803846896e-06, 9.999998845964708], [3e-05, 9.99999989942085], ],
        },
        Case { p: Params { v0: 0.001, g: 9.81, h0: 1.0, m: 1.0 },
          classical: [0.4515236409857309, 0.0004515236409857309, 4.4294470309509295, 1.5705705649782393, 1.000000488745015],
          uniform: [1000.0000706572049, 1.6012194972425042e-07, 0.001, 1.5707963267948966, 1.000000070657205],
          samples: &[
            Sample { t: 1.019367991845056e-11, uniform: [1.0193679918450543e-14, 1.0, 0.000999999999999995, -9.999999999999967e-11, -9.809999999999918e-07, -9.809999999999903, 9809999.999999952, -0.0004904999999999983, -9.809999999999918e-07, 9.809999999999934e-14, 9.809999999999968e-07],
              classical: [1.019367991845056e-14, 1.0, 9809999.999999853] },
            Sample { t: 3.058103975535168e-05, uniform: [3.013238287304833e-08, 0.9999999954800438, 0.0009566279119002483, -0.00029131261245159086, -2.73382898412736, -8.977493595519233, 9384519.815741437, -1428.8883640750532, -2.73382898412736, 0.8325064044807674, 2.8577767281501067],
              classical: [3.058103975535168e-08, 0.999999995412844, 8620436.566990362] },
            Sample { t: 0.00020387359836901122, uniform: [1.3269728196187717e-07, 0.999999864933461, 0.00026580222883407966, -0.0009640275800758169, -2.5137210653228452, -0.6930845918095433, 2607519.8648623214, -4728.555280271882, -2.5137210653228452, 9.116915408190458, 9.457110560543764],
              classical: [2.0387359836901121e-07, 0.9999997961264017, 877433.0743709174] },
            Sample { t: 0.0030581039755351682, uniform: [1.6012194972423134e-07, 0.9999970125532294, 1.8715245937680328e-16, -0.001, -1.83596562648644e-12, -3.436054823282107e-25, 1.8359656264864401e-06, -4905.0, -1.83596562648644e-12, 9.81, 9.81],
              classical: [3.0581039755351682e-06, 0.999954128440367, 362.7286177382724] },
            Sample { t: 0.040774719673802244, uniform: [1.6012194972425042e-07, 0.9999592959375312, 3.8303391934279094e-177, -0.001, -3.757562748752779e-173, -0.0, 3.757562748752779e-167, -4905.0, -3.757562748752779e-173, 9.81, 9.81],
              classical: [4.077471967380225e-05, 0.9918450560652395, 0.1532798129995078] },
            Sample { t: -0.0001529051987767584, uniform: [-1.1536476506121397e-07, 0.9999999127991671, 0.0004250960349422805, 0.0009051482536448664, 3.7746420991983443, -1.7727321278409924, 4170192.1027837717, 4439.7521841280695, 3.7746420991983443, 8.037267872159008, 8.879504368256141],
              classical: [-1.529051987767584e-07, 0.999999885321101, 1674341.2076829225] },
            Sample { t: 1000.0000706572049, uniform: [1.6012194972425042e-07, 2.804760639735782e-17, 0.0, -0.001, -0.0, -0.0, 0.0, -4905.0, -0.0, 9.81, 9.81],
              classical: [1.000000070657205, -4904999.693147205, 1.0391108825361788e-14] },
          ],
          trajectory: &[[8.006097486212521e-08, 0.9999999646713975], [1.6012194972425042e-07, 0.9999961505748729], [-4.803658491727512e-08, 0.9999999882361336], [3.0581039755351683e-07, 0.9999999989747284], ],
        },
        Case { p: Params { v0: 1000000.0, g: 0.01, h0: 1000000.0, m: 70.0 },
          classical: [14142.13562373095, 14142135623.73095, 1000000.0099999999, 0.00014142135529450047, 14142135670.871403],
          uniform: [14142.135647301177, 14142135600.160725, 1000000.0, 0.00014142135600160724, 14142135647.301176],
          samples: &[
            Sample { t: 10.0, uniform: [9999999.999999983, 999999.5, 999999.999999995, -0.09999999999999967, -9.999999999999918e-10, -0.0099999999999999, 9.99999999999995e-15, -3.499999999999988e-14, -6.999999999999942e-08, 6.999999999999954e-15, 6.999999999999977e-08],
              classical: [10000000.0, 999999.5, 9.99999999999985e-15] },
            Sample { t: 30000000.0, uniform: [29559867598460.414, -4434075992594.032, 956627.9119002483, -291312.6124515909, -0.002786777761597717, -0.009151369618266292, 9.566279119002484e-15, -1.0195941435805683e-07, -0.19507444331184018, 0.059404126721359564, 0.20391882871611364],
              classical: [30000000000000.0, -4499999000000.0, 8.787397112120655e-15] },
            Sample { t: 200000000.0, uniform: [130176033604601.52, -132500273735786.44, 265802.2288340797, -964027.5800758168, -0.0025624067944167634, -0.0007065082485316446, 2.658022288340797e-15, -3.374096530265359e-07, -0.17936847560917346, 0.6505444226027849, 0.6748193060530718],
              classical: [200000000000000.0, -199999999000000.0, 8.944271909999158e-16] },
            Sample { t: 3000000000.0, uniform: [157079632679470.94, -2930685280944005.5, 1.8715245937680338e-07, -1000000.0, -1.8715245937680336e-15, -3.5026043050786036e-28, 1.871524593768034e-27, -3.5e-07, -1.3100672156376235e-13, 0.7000000000000001, 0.7000000000000001],
              classical: [3000000000000000.0, -4.4999999999e+16, 3.6975394264859574e-19] },
            Sample { t: 40000000000.0, uniform: [157079632679489.66, -3.993068528094401e+16, 3.8303391934279797e-168, -1000000.0, -3.8303391934279794e-176, -0.0, 3.8303391934279794e-188, -3.5e-07, -2.6812374353995856e-174, 0.7000000000000001, 0.7000000000000001],
              classical: [4e+16, -7.999999999999001e+18, 1.56248535167694e-22] },
            Sample { t: -150000000.0, uniform: [-113172834525050.9, -85544016101379.67, 425096.03494228044, 905148.2536448664, 0.003847749336593623, -0.0018070663892364852, 4.2509603494228046e-15, 3.1680188877570324e-07, 0.2693424535615536, 0.573505352753446, 0.6336037775514065],
              classical: [-150000000000000.0, -112499999000000.0, 1.7067698345391665e-15] },
            Sample { t: 14142.135647301177, uniform: [14142135600.160725, -1.5915592452565238e-11, 999999.9900000001, -141.42135553020273, -1.414213541159892e-06, -0.009999999800000003, 9.9999999e-15, -4.9497474435570957e-11, -9.899494788119242e-05, 1.3999999860000002e-08, 9.899494887114192e-05],
              classical: [14142135647.301176, -0.0033333333536933706, 9.999999700000006e-15] },
          ],
          trajectory: &[[7071067800.080362, 750000.000625], [14142135600.160725, -4.6221920160404887e-11], [-4242640680.0482173, 910000.000273], [300000000000000.0, -1005790507369.2885], ],
        },
    ];

    /// Checks `got` against the reference `want`, allowing `ULPS × EPS × (1 + cond)` relative to
    /// `scale` (the magnitude the rounding errors are proportional to: `|want|` for a well
    /// scaled quantity, the sum of the magnitudes of the terms for a height that cancels near
    /// the ground). Returns the error relative to `scale`, both in units of `EPS × (1 + cond)`
    /// and plain.
    fn check(what: &str, got: f64, want: f64, scale: f64, cond: f64) -> [f64; 2] {
        let diff = (got - want).abs();
        if scale < f64::MIN_POSITIVE {
            // The reference underflows: allow the subnormal range.
            assert!(
                diff <= f64::MIN_POSITIVE,
                "{what}: got {got:e}, want {want:e}"
            );
            return [0.0, 0.0];
        }
        let err = diff / scale / (EPS * (1.0 + cond));
        assert!(
            got.is_finite() && err <= ULPS,
            "{what}: got {got:e}, want {want:e}, error {err:.2} × EPS × (1 + {cond:.3e})"
        );
        [err, diff / scale]
    }

    fn kinematics_array(k: &Kinematics) -> [f64; 5] {
        [
            k.t_impact,
            k.range,
            k.impact_speed,
            k.impact_angle,
            k.length,
        ]
    }

    fn ln_cosh(u: f64) -> f64 {
        if u.abs() < LN_COSH_SWITCH {
            ln_cosh_small(u)
        } else {
            u.abs() - ln_cosh_deficit(u)
        }
    }

    #[test]
    fn reference_values() {
        let mut worst = [[0.0_f64; 2]; 4];
        for (i, case) in CASES.iter().enumerate() {
            let p = &case.p;
            let l = p.v0 * p.v0 / p.g;
            let names = ["T", "R", "v_R", "alpha", "s"];
            let kc = kinematics_array(&classical::kinematics(p));
            let ku = kinematics_array(&uniform::kinematics(p));
            for j in 0..5 {
                let e = check(
                    &format!("case {i} classical {}", names[j]),
                    kc[j],
                    case.classical[j],
                    case.classical[j].abs(),
                    1.0,
                );
                worst[0] = [worst[0][0].max(e[0]), worst[0][1].max(e[1])];
                let e = check(
                    &format!("case {i} uniform {}", names[j]),
                    ku[j],
                    case.uniform[j],
                    case.uniform[j].abs(),
                    1.0,
                );
                worst[0] = [worst[0][0].max(e[0]), worst[0][1].max(e[1])];
            }
            for s in case.samples {
                let t = s.t;
                let c = (p.g * t / p.v0).abs();
                let x = uniform::position(p, t);
                let v = uniform::velocity(p, t);
                let a = uniform::acceleration(p, t);
                let f = uniform::chetaev_force(p, t);
                let got = [
                    x[0],
                    x[1],
                    v[0],
                    v[1],
                    a[0],
                    a[1],
                    uniform::curvature(p, t),
                    uniform::multiplier(p, t),
                    f[0],
                    f[1],
                    uniform::chetaev_force_magnitude(p, t),
                ];
                // Condition numbers with respect to u (bounds of |u f'(u) / f(u)|).
                let cond = [
                    1.0,
                    1.0,
                    c,
                    1.0,
                    1.0 + c,
                    2.0 * c,
                    c,
                    1.0,
                    1.0 + c,
                    2.0,
                    1.0,
                ];
                let names = [
                    "x", "y", "xd", "yd", "xdd", "ydd", "kappa", "mu", "Phi_x", "Phi_y", "|Phi|",
                ];
                for j in 0..11 {
                    let want = s.uniform[j];
                    let scale = if j == 1 {
                        p.h0 + l * ln_cosh(c)
                    } else {
                        want.abs()
                    };
                    let e = check(
                        &format!("case {i} t = {t:e} uniform {}", names[j]),
                        got[j],
                        want,
                        scale,
                        cond[j],
                    );
                    worst[1] = [worst[1][0].max(e[0]), worst[1][1].max(e[1])];
                }
                let x = classical::position(p, t);
                let got = [x[0], x[1], classical::curvature(p, t)];
                let scale = [
                    s.classical[0].abs(),
                    p.h0 + 0.5 * p.g * t * t,
                    s.classical[2].abs(),
                ];
                let cond = [1.0, 1.0, 3.0];
                for j in 0..3 {
                    let e = check(
                        &format!("case {i} t = {t:e} classical {}", ["x", "y", "kappa"][j]),
                        got[j],
                        s.classical[j],
                        scale[j],
                        cond[j],
                    );
                    worst[2] = [worst[2][0].max(e[0]), worst[2][1].max(e[1])];
                }
            }
            for &[x, want] in case.trajectory {
                let theta = x / l;
                let scale = p.h0 + l * (theta.cos().abs().ln().abs() + (theta * theta.tan()).abs());
                let e = check(
                    &format!("case {i} trajectory y({x:e})"),
                    uniform::trajectory_y(p, x),
                    want,
                    scale,
                    1.0,
                );
                worst[3] = [worst[3][0].max(e[0]), worst[3][1].max(e[1])];
            }
        }
        for (group, [scaled, plain]) in [
            "kinematics",
            "uniform motion",
            "classical motion",
            "trajectory",
        ]
        .iter()
        .zip(worst)
        {
            println!(
                "{group}: largest error {scaled:.3} EPS (1 + cond), largest relative error {plain:.2e}"
            );
        }
    }

    #[test]
    fn paper_table() {
        let t = table(&Params::PAPER);
        assert_eq!(t.classical, classical::kinematics(&Params::PAPER));
        assert_eq!(t.uniform, uniform::kinematics(&Params::PAPER));
        assert_eq!(Params::PAPER.z(), 0.5);
        let c = t.classical;
        assert_relative_eq!(c.t_impact, 1.0, max_relative = 2.0 * EPS);
        assert_relative_eq!(c.range, 10.0, max_relative = 2.0 * EPS);
        assert_relative_eq!(c.impact_speed, 200.0_f64.sqrt(), max_relative = 2.0 * EPS);
        assert_relative_eq!(c.impact_angle_deg(), 45.0, max_relative = 2.0 * EPS);
        let u = t.uniform;
        assert_eq!(u.impact_speed, 10.0);
        assert_relative_eq!(
            u.impact_angle.cos(),
            (-0.5_f64).exp(),
            max_relative = 4.0 * EPS
        );
        assert_relative_eq!(
            u.impact_angle_deg(),
            u.impact_angle * 180.0 / PI,
            max_relative = 2.0 * EPS
        );
        // Section 42.5 and the conclusion: the uniform motion takes longer, lands closer and
        // its trajectory is shorter.
        assert!(u.t_impact > c.t_impact);
        assert!(u.range < c.range);
        assert!(u.length < c.length);
    }

    /// Parameter sets spanning the supported range, used by the identity tests.
    fn parameter_sets() -> Vec<Params> {
        let mut sets: Vec<Params> = CASES.iter().map(|c| c.p).collect();
        for &v0 in &[1e-6, 1e-3, 1.0, 1e3, 1e6] {
            for &h0 in &[1e-6, 1e-2, 1.0, 1e2, 1e6] {
                for &z in &[1e-8, 1e-4, 0.1, 1.0, 10.0, 1e3, 1e6] {
                    sets.push(Params {
                        v0,
                        g: z * v0 * v0 / h0,
                        h0,
                        m: 2.0,
                    });
                }
            }
        }
        sets
    }

    /// Times spanning several scales, both signs, and the impact times.
    fn times(p: &Params) -> Vec<f64> {
        let tau = p.v0 / p.g;
        let mut ts = vec![0.0];
        for &u in &[1e-9, 1e-4, 0.1, 0.7, 1.0, 1.3, 3.0, 20.0, 300.0, 1e5] {
            ts.push(u * tau);
            ts.push(-u * tau);
        }
        ts.push(uniform::kinematics(p).t_impact);
        ts.push(classical::kinematics(p).t_impact);
        ts
    }

    #[test]
    fn uniform_speed_is_constant() {
        for p in parameter_sets() {
            for t in times(&p) {
                let [xd, yd] = uniform::velocity(&p, t);
                assert_relative_eq!(xd.hypot(yd), p.v0, max_relative = 4.0 * EPS);
            }
        }
    }

    #[test]
    fn impact_height_is_zero() {
        for p in parameter_sets() {
            let k = uniform::kinematics(&p);
            let [x, y] = uniform::position(&p, k.t_impact);
            // y(T) cancels h0 against L ln cosh(u) ≈ h0, and T itself is rounded:
            // |ẏ(T)| ≤ v0 makes that rounding worth at most v0 T EPS.
            assert_relative_eq!(y, 0.0, epsilon = 8.0 * EPS * (p.h0 + p.v0 * k.t_impact));
            assert_relative_eq!(x, k.range, max_relative = 8.0 * EPS);
            let [xd, yd] = uniform::velocity(&p, k.t_impact);
            assert_relative_eq!(xd.hypot(yd), k.impact_speed, max_relative = 4.0 * EPS);
            assert_relative_eq!((-yd).atan2(xd), k.impact_angle, max_relative = 8.0 * EPS);
            assert_relative_eq!(k.length, p.v0 * k.t_impact, max_relative = 2.0 * EPS);

            let k = classical::kinematics(&p);
            let [x, y] = classical::position(&p, k.t_impact);
            assert_relative_eq!(y, 0.0, epsilon = 8.0 * EPS * p.h0);
            assert_relative_eq!(x, k.range, max_relative = 2.0 * EPS);
            let [xd, yd] = classical::velocity(&p, k.t_impact);
            assert_relative_eq!(xd.hypot(yd), k.impact_speed, max_relative = 8.0 * EPS);
            assert_relative_eq!((-yd).atan2(xd), k.impact_angle, max_relative = 8.0 * EPS);
        }
    }

    #[test]
    fn trajectory_matches_parametric_motion() {
        for p in parameter_sets() {
            let l = p.v0 * p.v0 / p.g;
            for t in times(&p) {
                let u = p.g * t / p.v0;
                if u.abs() > 20.0 {
                    // x = L gd(u) is within EPS of ±π L/2 and no longer determines y: the slope
                    // −tan θ = −sinh u of (42.37) amplifies its rounding beyond any use.
                    continue;
                }
                let [x, y] = uniform::position(&p, t);
                let theta = x / l;
                // The rounding of x, amplified by the slope dy/dx = −tan θ = −sinh u, plus the
                // cancellation in y.
                let scale = p.h0 + l * (ln_cosh(u) + (theta * u.sinh()).abs());
                assert_relative_eq!(
                    uniform::trajectory_y(&p, x),
                    y,
                    epsilon = 16.0 * EPS * scale,
                    max_relative = 16.0 * EPS
                );
            }
        }
    }

    #[test]
    fn multiplier_and_chetaev_force() {
        for p in parameter_sets() {
            for t in times(&p) {
                let [xd, yd] = uniform::velocity(&p, t);
                let [xdd, ydd] = uniform::acceleration(&p, t);
                let mu = uniform::multiplier(&p, t);
                // (42.40), middle form.
                assert_relative_eq!(
                    mu,
                    p.m * p.g / (2.0 * p.v0 * p.v0) * yd,
                    max_relative = 8.0 * EPS
                );
                // (42.39): Φ = 2 μ (ẋ, ẏ).
                let phi = uniform::chetaev_force(&p, t);
                assert_relative_eq!(phi[0], 2.0 * mu * xd, max_relative = 8.0 * EPS);
                assert_relative_eq!(phi[1], 2.0 * mu * yd, max_relative = 8.0 * EPS);
                // (42.42): |Φ| = 2 v0 |μ| = m g |tanh(g t / v0)|.
                let magnitude = uniform::chetaev_force_magnitude(&p, t);
                assert_relative_eq!(magnitude, phi[0].hypot(phi[1]), max_relative = 8.0 * EPS);
                assert_relative_eq!(magnitude, 2.0 * p.v0 * mu.abs(), max_relative = 8.0 * EPS);
                // Φ opposes the velocity for t > 0 (φ < 0 in (42.41)).
                assert!(phi[0] * xd + phi[1] * yd <= 0.0 || t < 0.0);
                // The deformed equations (42.26): m ẍ = 2 μ ẋ, m ÿ = 2 μ ẏ − m g.
                let mg = p.m * p.g;
                assert_relative_eq!(p.m * xdd, phi[0], max_relative = 8.0 * EPS);
                assert_relative_eq!(p.m * ydd, phi[1] - mg, epsilon = 8.0 * EPS * mg);
                // The reduced equation (42.28): ÿ = −(g / v0²)(v0² − ẏ²).
                assert_relative_eq!(
                    ydd,
                    -p.g * (xd / p.v0) * (xd / p.v0),
                    epsilon = 8.0 * EPS * p.g,
                    max_relative = 8.0 * EPS
                );
            }
        }
    }

    #[test]
    fn curvature_matches_geometric_formula() {
        // (42.14): κ = |ẋ ÿ − ẍ ẏ| / (ẋ² + ẏ²)^(3/2), for both motions.
        for p in parameter_sets() {
            for t in times(&p) {
                let [xd, yd] = uniform::velocity(&p, t);
                let [xdd, ydd] = uniform::acceleration(&p, t);
                let k = (xd * ydd - xdd * yd).abs() / xd.hypot(yd).powi(3);
                // Both products carry sech; their sum has no cancellation (same signs).
                assert_relative_eq!(uniform::curvature(&p, t), k, max_relative = 16.0 * EPS);

                let [xd, yd] = classical::velocity(&p, t);
                let [xdd, ydd] = classical::acceleration(&p, t);
                let v = xd.hypot(yd);
                let k = (xd * ydd - xdd * yd).abs() / v / v / v;
                assert_relative_eq!(classical::curvature(&p, t), k, max_relative = 16.0 * EPS);
            }
        }
    }

    #[test]
    fn symmetry_in_time() {
        for p in parameter_sets() {
            for t in times(&p) {
                let [x, y] = uniform::position(&p, t);
                let [xm, ym] = uniform::position(&p, -t);
                assert_eq!((xm, ym), (-x, y));
                let [xd, yd] = uniform::velocity(&p, t);
                let [xdm, ydm] = uniform::velocity(&p, -t);
                assert_eq!((xdm, ydm), (xd, -yd));
                let [xdd, ydd] = uniform::acceleration(&p, t);
                let [xddm, yddm] = uniform::acceleration(&p, -t);
                assert_eq!((xddm, yddm), (-xdd, ydd));
                assert_eq!(uniform::curvature(&p, -t), uniform::curvature(&p, t));
                assert_eq!(uniform::multiplier(&p, -t), -uniform::multiplier(&p, t));
                assert_eq!(
                    uniform::chetaev_force_magnitude(&p, -t),
                    uniform::chetaev_force_magnitude(&p, t)
                );
                assert_eq!(uniform::trajectory_y(&p, -x), uniform::trajectory_y(&p, x));
                let [x, y] = classical::position(&p, t);
                let [xm, ym] = classical::position(&p, -t);
                assert_eq!((xm, ym), (-x, y));
                assert_eq!(classical::curvature(&p, -t), classical::curvature(&p, t));
            }
        }
    }

    #[test]
    fn large_z_limits() {
        // For z ≫ 1: arccosh e^z = z + ln 2 − e^(−2z)/4 + …, arccos e^(−z) = π/2 − e^(−z) + …;
        // from z = 40 on the corrections are below EPS.
        for &z in &[40.0, 1e3, 1e6, 1e8] {
            for &v0 in &[1e-3, 1.0, 1e3] {
                let h0 = 1.0;
                let p = Params {
                    v0,
                    g: z * v0 * v0 / h0,
                    h0,
                    m: 1.0,
                };
                let k = uniform::kinematics(&p);
                let tau = p.v0 / p.g;
                assert_relative_eq!(k.t_impact, tau * (p.z() + LN_2), max_relative = 4.0 * EPS);
                let l = p.v0 * p.v0 / p.g;
                assert_relative_eq!(k.range, FRAC_PI_2 * l, max_relative = 4.0 * EPS);
                assert_relative_eq!(k.impact_angle, FRAC_PI_2, max_relative = 2.0 * EPS);
            }
        }
    }

    #[test]
    fn small_z_agrees_with_classical() {
        // For z ≪ 1: T_u / T_c = 1 + z/6 + z²/120 + …, R_u / R_c = 1 − z/6 + z²/120 + ….
        for &z in &[1e-10, 1e-8, 1e-6, 1e-4, 1e-3] {
            for &v0 in &[1e-3, 1.0, 1e3] {
                let h0 = 0.5;
                let p = Params {
                    v0,
                    g: z * v0 * v0 / h0,
                    h0,
                    m: 1.0,
                };
                let z = p.z();
                let t = table(&p);
                let rt = t.uniform.t_impact / t.classical.t_impact;
                let rr = t.uniform.range / t.classical.range;
                assert!((rt - 1.0).abs() <= z && (rr - 1.0).abs() <= z);
                let tol = z * z / 60.0 + 8.0 * EPS;
                assert_relative_eq!(rt, 1.0 + z / 6.0, epsilon = tol);
                assert_relative_eq!(rr, 1.0 - z / 6.0, epsilon = tol);
            }
        }
    }

    #[test]
    fn finite_for_extreme_times() {
        let sets = [
            Params {
                v0: 1e-3,
                g: 10.0,
                h0: 1.0,
                m: 1.0,
            },
            Params {
                v0: 1e-6,
                g: 1e6,
                h0: 1e-6,
                m: 1.0,
            },
            Params {
                v0: 1.0,
                g: 1e-6,
                h0: 1e6,
                m: 1.0,
            },
        ];
        for p in sets {
            for &t in &[
                1e6,
                -1e6,
                1e300,
                -1e300,
                f64::MAX,
                -f64::MAX,
                f64::MIN_POSITIVE,
            ] {
                let mut values = Vec::new();
                values.extend(uniform::position(&p, t));
                values.extend(uniform::velocity(&p, t));
                values.extend(uniform::acceleration(&p, t));
                values.extend(uniform::chetaev_force(&p, t));
                values.push(uniform::curvature(&p, t));
                values.push(uniform::multiplier(&p, t));
                values.push(uniform::chetaev_force_magnitude(&p, t));
                values.extend(classical::acceleration(&p, t));
                values.push(classical::curvature(&p, t));
                // −g t and h0 − g t²/2 themselves exceed f64::MAX for the largest t.
                if t.abs() <= 1e300 {
                    values.extend(classical::velocity(&p, t));
                }
                if t.abs() <= 1e6 {
                    values.extend(classical::position(&p, t));
                }
                assert!(
                    values.iter().all(|v| v.is_finite()),
                    "t = {t:e}, {p:?}: {values:?}"
                );
            }
            // t = 1e6 with g / v0 = 1e4: sech underflows, y = h0 + (v0²/g) ln 2 − v0 t.
            let t = 1e6;
            if p.g / p.v0 == 1e4 {
                assert_eq!(uniform::velocity(&p, t), [0.0, -p.v0]);
                let l = p.v0 * p.v0 / p.g;
                assert_relative_eq!(
                    uniform::position(&p, t)[1],
                    p.h0 + l * LN_2 - p.v0 * t,
                    max_relative = 4.0 * EPS
                );
            }
        }
        for &x in &[1e6, -1e6, 1e12] {
            assert!(uniform::trajectory_y(&Params::PAPER, x).is_finite());
        }
    }

    /// The derivatives of `uniform::impact` in `h0` against their own closed forms,
    /// `∂T/∂h0 = 1/(v0 √(1 − e^(−2z)))` and `∂R/∂h0 = 1/√(e^(2z) − 1)`, written with `expm1`:
    /// from the paper's `z = 0.5` down to `z = 5e-15`, where `arccosh(e^z)` of dual numbers
    /// would have lost the leading digits, and up to `z = 2e4`, where `e^(−z)` underflows.
    #[test]
    fn impact_derivatives_are_accurate_for_every_z() {
        use chetaev::num_dual::Dual64;
        for v0 in [10.0, 1e2, 1e4, 1e8, 1.58, 0.05] {
            let (g, h0) = (10.0, 5.0);
            let z: f64 = g * h0 / (v0 * v0);
            let (t, r) = uniform::impact(Dual64::from(v0), Dual64::from(g), Dual64::new(h0, 1.0));
            let dt = 1.0 / (v0 * (-(-2.0 * z).exp_m1()).sqrt());
            let dr = 1.0 / (2.0 * z).exp_m1().sqrt();
            assert_relative_eq!(t.eps, dt, max_relative = 16.0 * EPS);
            assert_relative_eq!(r.eps, dr, max_relative = 16.0 * EPS);
            let k = uniform::kinematics(&Params { v0, g, h0, m: 1.0 });
            assert_relative_eq!(t.re, k.t_impact, max_relative = 4.0 * EPS);
            assert_relative_eq!(r.re, k.range, max_relative = 4.0 * EPS);
        }
    }
}
