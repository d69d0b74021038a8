//! The knife edge (a skate) on an inclined plane.
//!
//! Coordinates `q = (x, y, φ)`: the contact point in the plane, `x` pointing down the slope, and
//! the angle `φ` of the blade from the `x` axis. The plane is inclined at `α`.
//!
//! ```text
//! L = ½ m (ẋ² + ẏ²) + ½ I φ̇² + m g sin α · x
//! f = ẋ sin φ − ẏ cos φ = 0                      (no velocity across the blade)
//! ```
//!
//! Chetaev's equations in Newton form (`J = (sin φ, −cos φ, 0)`):
//!
//! ```text
//! m ẍ = m g sin α + μ sin φ,      m ÿ = −μ cos φ,      I φ̈ = 0.
//! ```
//!
//! **Reference** (closed form), for the start at rest at the origin with `φ(0) = 0`,
//! `φ̇(0) = ω`: with `v = ẋ cos φ + ẏ sin φ` the speed along the blade, the equations give
//! `v̇ = g sin α cos φ` and, from `df/dt = 0`, `μ = −m (ω v + g sin α sin φ)`; hence
//!
//! ```text
//! φ = ω t,
//! x = (g sin α / 2ω²) sin²(ω t),
//! y = (g sin α / 2ω²) (ω t − ½ sin 2ω t),
//! μ = −2 m g sin α sin(ω t).
//! ```
//!
//! The skate oscillates across the slope while drifting sideways at the mean speed
//! `g sin α / 2ω`; it never descends further than `x = g sin α / 2ω²`. The constraint is linear and
//! homogeneous in `q̇`, so `Φ` does no work and `E = ½ m v² + ½ I ω² − m g sin α · x` is
//! conserved. Sources: Neimark & Fufaev; Bloch §1.6 (see [`SOURCES`]).

use chetaev::model::Fixed;
use chetaev::prelude::*;

use crate::error::{check, positive, Error};
use crate::reference::{works, Check, Entry, Kind, Reference, Source};
use crate::special::{sinc, u_minus_sin_over_u2};

/// Where the closed form comes from.
pub const SOURCES: &[Source] = &[
    Source {
        work: works::BLOCH,
        location: "§1.6 The Knife Edge",
    },
    Source {
        work: works::NEIMARK_FUFAEV,
        location: "the skate on an inclined plane (Chapter I)",
    },
];

/// Parameters of the knife edge (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    /// Mass `m`, > 0.
    pub m: f64,
    /// Moment of inertia `I` about the vertical axis through the contact point, > 0.
    pub inertia: f64,
    /// Gravitational acceleration `g`, > 0.
    pub g: f64,
    /// Inclination `α` of the plane, in `(0, π/2]` radians.
    pub alpha: f64,
    /// Initial spin `ω = φ̇(0)`, non-zero (its sign is the sense of turning).
    pub omega: f64,
}

impl Default for Params {
    /// `m = 1 kg`, `I = 0.1 kg m²`, `g = 9.81 m/s²`, `α = 30°`, `ω = 1 rad/s`.
    fn default() -> Self {
        Self {
            m: 1.0,
            inertia: 0.1,
            g: 9.81,
            alpha: std::f64::consts::FRAC_PI_6,
            omega: 1.0,
        }
    }
}

impl Params {
    fn validate(&self) -> Result<(), Error> {
        positive("m", self.m)?;
        positive("inertia", self.inertia)?;
        positive("g", self.g)?;
        check(
            "alpha",
            self.alpha,
            |a| a > 0.0 && a <= std::f64::consts::FRAC_PI_2,
            "the inclination must lie in (0, π/2]",
        )?;
        check(
            "omega",
            self.omega,
            |w| w != 0.0,
            "must be finite and non-zero (with ω = 0 the skate slides straight down)",
        )?;
        Ok(())
    }

    /// `g sin α`, the acceleration down the slope.
    fn a(&self) -> f64 {
        self.g * self.alpha.sin()
    }
}

/// The knife edge as a `chetaev` model: `N = 3` coordinates `(x, y, φ)`, `K = 1` constraint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KnifeEdge {
    /// Mass.
    pub m: f64,
    /// Moment of inertia about the vertical axis.
    pub inertia: f64,
    /// Gravitational acceleration.
    pub g: f64,
    /// Inclination of the plane.
    pub alpha: f64,
}

impl Lagrangian<3> for KnifeEdge {
    /// `L = ½ m (ẋ² + ẏ²) + ½ I φ̇² + m g sin α · x`.
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 3>, qd: &SVector<R, 3>) -> R {
        (qd[0] * qd[0] + qd[1] * qd[1]) * (0.5 * self.m)
            + qd[2] * qd[2] * (0.5 * self.inertia)
            + q[0] * (self.m * self.g * self.alpha.sin())
    }
}

impl Constraints<3, 1> for KnifeEdge {
    /// `f = ẋ sin φ − ẏ cos φ`.
    fn constraints<R: Real>(&self, _t: R, q: &SVector<R, 3>, qd: &SVector<R, 3>) -> SVector<R, 1> {
        SVector::from([qd[0] * q[2].sin() - qd[1] * q[2].cos()])
    }
}

/// The problem: at rest at the origin, blade along the `x` axis (`φ = 0`), spinning at `ω`.
pub fn problem(p: &Params) -> Result<Problem<Fixed<KnifeEdge, 3, 1>>, Error> {
    p.validate()?;
    let model = KnifeEdge {
        m: p.m,
        inertia: p.inertia,
        g: p.g,
        alpha: p.alpha,
    };
    Ok(Problem::new(
        model,
        0.0,
        SVector::zeros(),
        SVector::from([0.0, 0.0, p.omega]),
    )?)
}

/// The problem with its closed form.
pub fn entry(p: &Params) -> Result<Entry<KnifeEdge, ClosedForm, 3, 1>, Error> {
    Ok(Entry {
        problem: problem(p)?,
        reference: ClosedForm { p: *p },
    })
}

/// The closed-form motion of the knife edge started at rest at the origin with `φ̇(0) = ω`.
///
/// Evaluated in forms without cancellation for small `ω t`:
/// `x = ½ g sin α t² sinc²(ω t)`, `y = g sin α t² (u − sin u)/u²` with `u = 2ω t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosedForm {
    p: Params,
}

impl ClosedForm {
    /// The closed form for these parameters.
    pub fn new(p: &Params) -> Self {
        Self { p: *p }
    }

    /// `q(t) = (x, y, φ)`.
    pub fn position(&self, t: f64) -> SVector<f64, 3> {
        let (a, w) = (self.p.a(), self.p.omega);
        let s = sinc(w * t);
        SVector::from([
            0.5 * a * t * t * s * s,
            a * t * t * u_minus_sin_over_u2(2.0 * w * t),
            w * t,
        ])
    }

    /// `q̇(t)`: `ẋ = (g sin α / 2ω) sin 2ω t`, `ẏ = (g sin α / ω) sin² ω t`, `φ̇ = ω`.
    pub fn velocity(&self, t: f64) -> SVector<f64, 3> {
        let (a, w) = (self.p.a(), self.p.omega);
        let s = sinc(w * t);
        SVector::from([a * t * sinc(2.0 * w * t), a * w * t * t * s * s, w])
    }

    /// `q̈(t)`: `ẍ = g sin α cos 2ω t`, `ÿ = g sin α sin 2ω t`, `φ̈ = 0`.
    pub fn acceleration(&self, t: f64) -> SVector<f64, 3> {
        let (a, w) = (self.p.a(), self.p.omega);
        SVector::from([a * (2.0 * w * t).cos(), a * (2.0 * w * t).sin(), 0.0])
    }

    /// The multiplier `μ(t) = −2 m g sin α sin(ω t)`, Newton form: the sideways force on the
    /// blade, `Φ = μ (sin φ, −cos φ, 0)`.
    pub fn multiplier(&self, t: f64) -> f64 {
        -2.0 * self.p.m * self.p.a() * (self.p.omega * t).sin()
    }

    /// The energy `E = ½ m (ẋ² + ẏ²) + ½ I φ̇² − m g sin α · x` of a state.
    pub fn energy(&self, q: &SVector<f64, 3>, qd: &SVector<f64, 3>) -> f64 {
        let p = &self.p;
        0.5 * p.m * (qd[0] * qd[0] + qd[1] * qd[1]) + 0.5 * p.inertia * qd[2] * qd[2]
            - p.m * p.a() * q[0]
    }

    /// The length scale `g sin α / ω²` (twice the largest descent).
    pub fn length_scale(&self) -> f64 {
        self.p.a() / (self.p.omega * self.p.omega)
    }
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
        let (qr, vr) = (self.position(t), self.velocity(t));
        let length = self.length_scale();
        let speed = p.a() / p.omega.abs();
        let e0 = 0.5 * p.inertia * p.omega * p.omega;
        let energy_scale = e0 + 0.5 * p.m * speed * speed;
        let mut out = vec![
            Check::new("x", Kind::Position, q[0], qr[0], length),
            Check::new("y", Kind::Position, q[1], qr[1], length.max(qr[1].abs())),
            Check::new("φ", Kind::Position, q[2], qr[2], qr[2].abs().max(1.0)),
            Check::new("ẋ", Kind::Velocity, qd[0], vr[0], speed),
            Check::new("ẏ", Kind::Velocity, qd[1], vr[1], speed),
            Check::new("φ̇", Kind::Velocity, qd[2], vr[2], p.omega.abs()),
            Check::new("E", Kind::Invariant, self.energy(q, qd), e0, energy_scale),
        ];
        if let Some(mu) = mu {
            out.push(Check::multiplier(mu[0], self.multiplier(t), p.m * p.a()));
        }
        out
    }
}
