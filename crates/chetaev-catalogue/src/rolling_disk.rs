//! The vertical rolling disk: a coin rolling upright without slipping on a horizontal plane.
//!
//! Coordinates `q = (x, y, θ, φ)`: the contact point, the rolling angle `θ` about the axle and the
//! heading `φ` of the disk's plane from the `x` axis. Radius `R`, mass `m`, moments of inertia
//! `I` about the axle and `J` about the vertical diameter.
//!
//! ```text
//! L  = ½ m (ẋ² + ẏ²) + ½ I θ̇² + ½ J φ̇²
//! f1 = ẋ − R cos φ · θ̇ = 0,     f2 = ẏ − R sin φ · θ̇ = 0      (rolling without slipping)
//! ```
//!
//! Chetaev's equations in Newton form (`Φ = J_fᵀ μ`, `J_f = [[1, 0, −R cos φ, 0], [0, 1, −R sin φ, 0]]`):
//!
//! ```text
//! m ẍ = μ1,   m ÿ = μ2,   I θ̈ = −R (μ1 cos φ + μ2 sin φ),   J φ̈ = 0.
//! ```
//!
//! **Reference** (closed form): differentiating the constraints,
//! `μ1 cos φ + μ2 sin φ = m R θ̈`, hence `(I + m R²) θ̈ = 0`: both `θ̇ = ω` and `φ̇ = Ω` are constant,
//! and the contact point runs on a circle of radius `ρ = R ω / Ω` (a straight line if `Ω = 0`):
//!
//! ```text
//! θ = θ0 + ω t,    φ = φ0 + Ω t,
//! x = x0 + (R ω / Ω)(sin φ − sin φ0),    y = y0 − (R ω / Ω)(cos φ − cos φ0),
//! μ1 = −m R ω Ω sin φ,    μ2 = m R ω Ω cos φ    (the centripetal force, |Φ| = m (Rω)² / ρ).
//! ```
//!
//! The constraints are linear and homogeneous in `q̇`: `E = ½ (m R² + I) ω² + ½ J Ω²` is conserved.
//! Source: Bloch §1.4 (see [`SOURCES`]).

use chetaev::model::Fixed;
use chetaev::prelude::*;

use crate::error::{finite, positive, Error};
use crate::reference::{works, Check, Entry, Kind, Reference, Source};
use crate::special::sinc;

/// Where the closed form comes from.
pub const SOURCES: &[Source] = &[Source {
    work: works::BLOCH,
    location: "§1.4 The Vertical Rolling Disk",
}];

/// Parameters and initial state of the rolling disk (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    /// Mass `m`, > 0.
    pub m: f64,
    /// Radius `R`, > 0.
    pub radius: f64,
    /// Moment of inertia `I` about the axle, > 0 (`½ m R²` for a uniform disk).
    pub i_roll: f64,
    /// Moment of inertia `J` about the vertical diameter, > 0 (`¼ m R²` for a uniform disk).
    pub i_spin: f64,
    /// Initial contact point `(x0, y0)`.
    pub position: [f64; 2],
    /// Initial rolling angle `θ0`.
    pub theta0: f64,
    /// Initial heading `φ0`.
    pub phi0: f64,
    /// Rolling rate `ω = θ̇`.
    pub omega: f64,
    /// Turning rate `Ω = φ̇`.
    pub spin: f64,
}

impl Default for Params {
    /// A uniform disk, `m = 1 kg`, `R = 0.5 m`, `I = ½ m R²`, `J = ¼ m R²`, from the origin with
    /// `θ0 = φ0 = 0`, rolling at `ω = 4 rad/s` and turning at `Ω = 1 rad/s`: a circle of radius
    /// `ρ = R ω / Ω = 2 m`.
    fn default() -> Self {
        Self {
            m: 1.0,
            radius: 0.5,
            i_roll: 0.125,
            i_spin: 0.0625,
            position: [0.0, 0.0],
            theta0: 0.0,
            phi0: 0.0,
            omega: 4.0,
            spin: 1.0,
        }
    }
}

impl Params {
    fn validate(&self) -> Result<(), Error> {
        positive("m", self.m)?;
        positive("radius", self.radius)?;
        positive("i_roll", self.i_roll)?;
        positive("i_spin", self.i_spin)?;
        finite("position[0]", self.position[0])?;
        finite("position[1]", self.position[1])?;
        finite("theta0", self.theta0)?;
        finite("phi0", self.phi0)?;
        finite("omega", self.omega)?;
        finite("spin", self.spin)?;
        Ok(())
    }

    fn initial_state(&self) -> (SVector<f64, 4>, SVector<f64, 4>) {
        let v = self.radius * self.omega;
        (
            SVector::from([self.position[0], self.position[1], self.theta0, self.phi0]),
            SVector::from([
                v * self.phi0.cos(),
                v * self.phi0.sin(),
                self.omega,
                self.spin,
            ]),
        )
    }
}

/// The vertical rolling disk as a `chetaev` model: `N = 4` coordinates `(x, y, θ, φ)`, `K = 2`
/// constraints.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RollingDisk {
    /// Mass.
    pub m: f64,
    /// Radius.
    pub radius: f64,
    /// Moment of inertia about the axle.
    pub i_roll: f64,
    /// Moment of inertia about the vertical diameter.
    pub i_spin: f64,
}

impl Lagrangian<4> for RollingDisk {
    /// `L = ½ m (ẋ² + ẏ²) + ½ I θ̇² + ½ J φ̇²`.
    fn lagrangian<R: Real>(&self, _t: R, _q: &SVector<R, 4>, qd: &SVector<R, 4>) -> R {
        (qd[0] * qd[0] + qd[1] * qd[1]) * (0.5 * self.m)
            + qd[2] * qd[2] * (0.5 * self.i_roll)
            + qd[3] * qd[3] * (0.5 * self.i_spin)
    }
}

impl Constraints<4, 2> for RollingDisk {
    /// `f = (ẋ − R cos φ θ̇, ẏ − R sin φ θ̇)`.
    fn constraints<R: Real>(&self, _t: R, q: &SVector<R, 4>, qd: &SVector<R, 4>) -> SVector<R, 2> {
        let roll = qd[2] * self.radius;
        SVector::from([qd[0] - roll * q[3].cos(), qd[1] - roll * q[3].sin()])
    }
}

/// The problem: the disk at `(x0, y0)` with angles `θ0`, `φ0`, rolling at `ω` and turning at `Ω`
/// (the initial `ẋ, ẏ` follow from the constraints).
pub fn problem(p: &Params) -> Result<Problem<Fixed<RollingDisk, 4, 2>>, Error> {
    p.validate()?;
    let model = RollingDisk {
        m: p.m,
        radius: p.radius,
        i_roll: p.i_roll,
        i_spin: p.i_spin,
    };
    let (q0, qd0) = p.initial_state();
    Ok(Problem::new(model, 0.0, q0, qd0)?)
}

/// The problem with its closed form.
pub fn entry(p: &Params) -> Result<Entry<RollingDisk, ClosedForm, 4, 2>, Error> {
    Ok(Entry {
        problem: problem(p)?,
        reference: ClosedForm::new(p),
    })
}

/// The closed-form motion of the rolling disk: uniform rolling and turning, the contact point on
/// a circle.
///
/// The position is evaluated as `x = x0 + R ω t cos(φ0 + Ω t/2) sinc(Ω t/2)` (and `sin` for `y`),
/// which equals the circle above and stays exact for `Ω → 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosedForm {
    p: Params,
}

impl ClosedForm {
    /// The closed form for these parameters.
    pub fn new(p: &Params) -> Self {
        Self { p: *p }
    }

    /// `q(t) = (x, y, θ, φ)`.
    pub fn position(&self, t: f64) -> SVector<f64, 4> {
        let p = &self.p;
        let chord = p.radius * p.omega * t * sinc(0.5 * p.spin * t);
        let mid = p.phi0 + 0.5 * p.spin * t;
        SVector::from([
            p.position[0] + chord * mid.cos(),
            p.position[1] + chord * mid.sin(),
            p.theta0 + p.omega * t,
            p.phi0 + p.spin * t,
        ])
    }

    /// `q̇(t) = (R ω cos φ, R ω sin φ, ω, Ω)`.
    pub fn velocity(&self, t: f64) -> SVector<f64, 4> {
        let p = &self.p;
        let phi = p.phi0 + p.spin * t;
        let v = p.radius * p.omega;
        SVector::from([v * phi.cos(), v * phi.sin(), p.omega, p.spin])
    }

    /// `q̈(t) = (−R ω Ω sin φ, R ω Ω cos φ, 0, 0)`.
    pub fn acceleration(&self, t: f64) -> SVector<f64, 4> {
        let p = &self.p;
        let phi = p.phi0 + p.spin * t;
        let c = p.radius * p.omega * p.spin;
        SVector::from([-c * phi.sin(), c * phi.cos(), 0.0, 0.0])
    }

    /// The multipliers `μ = m R ω Ω (−sin φ, cos φ)`: the horizontal force of the plane on the
    /// disk, Newton form.
    pub fn multiplier(&self, t: f64) -> SVector<f64, 2> {
        let p = &self.p;
        let phi = p.phi0 + p.spin * t;
        let c = p.m * p.radius * p.omega * p.spin;
        SVector::from([-c * phi.sin(), c * phi.cos()])
    }

    /// The centre and radius `ρ = R |ω / Ω|` of the circle of the contact point (`None` for
    /// `Ω = 0`, a straight line).
    pub fn circle(&self) -> Option<([f64; 2], f64)> {
        let p = &self.p;
        if p.spin == 0.0 {
            return None;
        }
        let rho = p.radius * p.omega / p.spin;
        Some((
            [
                p.position[0] - rho * p.phi0.sin(),
                p.position[1] + rho * p.phi0.cos(),
            ],
            rho.abs(),
        ))
    }

    /// The energy `E = ½ m (ẋ² + ẏ²) + ½ I θ̇² + ½ J φ̇²` of a state.
    pub fn energy(&self, qd: &SVector<f64, 4>) -> f64 {
        let p = &self.p;
        0.5 * (p.m * (qd[0] * qd[0] + qd[1] * qd[1])
            + p.i_roll * qd[2] * qd[2]
            + p.i_spin * qd[3] * qd[3])
    }
}

impl Reference<4, 2> for ClosedForm {
    fn sources(&self) -> &[Source] {
        SOURCES
    }

    fn checks(
        &self,
        t: f64,
        q: &SVector<f64, 4>,
        qd: &SVector<f64, 4>,
        mu: Option<&SVector<f64, 2>>,
    ) -> Vec<Check> {
        let p = &self.p;
        let (qr, vr) = (self.position(t), self.velocity(t));
        let speed = (p.radius * p.omega).abs();
        // Positions relative to the larger of the circle's radius and the disk's radius.
        let length = match self.circle() {
            Some((_, rho)) => rho.max(p.radius),
            None => p.radius.max(speed * t.abs()),
        };
        let rates = p.omega.abs().max(p.spin.abs());
        let e0 = self.energy(&vr);
        let mut out = vec![
            Check::new("x", Kind::Position, q[0], qr[0], length),
            Check::new("y", Kind::Position, q[1], qr[1], length),
            Check::new("θ", Kind::Position, q[2], qr[2], qr[2].abs().max(1.0)),
            Check::new("φ", Kind::Position, q[3], qr[3], qr[3].abs().max(1.0)),
            Check::new("ẋ", Kind::Velocity, qd[0], vr[0], speed),
            Check::new("ẏ", Kind::Velocity, qd[1], vr[1], speed),
            Check::new("θ̇", Kind::Velocity, qd[2], vr[2], rates),
            Check::new("φ̇", Kind::Velocity, qd[3], vr[3], rates),
            Check::new("E", Kind::Invariant, self.energy(qd), e0, e0),
        ];
        if let Some(mu) = mu {
            let mr = self.multiplier(t);
            let scale = p.m * speed * rates;
            out.push(Check::new("μ1", Kind::Multiplier, mu[0], mr[0], scale));
            out.push(Check::new("μ2", Kind::Multiplier, mu[1], mr[1], scale));
        }
        out
    }
}
