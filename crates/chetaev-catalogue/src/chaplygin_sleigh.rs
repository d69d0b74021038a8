//! The Chaplygin sleigh: a rigid body on a horizontal plane, supported at one point by a knife edge
//! that cannot move sideways.
//!
//! Coordinates `q = (x, y, θ)`: the contact point of the blade and the heading `θ` of the blade.
//! The centre of mass lies on the blade's line, a distance `a` ahead of the contact point, at
//! `(x + a cos θ, y + a sin θ)`; `m` is the mass and `I` the moment of inertia about the centre of
//! mass.
//!
//! ```text
//! L = ½ m [(ẋ − a sin θ · θ̇)² + (ẏ + a cos θ · θ̇)²] + ½ I θ̇²
//! f = −ẋ sin θ + ẏ cos θ = 0                      (no velocity across the blade)
//! ```
//!
//! Chetaev's equations in Newton form, `d/dt ∂L/∂q̇ − ∂L/∂q = μ (−sin θ, cos θ, 0)`: `μ` is the
//! sideways force of the plane on the blade. In the body velocities `u = ẋ cos θ + ẏ sin θ`
//! (forward speed of the contact point) and `ω = θ̇` they reduce to
//!
//! ```text
//! u̇ = a ω²,    (I + m a²) ω̇ = −m a u ω,    μ = m I u ω / (I + m a²).
//! ```
//!
//! **Reference** (closed form of the body velocities, energy): the energy
//! `E = ½ m u² + ½ (I + m a²) ω²` is conserved (the constraint is linear and homogeneous), so with
//! `V = √(2E/m)` the speed tends to its limit along a `tanh` law and the turning rate dies out
//! along a `sech` law:
//!
//! ```text
//! u(t) = V tanh(c V t + s0),                 c = m a / (I + m a²),   tanh s0 = u0 / V,
//! ω(t) = ω0 cosh s0 / cosh(c V t + s0),
//! θ(t) = θ0 + (ω0 cosh s0 / c V) [gd(c V t + s0) − gd(s0)]        (gd: Gudermannian),
//! ```
//!
//! so the sleigh turns through a finite total angle and ends moving straight ahead at speed `V`
//! (`a > 0`; backwards for `a < 0`). The position `(x, y)` is a quadrature of `u (cos θ, sin θ)` and
//! is checked through `u`, `θ` and the constraint. Source: Bloch §1.7 (see [`SOURCES`]).

use chetaev::model::Fixed;
use chetaev::prelude::*;

use crate::error::{check, finite, positive, Error};
use crate::reference::{works, Check, Entry, Kind, Reference, Source};
use crate::special::turning;

/// Where the reduced equations and their solution come from.
pub const SOURCES: &[Source] = &[
    Source {
        work: works::BLOCH,
        location: "§1.7 The Chaplygin Sleigh",
    },
    Source {
        work: works::NEIMARK_FUFAEV,
        location: "Chaplygin's sleigh (Chapter III)",
    },
];

/// Parameters and initial state of the sleigh (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    /// Mass `m`, > 0.
    pub m: f64,
    /// Moment of inertia `I` about the centre of mass, > 0.
    pub inertia: f64,
    /// Distance `a` from the contact point to the centre of mass along the blade, non-zero
    /// (negative: the centre of mass behind the blade).
    pub a: f64,
    /// Initial contact point `(x0, y0)`.
    pub position: [f64; 2],
    /// Initial heading `θ0`.
    pub theta0: f64,
    /// Initial forward speed `u0` of the contact point.
    pub u0: f64,
    /// Initial turning rate `ω0 = θ̇(0)`.
    pub omega0: f64,
}

impl Default for Params {
    /// `m = 1 kg`, `I = 0.1 kg m²`, `a = 0.5 m`, from the origin heading along `x` with
    /// `u0 = 0.2 m/s`, `ω0 = 3 rad/s`: `V ≈ 1.79 m/s`, `c V ≈ 2.55 /s`.
    fn default() -> Self {
        Self {
            m: 1.0,
            inertia: 0.1,
            a: 0.5,
            position: [0.0, 0.0],
            theta0: 0.0,
            u0: 0.2,
            omega0: 3.0,
        }
    }
}

impl Params {
    fn validate(&self) -> Result<(), Error> {
        positive("m", self.m)?;
        positive("inertia", self.inertia)?;
        check(
            "a",
            self.a,
            |a| a != 0.0,
            "must be finite and non-zero (with a = 0 the sleigh moves uniformly)",
        )?;
        finite("position[0]", self.position[0])?;
        finite("position[1]", self.position[1])?;
        finite("theta0", self.theta0)?;
        finite("u0", self.u0)?;
        finite("omega0", self.omega0)?;
        Ok(())
    }

    /// `I + m a²`, the moment of inertia about the contact point.
    fn i_contact(&self) -> f64 {
        self.inertia + self.m * self.a * self.a
    }
}

/// The Chaplygin sleigh as a `chetaev` model: `N = 3` coordinates `(x, y, θ)`, `K = 1` constraint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChaplyginSleigh {
    /// Mass.
    pub m: f64,
    /// Moment of inertia about the centre of mass.
    pub inertia: f64,
    /// Distance from the contact point to the centre of mass.
    pub a: f64,
}

impl Lagrangian<3> for ChaplyginSleigh {
    /// `L = ½ m |v_c|² + ½ I θ̇²` with `v_c = (ẋ − a sin θ θ̇, ẏ + a cos θ θ̇)`.
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 3>, qd: &SVector<R, 3>) -> R {
        let vx = qd[0] - q[2].sin() * qd[2] * self.a;
        let vy = qd[1] + q[2].cos() * qd[2] * self.a;
        (vx * vx + vy * vy) * (0.5 * self.m) + qd[2] * qd[2] * (0.5 * self.inertia)
    }
}

impl Constraints<3, 1> for ChaplyginSleigh {
    /// `f = −ẋ sin θ + ẏ cos θ`.
    fn constraints<R: Real>(&self, _t: R, q: &SVector<R, 3>, qd: &SVector<R, 3>) -> SVector<R, 1> {
        SVector::from([qd[1] * q[2].cos() - qd[0] * q[2].sin()])
    }
}

/// The problem: the contact point at `(x0, y0)`, heading `θ0`, moving forward at `u0` and turning
/// at `ω0`.
pub fn problem(p: &Params) -> Result<Problem<Fixed<ChaplyginSleigh, 3, 1>>, Error> {
    p.validate()?;
    let model = ChaplyginSleigh {
        m: p.m,
        inertia: p.inertia,
        a: p.a,
    };
    let q0 = SVector::from([p.position[0], p.position[1], p.theta0]);
    let qd0 = SVector::from([p.u0 * p.theta0.cos(), p.u0 * p.theta0.sin(), p.omega0]);
    Ok(Problem::new(model, 0.0, q0, qd0)?)
}

/// The problem with its closed form.
pub fn entry(p: &Params) -> Result<Entry<ChaplyginSleigh, ClosedForm, 3, 1>, Error> {
    Ok(Entry {
        problem: problem(p)?,
        reference: ClosedForm::new(p)?,
    })
}

/// The closed form of the body velocities `u, ω`, the heading `θ` and the multiplier.
///
/// Evaluated without overflow, underflow or cancellation: with `β = u0 / V`, `τ = c V t`,
/// `cosh τ + β sinh τ = ½ e^|τ| [(1 ± β) + (1 ∓ β) e^(−2|τ|)]` (upper signs for `τ ≥ 0`), and
/// `1 ± β` formed in logarithms as `ln((V ± u0)/V)` or `ln((I + m a²) ω0² / (m V (V ∓ u0)))`,
/// whichever does not cancel, so that neither underflows where `ω0` is tiny (`1e-160`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosedForm {
    p: Params,
    /// The limit speed `V = √(u0² + (I + m a²) ω0² / m)`.
    v: f64,
    /// `c = m a / (I + m a²)`.
    c: f64,
    /// `ln(1 + β)`, `ln(1 − β)` with `β = u0 / V`.
    ln_plus: f64,
    ln_minus: f64,
}

impl ClosedForm {
    /// The closed form for these parameters.
    pub fn new(p: &Params) -> Result<Self, Error> {
        p.validate()?;
        // √((I + m a²)/m) |ω0|, and V from it without squaring a tiny ω0.
        let across = p.omega0.abs() * (p.i_contact() / p.m).sqrt();
        let v = p.u0.hypot(across);
        let (ln_plus, ln_minus) = if v == 0.0 {
            (0.0, 0.0)
        } else {
            // (1 + β)(1 − β) = (across / V)²: the factor that would cancel is that over the other.
            let ln_product = 2.0 * (across.ln() - v.ln());
            if p.u0 >= 0.0 {
                let ln_plus = (p.u0 / v).ln_1p();
                (ln_plus, ln_product - ln_plus)
            } else {
                let ln_minus = (-p.u0 / v).ln_1p();
                (ln_product - ln_minus, ln_minus)
            }
        };
        Ok(Self {
            p: *p,
            v,
            c: p.m * p.a / p.i_contact(),
            ln_plus,
            ln_minus,
        })
    }

    /// The limit speed `V = √(2E/m)`.
    pub fn limit_speed(&self) -> f64 {
        self.v
    }

    /// `(tanh(|τ| ± s0), cosh s0 / cosh(|τ| ± s0), ±1)` with the upper signs for `τ ≥ 0`,
    /// `τ = c V t`: `u = ±V tanh(|τ| ± s0)` and `ω = ω0 cosh s0 / cosh(τ + s0)`.
    fn turned(&self, t: f64) -> (f64, f64, f64) {
        let tau = self.c * self.v * t;
        let (la, lb, sign) = if tau >= 0.0 {
            (self.ln_plus, self.ln_minus, 1.0)
        } else {
            (self.ln_minus, self.ln_plus, -1.0)
        };
        let (along, rate) = turning(la, lb, tau.abs());
        (along, rate, sign)
    }

    /// The forward speed `u(t) = V tanh(c V t + s0)`.
    pub fn forward_speed(&self, t: f64) -> f64 {
        if self.p.omega0 == 0.0 {
            return self.p.u0;
        }
        let (along, _, sign) = self.turned(t);
        sign * self.v * along
    }

    /// The turning rate `ω(t) = ω0 / (cosh τ + β sinh τ)`, `τ = c V t`.
    pub fn turning_rate(&self, t: f64) -> f64 {
        if self.p.omega0 == 0.0 {
            return 0.0;
        }
        self.p.omega0 * self.turned(t).1
    }

    /// The heading `θ(t) = θ0 + (ω0 cosh s0 / c V) [gd(c V t + s0) − gd(s0)]`.
    pub fn heading(&self, t: f64) -> f64 {
        let p = &self.p;
        if p.omega0 == 0.0 {
            return p.theta0;
        }
        // ω0 cosh s0 / V = ±√(m / (I + m a²)) (cosh s0 = V / √(V² − u0²)), and
        // s0 = ½ ln((1 + β)/(1 − β)).
        let scale = p.omega0.signum() * (p.m / p.i_contact()).sqrt() / self.c;
        let s0 = 0.5 * (self.ln_plus - self.ln_minus);
        let tau = self.c * self.v * t;
        // gd(τ + s0) − gd(s0) = 2 arctan(sinh(τ/2) / cosh(s0 + τ/2)) (the difference of the
        // arctangents of tanh((τ + s0)/2) and tanh(s0/2)): no cancellation where τ is small, as
        // for a small `a`, where the difference of the two values would lose all of θ − θ0 − ω0 t.
        // The quotient as ± e^(|x| − |y|) (1 − e^(−2|x|)) / (1 + e^(−2|y|)), which overflows
        // nowhere.
        let (x, y) = (0.5 * tau, s0 + 0.5 * tau);
        let quotient = x.signum() * (x.abs() - y.abs()).exp() * -(-2.0 * x.abs()).exp_m1()
            / (1.0 + (-2.0 * y.abs()).exp());
        p.theta0 + scale * 2.0 * quotient.atan()
    }

    /// The body accelerations `(u̇, ω̇) = (a ω², −m a u ω / (I + m a²))` at `t` (the reduced
    /// equations, evaluated on the closed form).
    pub fn body_accelerations(&self, t: f64) -> (f64, f64) {
        let p = &self.p;
        let (u, w) = (self.forward_speed(t), self.turning_rate(t));
        (p.a * w * w, -p.m * p.a * u * w / p.i_contact())
    }

    /// The multiplier `μ = m I u ω / (I + m a²)`: the sideways force on the blade.
    pub fn multiplier(&self, t: f64) -> f64 {
        let p = &self.p;
        p.m * p.inertia * self.forward_speed(t) * self.turning_rate(t) / p.i_contact()
    }

    /// The energy `E = ½ m |v_c|² + ½ I θ̇²` of a state (the Lagrangian itself).
    pub fn energy(&self, q: &SVector<f64, 3>, qd: &SVector<f64, 3>) -> f64 {
        let p = &self.p;
        let vx = qd[0] - p.a * q[2].sin() * qd[2];
        let vy = qd[1] + p.a * q[2].cos() * qd[2];
        0.5 * p.m * (vx * vx + vy * vy) + 0.5 * p.inertia * qd[2] * qd[2]
    }
}

/// The body velocities `(u, ω)` of a state: `u = ẋ cos θ + ẏ sin θ`, `ω = θ̇`.
pub fn body_velocities(q: &SVector<f64, 3>, qd: &SVector<f64, 3>) -> (f64, f64) {
    (qd[0] * q[2].cos() + qd[1] * q[2].sin(), qd[2])
}

impl Reference<3, 1> for ClosedForm {
    fn sources(&self) -> &[Source] {
        SOURCES
    }

    fn checks(
        &self,
        t: f64,
        q: &SVector<f64, 3>,
        qd: &SVector<f64, 3>,
        mu: Option<&SVector<f64, 1>>,
    ) -> Vec<Check> {
        let p = &self.p;
        let (u, w) = body_velocities(q, qd);
        let e0 = 0.5 * p.m * self.v * self.v;
        // ω is measured against its largest value, V √(m / (I + m a²)).
        let w_scale = self.v * (p.m / p.i_contact()).sqrt();
        let theta = self.heading(t);
        let mut out = vec![
            Check::new("u", Kind::Velocity, u, self.forward_speed(t), self.v),
            Check::new("ω", Kind::Velocity, w, self.turning_rate(t), w_scale),
            Check::new("θ", Kind::Position, q[2], theta, theta.abs().max(1.0)),
            Check::new("E", Kind::Invariant, self.energy(q, qd), e0, e0),
        ];
        if let Some(mu) = mu {
            let scale = p.m * p.inertia * self.v * w_scale / p.i_contact();
            out.push(Check::multiplier(mu[0], self.multiplier(t), scale));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_form_satisfies_the_reduced_equations_and_stays_finite() {
        for p in [
            Params::default(),
            // Nearly all the energy in backward motion: 1 + β ≈ 1e-12, formed without cancellation.
            Params {
                u0: -1.0,
                omega0: 1e-6,
                ..Params::default()
            },
            Params {
                a: -0.4,
                ..Params::default()
            },
        ] {
            let cf = ClosedForm::new(&p).expect("valid");
            let (v, ic) = (cf.limit_speed(), p.i_contact());
            for t in [0.0, 0.3, 2.0, 40.0, 1e4, -0.5] {
                let (u, w) = (cf.forward_speed(t), cf.turning_rate(t));
                assert!(u.is_finite() && w.is_finite() && cf.heading(t).is_finite());
                // Energy: m u² + (I + m a²) ω² = m V².
                let e = p.m * u * u + ic * w * w;
                assert!(
                    (e - p.m * v * v).abs() <= 1e-14 * p.m * v * v,
                    "{p:?} t = {t}"
                );
                // u̇ = a ω² by a central difference (h = 1e-5 against |ü| ≲ 1e2: error ≲ 1e-8).
                let h = 1e-5;
                let du = (cf.forward_speed(t + h) - cf.forward_speed(t - h)) / (2.0 * h);
                assert!(
                    (du - p.a * w * w).abs() <= 1e-8 * (1.0 + v * v),
                    "{p:?} t = {t}"
                );
                let dth = (cf.heading(t + h) - cf.heading(t - h)) / (2.0 * h);
                assert!(
                    (dth - w).abs() <= 1e-8 * (1.0 + p.omega0.abs()),
                    "{p:?} t = {t}"
                );
            }
            assert!((cf.forward_speed(0.0) - p.u0).abs() <= 2.0 * f64::EPSILON * v);
        }
        // The heading is the integral of the turning rate (by Gauss–Legendre quadrature), also
        // for a blade offset `a` so small that θ − θ0 − ω0 t is a rounding of θ itself.
        let tiny = |u0| Params {
            u0,
            omega0: 1e-160,
            ..Params::default()
        };
        let cases = [0.5, -0.4, 1e-3, 1e-9, 1e-12, -1e-12, 1e-14].map(|a| Params {
            a,
            theta0: 0.3,
            ..Params::default()
        });
        // And a turning rate whose square underflows, from nearly the limit speed ahead or
        // behind: the turn comes after c V |t| ≈ 368, and θ turns by 3.7 rad.
        for (p, times) in cases
            .into_iter()
            .map(|p| (p, &[0.5, 10.0, -3.0][..]))
            .chain([
                (tiny(1.0), &[-300.0, 300.0][..]),
                (tiny(-1.0), &[300.0, -300.0][..]),
            ])
        {
            let cf = ClosedForm::new(&p).expect("valid");
            for &t in times {
                let turned = crate::special::integrate(|s| cf.turning_rate(s), 0.0, t, 1e-15);
                let th = cf.heading(t) - p.theta0;
                assert!(
                    (th - turned).abs() <= 1e-13 * turned.abs(),
                    "{p:?}, t = {t}: {th} against {turned}"
                );
            }
        }
        // Without turning the sleigh moves uniformly.
        let p = Params {
            omega0: 0.0,
            u0: -0.7,
            ..Params::default()
        };
        let cf = ClosedForm::new(&p).expect("valid");
        assert_eq!(
            (cf.forward_speed(5.0), cf.turning_rate(5.0), cf.heading(5.0)),
            (-0.7, 0.0, 0.0)
        );
    }
}
