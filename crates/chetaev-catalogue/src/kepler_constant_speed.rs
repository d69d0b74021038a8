//! A particle held at constant speed in a central (Kepler) field: the isotachytonic constraint of
//! the uniform projectile, with the homogeneous field replaced by an attracting centre.
//!
//! Coordinates `q = (x, y, z)`, `r = |q|`; `k` is the strength of the centre (`G M`).
//!
//! ```text
//! L = ½ m |q̇|² + k m / r
//! f = |q̇|² − v0² = 0                       (constant speed v0)
//! ```
//!
//! Chetaev's equations in Newton form (`J = 2 q̇ᵀ`, `Φ = 2 μ q̇`):
//!
//! ```text
//! m q̈ = −k m q / r³ + 2 μ q̇,          μ = k m ṙ / (2 v0² r²)      (from q̇·q̈ = 0).
//! ```
//!
//! **Reference** (an exact invariant, derived here). Let `h = q × q̇` and `λ = k / v0²`. The
//! central force has no moment about the centre, so
//! `ḣ = q × q̈ = (2μ/m) h = λ (ṙ / r²) h = −λ (d/dt (1/r)) h`, and therefore
//!
//! ```text
//! C = (q × q̇) · exp(λ / r)        is constant along every motion.
//! ```
//!
//! Its direction makes the motion planar; its magnitude gives the orbit by quadratures. With
//! `u = 1/r`, `b = |C| / v0` and `sin ψ = b u e^(−λu)`:
//!
//! ```text
//! ṙ = ± v0 cos ψ,      dθ = dψ / (1 − λ u),      dt = dψ / (v0 u sin ψ (1 − λ u)),
//! ```
//!
//! and the radial equation `r̈ = θ̇² (r − λ)` shows that no orbit is bound except the unstable
//! circle `r = λ`: outside it (`r > λ`) the particle comes in from infinity, turns at the periapsis
//! `r_p` (the root of `r e^(λ/r) = b` above `λ`) and leaves; inside it falls into the centre. For
//! such scattering orbits [`Invariant`] also gives `q(t)` and `q̇(t)` by quadrature. The proof is
//! in `docs/catalogue/kepler_constant_speed.md`.

use chetaev::model::Fixed;
use chetaev::prelude::*;

use crate::error::{check, positive, Error};
use crate::reference::{Check, Entry, Kind, Reference, Source};
use crate::special::integrate;

/// Where the invariant comes from.
pub const SOURCES: &[Source] = &[Source {
    work: "derived in docs/catalogue/kepler_constant_speed.md from the Chetaev equations (Newton \
           form) of L = ½ m |q̇|² + k m / r under f = |q̇|² − v0²",
    location: "the invariant C = (q × q̇) exp(k / (v0² r)) and the orbit quadratures",
}];

/// Relative tolerance of the quadratures of the orbit.
const QUADRATURE_TOL: f64 = 1e-14;

/// Parameters and initial state (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    /// Mass `m`, > 0 (enters only `μ` and the energy).
    pub m: f64,
    /// Strength `k` of the centre (`G M`), ≥ 0.
    pub k: f64,
    /// Initial position, not the centre.
    pub q0: [f64; 3],
    /// Initial velocity, not zero; its magnitude is the constant speed `v0`.
    pub qd0: [f64; 3],
}

impl Default for Params {
    /// `m = 1`, `k = 1`, `v0 = 1` (so `λ = 1`): incoming from `r0 = 20` in an inclined plane, aimed
    /// to turn at the periapsis `r_p = 1.2` ([`Params::incoming`]).
    fn default() -> Self {
        Self::incoming(1.0, 1.0, 1.0, 20.0, 1.2)
    }
}

impl Params {
    /// A particle at distance `r0` on the `x` axis, coming in at speed `v0` in the plane spanned
    /// by the `x` axis and `(0, cos 30°, sin 30°)`, aimed so that its periapsis is `periapsis`
    /// (`λ < periapsis ≤ r0`, `λ = k / v0²`; otherwise the returned state falls into the centre
    /// and [`problem`] still accepts it, but [`Invariant::orbit`] is `None`).
    pub fn incoming(m: f64, k: f64, v0: f64, r0: f64, periapsis: f64) -> Self {
        let lambda = k / (v0 * v0);
        // |C| = r0 v0 sin χ e^(λ/r0) = v0 r_p e^(λ/r_p), χ the angle between q0 and −q̇0.
        let sin_chi = ((periapsis / r0) * (lambda / periapsis - lambda / r0).exp()).min(1.0);
        let cos_chi = (1.0 - sin_chi * sin_chi).sqrt();
        let (c30, s30) = (0.75f64.sqrt(), 0.5);
        Self {
            m,
            k,
            q0: [r0, 0.0, 0.0],
            qd0: [-v0 * cos_chi, v0 * sin_chi * c30, v0 * sin_chi * s30],
        }
    }

    fn validate(&self) -> Result<(), Error> {
        positive("m", self.m)?;
        check("k", self.k, |k| k >= 0.0, "must be finite and ≥ 0")?;
        for (name, v) in [
            ("q0[0]", self.q0[0]),
            ("q0[1]", self.q0[1]),
            ("q0[2]", self.q0[2]),
            ("qd0[0]", self.qd0[0]),
            ("qd0[1]", self.qd0[1]),
            ("qd0[2]", self.qd0[2]),
        ] {
            check(name, v, |_| true, "must be finite")?;
        }
        let q0 = SVector::from(self.q0);
        let qd0 = SVector::from(self.qd0);
        positive("|q0| (distance from the centre)", q0.norm())?;
        positive("|qd0| (the speed v0)", qd0.norm())?;
        Ok(())
    }

    /// The constant speed `v0 = |q̇0|`.
    pub fn v0(&self) -> f64 {
        SVector::from(self.qd0).norm()
    }
}

/// The particle at constant speed in the central field as a `chetaev` model: `N = 3`, `K = 1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConstantSpeedKepler {
    /// Mass.
    pub m: f64,
    /// Strength of the centre.
    pub k: f64,
    /// The constant speed.
    pub v0: f64,
}

impl Lagrangian<3> for ConstantSpeedKepler {
    /// `L = ½ m |q̇|² + k m / |q|`.
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 3>, qd: &SVector<R, 3>) -> R {
        qd.dot(qd) * (0.5 * self.m) + q.dot(q).sqrt().recip() * (self.k * self.m)
    }
}

impl Constraints<3, 1> for ConstantSpeedKepler {
    /// `f = |q̇|² − v0²`.
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 3>, qd: &SVector<R, 3>) -> SVector<R, 1> {
        SVector::from([qd.dot(qd) - self.v0 * self.v0])
    }
}

/// The problem, with `v0 = |q̇0|`.
pub fn problem(p: &Params) -> Result<Problem<Fixed<ConstantSpeedKepler, 3, 1>>, Error> {
    p.validate()?;
    let model = ConstantSpeedKepler {
        m: p.m,
        k: p.k,
        v0: p.v0(),
    };
    Ok(Problem::new(
        model,
        0.0,
        SVector::from(p.q0),
        SVector::from(p.qd0),
    )?)
}

/// The problem with its invariant.
pub fn entry(p: &Params) -> Result<Entry<ConstantSpeedKepler, Invariant, 3, 1>, Error> {
    Ok(Entry {
        problem: problem(p)?,
        reference: Invariant::new(p)?,
    })
}

/// `C = (q × q̇) exp(λ / |q|)` of a state, `λ = k / v0²`.
pub fn invariant(lambda: f64, q: &SVector<f64, 3>, qd: &SVector<f64, 3>) -> SVector<f64, 3> {
    q.cross(qd) * (lambda / q.norm()).exp()
}

/// The multiplier the Chetaev equations give at a state, `μ = k m (q·q̇) / (2 v0² r³)`.
pub fn multiplier_at(p: &Params, q: &SVector<f64, 3>, qd: &SVector<f64, 3>) -> f64 {
    let r = q.norm();
    let v0 = p.v0();
    p.k * p.m * q.dot(qd) / (2.0 * v0 * v0 * r * r * r)
}

/// The reference: the invariant `C`, and for scattering orbits (outside the circle `r = λ`) the
/// motion itself by quadrature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Invariant {
    p: Params,
    lambda: f64,
    c: SVector<f64, 3>,
    orbit: Option<Orbit>,
}

/// A scattering orbit: periapsis time, direction and radius, and the plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    /// Time of the periapsis.
    pub t_periapsis: f64,
    /// Periapsis distance `r_p`, the root of `r e^(λ/r) = |C|/v0` above `λ`.
    pub r_periapsis: f64,
    /// Unit vector towards the periapsis.
    pub p_hat: SVector<f64, 3>,
    /// Unit normal of the plane, along `C`.
    pub n_hat: SVector<f64, 3>,
    /// The total angle swept from infinity to infinity, `2 ∫₀^(π/2) dψ / (1 − λ u(ψ))`.
    pub total_angle: f64,
}

impl Invariant {
    /// The invariant of the initial state, and the orbit where the state is on a scattering one.
    pub fn new(p: &Params) -> Result<Self, Error> {
        p.validate()?;
        let (q0, qd0) = (SVector::from(p.q0), SVector::from(p.qd0));
        let v0 = p.v0();
        let lambda = p.k / (v0 * v0);
        let c = invariant(lambda, &q0, &qd0);
        let mut me = Self {
            p: *p,
            lambda,
            c,
            orbit: None,
        };
        me.orbit = me.scattering_orbit(&q0, &qd0);
        Ok(me)
    }

    /// `λ = k / v0²`, the radius of the circular orbit.
    pub fn lambda(&self) -> f64 {
        self.lambda
    }

    /// The invariant `C` of the initial state.
    pub fn value(&self) -> SVector<f64, 3> {
        self.c
    }

    /// The scattering orbit, if the initial state is on one (`r0 > λ` and
    /// `|C|/v0 > λ e`, so that the periapsis exists).
    pub fn orbit(&self) -> Option<&Orbit> {
        self.orbit.as_ref()
    }

    /// `b = |C| / v0`.
    fn b(&self) -> f64 {
        self.c.norm() / self.p.v0()
    }

    /// `u ≤ 1/λ` with `b u e^(−λu) = s`, `0 < s ≤ 1`: Newton's method on the concave, increasing
    /// `ln b + ln u − λ u − ln s`, which climbs monotonically to the root from `u = s/b`.
    fn u_of(&self, s: f64) -> f64 {
        let (b, lambda) = (self.b(), self.lambda);
        let target = (s / b).ln();
        let mut u = s / b;
        for _ in 0..200 {
            let g = u.ln() - lambda * u - target;
            let step = g / (1.0 / u - lambda);
            u -= step;
            if step.abs() <= 2.0 * f64::EPSILON * u {
                break;
            }
        }
        u
    }

    fn angle_rate(&self, psi: f64) -> f64 {
        1.0 / (1.0 - self.lambda * self.u_of(psi.sin()))
    }

    fn time_rate(&self, psi: f64) -> f64 {
        let u = self.u_of(psi.sin());
        1.0 / (self.p.v0() * u * psi.sin() * (1.0 - self.lambda * u))
    }

    fn scattering_orbit(&self, q0: &SVector<f64, 3>, qd0: &SVector<f64, 3>) -> Option<Orbit> {
        let (r0, lambda) = (q0.norm(), self.lambda);
        if self.c.norm() == 0.0 || r0 <= lambda || self.b() <= lambda * std::f64::consts::E {
            return None;
        }
        let u_p = self.u_of(1.0);
        if u_p * lambda >= 1.0 {
            return None;
        }
        let n_hat = self.c / self.c.norm();
        let s0 = (self.b() * (-lambda / r0).exp() / r0).min(1.0);
        let psi0 = s0.asin();
        let right = std::f64::consts::FRAC_PI_2;
        let a0 = integrate(|x| self.angle_rate(x), psi0, right, QUADRATURE_TOL);
        let t0 = integrate(|x| self.time_rate(x), psi0, right, QUADRATURE_TOL);
        // Incoming (q·q̇ < 0): the periapsis lies ahead, by the angle a0 and the time t0.
        let ahead = if q0.dot(qd0) < 0.0 { 1.0 } else { -1.0 };
        let q_hat = q0 / r0;
        let angle = ahead * a0;
        let p_hat = q_hat * angle.cos() + n_hat.cross(&q_hat) * angle.sin();
        let total_angle = 2.0 * integrate(|x| self.angle_rate(x), 0.0, right, QUADRATURE_TOL);
        Some(Orbit {
            t_periapsis: ahead * t0,
            r_periapsis: 1.0 / u_p,
            p_hat,
            n_hat,
            total_angle,
        })
    }

    /// `q(t)` and `q̇(t)` on the scattering orbit (`None` if the initial state is not on one): the
    /// time from the periapsis `|t − t_p| = ∫_ψ^(π/2) dψ / (v0 u sin ψ (1 − λu))` is solved for `ψ`
    /// by safeguarded Newton steps, then `r = 1/u(ψ)`, the angle from the periapsis
    /// `∫_ψ^(π/2) dψ / (1 − λu)`, `ṙ = ±v0 cos ψ` and `r θ̇ = |C| u e^(−λu)`.
    pub fn state(&self, t: f64) -> Option<(SVector<f64, 3>, SVector<f64, 3>)> {
        let orbit = self.orbit.as_ref()?;
        let dt = t - orbit.t_periapsis;
        let sigma = if dt < 0.0 { -1.0 } else { 1.0 };
        let target = dt.abs();
        let right = std::f64::consts::FRAC_PI_2;
        // F(ψ) = T(ψ) − |Δt|, decreasing; bracket [lo, hi] with F(lo) > 0 ≥ F(hi).
        let (mut lo, mut hi) = (0.0f64, right);
        let mut psi = right;
        let mut f = -target;
        for _ in 0..100 {
            if f.abs() <= 4.0 * f64::EPSILON * target.max(1.0 / self.p.v0()) {
                break;
            }
            if f > 0.0 {
                lo = psi;
            } else {
                hi = psi;
            }
            // Newton: F'(ψ) = −time_rate(ψ).
            let mut next = psi + f / self.time_rate(psi);
            if !(next > lo && next < hi) {
                next = 0.5 * (lo + hi);
            }
            f += integrate(|x| self.time_rate(x), next, psi, QUADRATURE_TOL);
            psi = next;
            if (hi - lo) <= 4.0 * f64::EPSILON {
                break;
            }
        }
        let u = self.u_of(psi.sin());
        let angle = sigma * integrate(|x| self.angle_rate(x), psi, right, QUADRATURE_TOL);
        let e_theta_0 = orbit.n_hat.cross(&orbit.p_hat);
        let r_hat = orbit.p_hat * angle.cos() + e_theta_0 * angle.sin();
        let t_hat = orbit.n_hat.cross(&r_hat);
        let v0 = self.p.v0();
        let q = r_hat / u;
        let qd = r_hat * (sigma * v0 * psi.cos())
            + t_hat * (self.c.norm() * u * (-self.lambda * u).exp());
        Some((q, qd))
    }
}

impl Reference<3, 1> for Invariant {
    fn sources(&self) -> &[Source] {
        SOURCES
    }

    /// The three components of `C` (against `|C|`), `μ` against its value at the recorded state
    /// (against its largest value at that radius, `k m / (2 v0 r²)`), and on scattering orbits
    /// `q` (relative to `r`) and `q̇` (relative to `v0`) against the quadrature.
    fn checks(
        &self,
        t: f64,
        q: &SVector<f64, 3>,
        qd: &SVector<f64, 3>,
        mu: Option<&SVector<f64, 1>>,
    ) -> Vec<Check> {
        let c = invariant(self.lambda, q, qd);
        let scale = self.c.norm();
        let mut out = vec![
            Check::new("C_x", Kind::Invariant, c[0], self.c[0], scale),
            Check::new("C_y", Kind::Invariant, c[1], self.c[1], scale),
            Check::new("C_z", Kind::Invariant, c[2], self.c[2], scale),
        ];
        let v0 = self.p.v0();
        if let Some((qr, vr)) = self.state(t) {
            let r = qr.norm();
            for (k, name) in ["x", "y", "z"].into_iter().enumerate() {
                out.push(Check::new(name, Kind::Position, q[k], qr[k], r));
            }
            for (k, name) in ["ẋ", "ẏ", "ż"].into_iter().enumerate() {
                out.push(Check::new(name, Kind::Velocity, qd[k], vr[k], v0));
            }
        }
        if let Some(mu) = mu {
            let r = q.norm();
            let scale = self.p.k * self.p.m / (2.0 * v0 * r * r);
            out.push(Check::multiplier(
                mu[0],
                multiplier_at(&self.p, q, qd),
                scale,
            ));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn without_a_centre_the_quadratures_give_the_straight_line() {
        // k = 0: λ = 0, C = q × q̇ is the angular momentum, the orbit is q0 + q̇0 t and turns
        // through π.
        let p = Params {
            m: 1.0,
            k: 0.0,
            q0: [5.0, 1.0, -0.5],
            qd0: [-1.0, 0.2, 0.1],
        };
        let inv = Invariant::new(&p).expect("valid");
        let orbit = inv.orbit().expect("a straight line scatters");
        assert!((orbit.total_angle - std::f64::consts::PI).abs() <= 1e-14);
        let (q0, qd0) = (SVector::from(p.q0), SVector::from(p.qd0));
        let r_min = q0.cross(&qd0).norm() / qd0.norm();
        assert!((orbit.r_periapsis - r_min).abs() <= 1e-15 * r_min);
        for t in [0.0, 1.0, 4.0, 4.9, 10.0, 100.0] {
            let (q, qd) = inv.state(t).expect("on the orbit");
            let exact = q0 + qd0 * t;
            assert!(
                (q - exact).norm() <= 1e-13 * exact.norm(),
                "t = {t}: {q} vs {exact}"
            );
            assert!((qd - qd0).norm() <= 1e-13 * qd0.norm(), "t = {t}: {qd}");
        }
    }

    #[test]
    fn the_state_starts_at_the_initial_state_and_turns_at_the_periapsis() {
        let p = Params::incoming(1.0, 2.0, 1.3, 10.0, 1.8);
        let inv = Invariant::new(&p).expect("valid");
        let orbit = *inv.orbit().expect("scattering");
        let (q, qd) = inv.state(0.0).expect("on the orbit");
        assert!((q - SVector::from(p.q0)).norm() <= 1e-13 * 10.0);
        assert!((qd - SVector::from(p.qd0)).norm() <= 1e-13 * 1.3);
        let (q, qd) = inv.state(orbit.t_periapsis).expect("on the orbit");
        assert!((q.norm() - 1.8).abs() <= 1e-13);
        assert!(q.dot(&qd).abs() <= 1e-13 * 1.8 * 1.3);
        // The invariant holds along the quadrature itself.
        for t in [1.0, 5.0, orbit.t_periapsis + 3.0, 60.0] {
            let (q, qd) = inv.state(t).expect("on the orbit");
            let c = invariant(inv.lambda(), &q, &qd);
            assert!(
                (c - inv.value()).norm() <= 1e-13 * inv.value().norm(),
                "t = {t}"
            );
        }
    }
}
