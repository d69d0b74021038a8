//! The Gaussian isokinetic thermostat: particles in a constant field whose total kinetic energy is
//! held fixed by one constraint, nonlinear in the velocities, on all `N` coordinates.
//!
//! Coordinates `q` (length `N`): the Cartesian components of all particles, particle after
//! particle; `m_k` is the mass belonging to component `k` (a particle's mass repeated over its
//! components) and `F_k` the constant force on it (charge times field, or mass times gravity).
//!
//! ```text
//! L = Σ_k ½ m_k q̇_k² + Σ_k F_k q_k
//! f = Σ_k ½ m_k q̇_k² − K0 = 0                      (the kinetic energy is K0)
//! ```
//!
//! Chetaev's equations in Newton form: `J = ∂f/∂q̇ = (m_k q̇_k)`, so `Φ_k = μ m_k q̇_k` and
//!
//! ```text
//! m_k q̈_k = F_k + μ m_k q̇_k.
//! ```
//!
//! `df/dt = Σ q̇_k (F_k + μ m_k q̇_k) = F·q̇ + 2 K0 μ = 0` gives `μ = −F·q̇ / Σ m_k q̇_k²`: this is
//! **minus** the friction coefficient `α = Σ F·v / Σ m v²` of the Gaussian isokinetic equations of
//! motion `m v̇ = F − α m v` (Evans & Morriss), with factor 1 because `f` is the kinetic energy
//! itself. The Chetaev force `Φ = −α m v` is the thermostat's friction force; it does the work
//! `q̇·Φ = 2 K0 μ = −F·q̇`, which cancels the work of the field, so `E = K0 − F·q` changes by
//! exactly `W_Φ`.
//!
//! **Reference** (closed form for a constant force, Zhang 1997; Minary, Martyna & Tuckerman 2003;
//! Tuckerman §4.12): with `a = F·q̇0 / 2K0` and `b = Σ F_k²/m_k / 2K0` (so `a² ≤ b`),
//!
//! ```text
//! s(t) = (a/b)(cosh √b t − 1) + sinh(√b t)/√b,      ṡ(t) = cosh √b t + (a/√b) sinh √b t,
//! q̇(t) = (q̇0 + M⁻¹F s(t)) / ṡ(t),                   μ(t) = −α(t) = −(a + b s(t)) / ṡ(t),
//! q(t) = q0 + q̇0 G(t) + M⁻¹F (ln ṡ(t) − a G(t)) / b,  G(t) = ∫₀ᵗ dτ / ṡ(τ).
//! ```
//!
//! `s` solves `s̈ = a + b s`, `s(0) = 0`, `ṡ(0) = 1`, and `ṡ² = 1 + 2 a s + b s²` keeps the kinetic
//! energy at `K0`. The position is the integral of the velocity, using `s/ṡ = (s̈/ṡ − a/ṡ)/b` and
//! `∫ s̈/ṡ = ln ṡ`; `G` is elementary (see [`ClosedForm::g`]). For one particle in gravity this is
//! the uniform horizontal projectile of Swaczyna and Volný: `a = 0`, `√b = g/v0`, `ṡ = cosh(g t/v0)`.

use chetaev::model::Fixed;
use chetaev::prelude::*;

use crate::error::{finite, positive, Error};
use crate::reference::{Check, Entry, Kind, Reference, Source};
use crate::special::{atanc, sinhc, tanhc, turning};

/// Where the equations of motion and the closed form come from.
pub const SOURCES: &[Source] = &[
    Source {
        work: "D. J. Evans, G. P. Morriss, Statistical Mechanics of Nonequilibrium Liquids, \
               Academic Press (1990); 2nd ed. Cambridge University Press (2008)",
        location: "Chapter 3: Gauss's principle of least constraint and the isokinetic equations \
                   of motion, m v̇ = F − α m v, α = Σ F·v / Σ m v²",
    },
    Source {
        work: "M. E. Tuckerman, Statistical Mechanics: Theory and Molecular Simulation, Oxford \
               University Press (2010)",
        location: "§4.12, eqs. (4.12.16)–(4.12.20): v(t) = (v(0) + F s(t)/m)/ṡ(t) for constant \
                   forces",
    },
    Source {
        work: "P. Minary, G. J. Martyna, M. E. Tuckerman, J. Chem. Phys. 118, 2510 (2003); \
               F. Zhang, J. Chem. Phys. 106, 6102 (1997)",
        location: "the analytic isokinetic propagator for constant forces",
    },
];

/// Masses, forces and initial state, one entry per coordinate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params<const N: usize> {
    /// Mass `m_k` of each coordinate, > 0.
    pub mass: SVector<f64, N>,
    /// Constant force `F_k` on each coordinate.
    pub force: SVector<f64, N>,
    /// Initial positions.
    pub q0: SVector<f64, N>,
    /// Initial velocities, not all zero; they fix `K0 = Σ ½ m_k q̇0_k²`.
    pub qd0: SVector<f64, N>,
}

impl<const N: usize> Params<N> {
    /// Particles in `dim` dimensions, `N = dim × masses.len()` coordinates: particle `i` has mass
    /// `masses[i]` and charge `charges[i]` in the uniform field `field` (length `dim`), so the
    /// force on it is `charges[i] · field`; `positions` and `velocities` list the particles'
    /// components one particle after the other (length `N`). For gravity, pass the masses as
    /// charges and `(0, …, −g)` as the field.
    pub fn particles_in_field(
        dim: usize,
        masses: &[f64],
        charges: &[f64],
        field: &[f64],
        positions: &[f64],
        velocities: &[f64],
    ) -> Result<Self, Error> {
        let lengths = [
            ("masses × dim", masses.len() * dim, N),
            ("charges", charges.len(), masses.len()),
            ("field", field.len(), dim),
            ("positions", positions.len(), N),
            ("velocities", velocities.len(), N),
        ];
        for (what, got, expected) in lengths {
            if got != expected {
                return Err(Error::WrongLength {
                    what,
                    got,
                    expected,
                });
            }
        }
        let mass = SVector::from_fn(|k, _| masses[k / dim]);
        let force = SVector::from_fn(|k, _| charges[k / dim] * field[k % dim]);
        Ok(Self {
            mass,
            force,
            q0: SVector::from_column_slice(positions),
            qd0: SVector::from_column_slice(velocities),
        })
    }

    fn validate(&self) -> Result<(), Error> {
        for k in 0..N {
            positive("mass", self.mass[k])?;
            finite("force", self.force[k])?;
            finite("q0", self.q0[k])?;
            finite("qd0", self.qd0[k])?;
        }
        positive("K0 (kinetic energy of qd0)", self.kinetic_energy())?;
        Ok(())
    }

    /// `K0 = Σ ½ m_k q̇0_k²`.
    pub fn kinetic_energy(&self) -> f64 {
        0.5 * self.mass.component_mul(&self.qd0).dot(&self.qd0)
    }
}

impl Params<12> {
    /// Four particles in 3D (`N = 12`): masses `1, 2, 3, 4`, charges `1, −1, 2, −½` in the field
    /// `(0.5, 0, −1)`, starting at the origin and at the unit points of the three axes with mixed
    /// velocities.
    pub fn four_particles() -> Self {
        let masses = [1.0, 2.0, 3.0, 4.0];
        let charges = [1.0, -1.0, 2.0, -0.5];
        let field = [0.5, 0.0, -1.0];
        let positions = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        let velocities = [
            0.3, -0.2, 0.5, -0.1, 0.4, 0.0, 0.2, 0.1, -0.3, 0.0, -0.25, 0.15,
        ];
        Self {
            mass: SVector::from_fn(|k, _| masses[k / 3]),
            force: SVector::from_fn(|k, _| charges[k / 3] * field[k % 3]),
            q0: SVector::from(positions),
            qd0: SVector::from(velocities),
        }
    }
}

impl Params<2> {
    /// One particle of mass `m` in the plane, in gravity `(0, −g)`, from `(0, h0)` with velocity
    /// `(v0, 0)`: the uniform horizontal projectile of Swaczyna and Volný, with `K0 = ½ m v0²`.
    pub fn projectile(m: f64, g: f64, v0: f64, h0: f64) -> Self {
        Self {
            mass: SVector::from([m, m]),
            force: SVector::from([0.0, -m * g]),
            q0: SVector::from([0.0, h0]),
            qd0: SVector::from([v0, 0.0]),
        }
    }
}

/// The thermostatted particles as a `chetaev` model: `N` coordinates, `K = 1` constraint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IsokineticThermostat<const N: usize> {
    /// Mass of each coordinate.
    pub mass: SVector<f64, N>,
    /// Constant force on each coordinate.
    pub force: SVector<f64, N>,
    /// The kinetic energy held fixed.
    pub k0: f64,
}

impl<const N: usize> IsokineticThermostat<N> {
    fn kinetic<R: Real>(&self, qd: &SVector<R, N>) -> R {
        (0..N).map(|k| qd[k] * qd[k] * (0.5 * self.mass[k])).sum()
    }
}

impl<const N: usize> Lagrangian<N> for IsokineticThermostat<N> {
    /// `L = Σ ½ m_k q̇_k² + Σ F_k q_k`.
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, N>, qd: &SVector<R, N>) -> R {
        self.kinetic(qd) + (0..N).map(|k| q[k] * self.force[k]).sum::<R>()
    }
}

impl<const N: usize> Constraints<N, 1> for IsokineticThermostat<N> {
    /// `f = Σ ½ m_k q̇_k² − K0`.
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, N>, qd: &SVector<R, N>) -> SVector<R, 1> {
        SVector::from([self.kinetic(qd) - self.k0])
    }
}

/// The problem, with `K0` the kinetic energy of the initial velocities.
pub fn problem<const N: usize>(
    p: &Params<N>,
) -> Result<Problem<Fixed<IsokineticThermostat<N>, N, 1>>, Error> {
    p.validate()?;
    let model = IsokineticThermostat {
        mass: p.mass,
        force: p.force,
        k0: p.kinetic_energy(),
    };
    Ok(Problem::new(model, 0.0, p.q0, p.qd0)?)
}

/// The problem with its closed form.
pub fn entry<const N: usize>(
    p: &Params<N>,
) -> Result<Entry<IsokineticThermostat<N>, ClosedForm<N>, N, 1>, Error> {
    Ok(Entry {
        problem: problem(p)?,
        reference: ClosedForm::new(p)?,
    })
}

/// The Euclidean norm of `v`, scaled by its largest component so that the squares of tiny
/// components do not underflow (`(1e-200, 0)` has the norm `1e-200`, not 0).
fn norm<const N: usize>(v: &SVector<f64, N>) -> f64 {
    let largest = v.amax();
    if largest > 0.0 && largest.is_finite() {
        largest * (v / largest).norm()
    } else {
        largest
    }
}

/// The friction coefficient of the Gaussian isokinetic equations at a state,
/// `α = Σ F_k q̇_k / Σ m_k q̇_k²`; the Chetaev multiplier is `μ = −α`.
pub fn friction_coefficient<const N: usize>(
    mass: &SVector<f64, N>,
    force: &SVector<f64, N>,
    qd: &SVector<f64, N>,
) -> f64 {
    force.dot(qd) / mass.component_mul(qd).dot(qd)
}

/// The closed-form motion under a constant force.
///
/// Evaluated without cancellation or overflow for every finite `t`: `s` and `ṡ` as sums of terms
/// of one sign, scaled by `2 e^(−√b |t|)` beyond `√b |t| = 1`; `ln ṡ` through `ln1p` for
/// `√b |t| < 1` and as `√b |t| + ln(½ (1 ± β) + ½ (1 ∓ β) e^(−2√b |t|))` beyond (`β = a/√b`,
/// `1 ± β` formed without cancellation); `G` by [`ClosedForm::g`]. A velocity exactly along or
/// against the field (`γ = 0`) cannot turn: the motion is uniform, `q = q0 + q̇0 t`, with
/// `μ = −β √b`, and is given so. Near `β = −1` (`0 < γ ≪ 1`) the representation
/// `(q̇0 + M⁻¹F s)/ṡ` has the condition `e^(√b t)` of the motion itself, which is unstable there
/// (any deviation turns the velocity towards the field), see the tests.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosedForm<const N: usize> {
    p: Params<N>,
    k0: f64,
    /// `a = F·q̇0 / 2K0`.
    a: f64,
    /// `b = Σ F_k²/m_k / 2K0`.
    b: f64,
    /// `γ = √(1 − β²)`, `β = a/√b`: the sine of the angle between `q̇0` and `M⁻¹F` in the
    /// metric `M`.
    gamma: f64,
    /// `β`, `1 + β` and `1 − β`, the last two formed without cancellation.
    beta: f64,
    one_plus: f64,
    one_minus: f64,
    /// `u = M⁻¹F/√b`, the field's acceleration scaled to the speed of `q̇0` (`|u|_M = |q̇0|_M`;
    /// zero without a field).
    u: SVector<f64, N>,
    /// `w = q̇0 − β u`, the part of `q̇0` perpendicular to `u` in the metric `M` (`|w|_M = γ |q̇0|_M`),
    /// formed by projection, so that it is exactly zero where `q̇0` lies along the field.
    w: SVector<f64, N>,
}

impl<const N: usize> ClosedForm<N> {
    /// The closed form for these parameters.
    pub fn new(p: &Params<N>) -> Result<Self, Error> {
        p.validate()?;
        let k0 = p.kinetic_energy();
        let a = p.force.dot(&p.qd0) / (2.0 * k0);
        let b = p.force.component_div(&p.mass).dot(&p.force) / (2.0 * k0);
        // γ and w from the component of M^½ q̇0 perpendicular to M^(−½) F, without cancellation
        // in 1 − a²/b.
        let scaled = SVector::<f64, N>::from_fn(|k, _| p.mass[k].sqrt() * p.qd0[k]);
        let e = SVector::<f64, N>::from_fn(|k, _| p.force[k] / p.mass[k].sqrt());
        let (gamma, w) = if norm(&e) > 0.0 {
            let e = e / norm(&e);
            // Projected twice: once leaves a part along e of rounding size relative to q̇0, which
            // matters where γ is small; twice, relative to the part across.
            let across = scaled - e * scaled.dot(&e);
            let across = across - e * across.dot(&e);
            let w = SVector::<f64, N>::from_fn(|k, _| across[k] / p.mass[k].sqrt());
            ((norm(&across) / norm(&scaled)).min(1.0), w)
        } else {
            (1.0, p.qd0)
        };
        let u = if b > 0.0 {
            p.force.component_div(&p.mass) / b.sqrt()
        } else {
            SVector::zeros()
        };
        let beta = if b > 0.0 {
            (a / b.sqrt()).clamp(-1.0, 1.0)
        } else {
            0.0
        };
        let (one_plus, one_minus) = if beta >= 0.0 {
            (1.0 + beta, gamma * gamma / (1.0 + beta))
        } else {
            (gamma * gamma / (1.0 - beta), 1.0 - beta)
        };
        Ok(Self {
            p: *p,
            k0,
            a,
            b,
            gamma,
            beta,
            one_plus,
            one_minus,
            u,
            w,
        })
    }

    /// `(a, b)`: `a = F·q̇0 / 2K0` (the initial friction coefficient) and
    /// `b = Σ F_k²/m_k / 2K0` (the squared inverse time scale of the field).
    pub fn coefficients(&self) -> (f64, f64) {
        (self.a, self.b)
    }

    /// The kinetic energy `K0`.
    pub fn kinetic_energy(&self) -> f64 {
        self.k0
    }

    /// `(s, ṡ)` at `t` (both grow like `e^(√b |t|)` and overflow beyond `√b |t| ≈ 709`; the
    /// velocity and the multiplier use their ratio, which does not).
    pub fn s(&self, t: f64) -> (f64, f64) {
        let (s, sd, c) = self.s_scaled(t);
        (s / c, sd / c)
    }

    /// `(c s, c ṡ, c)` with `c = 1` for `|x| < 1` and `c = 2 e^(−|x|)` beyond, `x = √b t`.
    ///
    /// For `|x| < 1`: `s = ½ a t² sinhc²(x/2) + t sinhc(x)` (the first term is at most 0.55 times
    /// the second) and `ṡ = cosh x + a t sinhc(x)`. Beyond, with `(A, B) = (1 ± β, 1 ∓ β)` (upper
    /// signs for `t > 0`) and `y = |x|`: `c ṡ = A + B e^(−2y)` and
    /// `c s = ± (−expm1(−y)) (A + B e^(−y)) / √b`, sums of terms of one sign.
    fn s_scaled(&self, t: f64) -> (f64, f64, f64) {
        let r = self.b.sqrt();
        let x = r * t;
        if x.abs() < 1.0 {
            let h = sinhc(0.5 * x);
            let s = 0.5 * self.a * t * t * h * h + t * sinhc(x);
            let sd = x.cosh() + self.a * t * sinhc(x);
            (s, sd, 1.0)
        } else {
            let (ahead, behind, sign) = if t >= 0.0 {
                (self.one_plus, self.one_minus, 1.0)
            } else {
                (self.one_minus, self.one_plus, -1.0)
            };
            let (y, e) = (x.abs(), (-x.abs()).exp());
            let s = sign * -(-y).exp_m1() * (ahead + behind * e) / r;
            let sd = ahead + behind * e * e;
            (s, sd, 2.0 * e)
        }
    }

    /// `ln ṡ(t)`.
    fn ln_sd(&self, t: f64) -> f64 {
        let r = self.b.sqrt();
        let x = r * t;
        if x.abs() < 1.0 {
            let sh = (0.5 * x).sinh();
            (2.0 * sh * sh + self.a * t * sinhc(x)).ln_1p()
        } else {
            // ṡ = ½ e^|x| [(1 ± β) + (1 ∓ β) e^(−2|x|)], upper signs for t > 0: the larger term
            // taken out, in logarithms, so that neither underflows.
            let (la, lb, _) = self.ln_ends(t);
            let y = x.abs();
            let l = la - lb + 2.0 * y;
            if l >= 0.0 {
                y + la - std::f64::consts::LN_2 + (-l).exp().ln_1p()
            } else {
                lb - y - std::f64::consts::LN_2 + l.exp().ln_1p()
            }
        }
    }

    /// `(ln A, ln B, ±1)` with `(A, B) = (1 ± β, 1 ∓ β)`, upper signs for `t ≥ 0`: the weights
    /// of `e^|x|` and `e^(−|x|)` in `2ṡ`, in logarithms from `γ` (`(1 + β)(1 − β) = γ²`), so that
    /// the smaller of them does not underflow where `γ` is tiny.
    fn ln_ends(&self, t: f64) -> (f64, f64, f64) {
        let small = 2.0 * self.gamma.ln();
        let (ln_plus, ln_minus) = if self.beta >= 0.0 {
            let big = self.one_plus.ln();
            (big, small - big)
        } else {
            let big = self.one_minus.ln();
            (small - big, big)
        };
        if t >= 0.0 {
            (ln_plus, ln_minus, 1.0)
        } else {
            (ln_minus, ln_plus, -1.0)
        }
    }

    /// `(v, g)` such that `q̇ = v u + g w` and `μ = −√b v`, beyond `√b |t| = 1`.
    ///
    /// With `y = √b |t|`, `(A, B)` and `σ` as in [`ClosedForm::ln_ends`], and `c = 2 e^(−y)`:
    /// `c (q̇0 + M⁻¹F s) = σ u (A − B e^(−2y)) + 2 e^(−y) w` and `c ṡ = A + B e^(−2y)`, so
    /// `v = σ (A − B e^(−2y)) / (A + B e^(−2y))`, `g = 2 e^(−y) / (A + B e^(−2y))`, each divided
    /// through by its larger term. Since `A B = γ²`, `v² + γ² g² = 1`: the kinetic energy stays
    /// `K0` to rounding, and nothing cancels (near `β = −1` the textbook form cancels to rounding
    /// amplified by `e^y`).
    fn turning(&self, t: f64) -> (f64, f64) {
        let (la, lb, sign) = self.ln_ends(t);
        let (v, g) = turning(la, lb, self.b.sqrt() * t.abs());
        (sign * v, g)
    }

    /// `G(t) = ∫₀ᵗ dτ / ṡ(τ)`. With `r = √b`, `β = a/r`, `γ = √(1 − β²)`, `w = tanh(r t/2)`, the
    /// substitution `w = tanh(r τ/2)` turns the integrand into a rational function:
    /// `G = (2/(r γ)) arctan(γ w / (1 + β w))`, evaluated as
    /// `t tanhc(r t/2) / (1 + β w) · atanc(γ w / (1 + β w))`, which stays exact as `γ → 0`
    /// (`q̇0` along `M⁻¹F`) and `r → 0` (a weak field).
    pub fn g(&self, t: f64) -> f64 {
        let r = self.b.sqrt();
        let x = 0.5 * r * t;
        let w = x.tanh();
        // 1 + β w = (1 ± β) ∓ β (1 − |w|), 1 − |w| = 2 e^(−2|x|) / (1 + e^(−2|x|)): no cancellation
        // where β w → −1.
        let e = (-2.0 * x.abs()).exp();
        let rest = 2.0 * e / (1.0 + e);
        let one_plus_beta_w = if t >= 0.0 {
            self.one_plus - self.beta * rest
        } else {
            self.one_minus + self.beta * rest
        };
        if self.gamma == 0.0 {
            // Along the field `G` stays below `t`; against it, it is `(e^(√b t) − 1)/√b`.
            return t * tanhc(x) / one_plus_beta_w;
        }
        let z = w / one_plus_beta_w;
        let across = self.gamma * z;
        if across.abs() > 1.0 {
            // The same as `(2/(√b γ)) arctan(γ z)` (`t tanhc(x)/w = 2/√b`), which holds where
            // `1 + β w` underflows (`γ` below about `1e-154`, `√b |t|` beyond about 372).
            return t * tanhc(x) / w * across.atan() / self.gamma;
        }
        t * tanhc(x) / one_plus_beta_w * atanc(across)
    }

    /// Whether the motion is uniform, `q = q0 + q̇0 t`: without a field, or with the velocity
    /// exactly along or against it (`γ = 0`), where it cannot turn. Against the field the general
    /// forms would cancel to rounding amplified by `e^(√b t)`.
    fn uniform(&self) -> bool {
        self.b == 0.0 || self.gamma == 0.0
    }

    /// `q(t) = q0 + q̇0 G + M⁻¹F (ln ṡ − a G)/b = q0 + w G + u ln ṡ / √b` (`q0 + q̇0 t` where the
    /// motion is uniform): the second form, with nothing to cancel where `G` is large.
    pub fn position(&self, t: f64) -> SVector<f64, N> {
        let p = &self.p;
        if self.uniform() {
            return p.q0 + p.qd0 * t;
        }
        p.q0 + self.w * self.g(t) + self.u * (self.ln_sd(t) / self.b.sqrt())
    }

    /// `q̇(t) = (q̇0 + M⁻¹F s) / ṡ` (`q̇0` where the motion is uniform).
    pub fn velocity(&self, t: f64) -> SVector<f64, N> {
        let p = &self.p;
        if self.uniform() {
            return p.qd0;
        }
        if self.b.sqrt() * t.abs() >= 1.0 {
            let (v, g) = self.turning(t);
            return self.u * v + self.w * g;
        }
        let (s, sd, c) = self.s_scaled(t);
        (p.qd0 * c + p.force.component_div(&p.mass) * s) / sd
    }

    /// The multiplier `μ(t) = −α(t) = −(a + b s)/ṡ` (`−β √b` where the motion is uniform).
    pub fn multiplier(&self, t: f64) -> f64 {
        if self.uniform() {
            return -self.beta * self.b.sqrt();
        }
        if self.b.sqrt() * t.abs() >= 1.0 {
            return -self.b.sqrt() * self.turning(t).0;
        }
        let (s, sd, c) = self.s_scaled(t);
        -(self.a * c + self.b * s) / sd
    }

    /// The energy `E = K − F·q` of a state (`K = Σ ½ m_k q̇_k²`).
    pub fn energy(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> f64 {
        0.5 * self.p.mass.component_mul(qd).dot(qd) - self.p.force.dot(q)
    }
}

impl<const N: usize> Reference<N, 1> for ClosedForm<N> {
    fn sources(&self) -> &[Source] {
        SOURCES
    }

    /// All coordinates (`"q"`: the component with the largest scaled error) and velocities
    /// (`"q̇"`) against the closed form, the kinetic energy `K` and the multiplier.
    fn checks(
        &self,
        t: f64,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        mu: Option<&SVector<f64, 1>>,
    ) -> Vec<Check> {
        let (qr, vr) = (self.position(t), self.velocity(t));
        // Scales: a coordinate's speed by the largest speed it can reach, √(2K0/m_k); its position
        // by that speed times max(|t|, 1/√b), the distance it can cover in the time elapsed or in
        // the field's time scale.
        let time = if self.b > 0.0 {
            t.abs().max(1.0 / self.b.sqrt())
        } else {
            t.abs()
        };
        let worst = |name: &'static str,
                     kind: Kind,
                     x: &SVector<f64, N>,
                     r: &SVector<f64, N>,
                     per_time: f64| {
            (0..N)
                .map(|k| {
                    let speed = (2.0 * self.k0 / self.p.mass[k]).sqrt();
                    Check::new(name, kind, x[k], r[k], speed * per_time)
                })
                .max_by(|a, b| a.error().total_cmp(&b.error()))
        };
        let mut out = Vec::with_capacity(4);
        out.extend(worst("q", Kind::Position, q, &qr, time));
        out.extend(worst("q̇", Kind::Velocity, qd, &vr, 1.0));
        let kinetic = 0.5 * self.p.mass.component_mul(qd).dot(qd);
        out.push(Check::new("K", Kind::Invariant, kinetic, self.k0, self.k0));
        if let Some(mu) = mu {
            // |α| ≤ √b (Cauchy–Schwarz), so √b is the multiplier's scale.
            let scale = self.b.sqrt();
            out.push(Check::multiplier(mu[0], self.multiplier(t), scale));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn branches_agree_at_the_switch_and_nothing_overflows() {
        let p = Params::four_particles();
        let cf = ClosedForm::new(&p).expect("valid");
        let r = cf.b.sqrt();
        // Across √b |t| = 1 the two evaluations of s, ṡ, ln ṡ meet to rounding.
        for t in [1.0 / r, -1.0 / r] {
            let (below, above) = (t * (1.0 - 1e-15), t * (1.0 + 1e-15));
            let (s0, sd0) = cf.s(below);
            let (s1, sd1) = cf.s(above);
            assert!((s0 - s1).abs() <= 1e-14 * s0.abs(), "s at {t}");
            assert!((sd0 - sd1).abs() <= 1e-14 * sd0, "ṡ at {t}");
            assert!(
                (cf.ln_sd(below) - cf.ln_sd(above)).abs() <= 1e-14,
                "ln ṡ at {t}"
            );
            assert!((cf.ln_sd(above) - sd1.ln()).abs() <= 1e-14, "ln ṡ at {t}");
        }
        // Far out (√b t = 2000, where e^(√b t) overflows) the velocity keeps K = K0, everything
        // stays finite, and the velocity has turned along M⁻¹F, where α = √b.
        let t = 2000.0 / r;
        let v = cf.velocity(t);
        let k = 0.5 * p.mass.component_mul(&v).dot(&v);
        assert!((k - cf.k0).abs() <= 1e-14 * cf.k0, "K = {k}");
        assert!(cf.multiplier(t).is_finite() && cf.position(t).iter().all(|x| x.is_finite()));
        assert!((cf.multiplier(t) + r).abs() <= 1e-14 * r);
    }

    #[test]
    fn the_velocity_and_the_multiplier_meet_at_the_switch_and_keep_the_kinetic_energy() {
        // Generic, and nearly against the field (γ about 1e-3 and 1e-9), where the textbook form
        // (q̇0 + M⁻¹F s)/ṡ loses K0 to rounding amplified by e^(√b t).
        let mut cases = vec![Params::four_particles()];
        for tilt in [1e-3, 1e-9] {
            let mut p = Params::four_particles();
            p.qd0 = -p.force.component_div(&p.mass);
            p.qd0[0] += tilt;
            cases.push(p);
        }
        for p in cases {
            let cf = ClosedForm::new(&p).expect("valid");
            let r = cf.b.sqrt();
            for t in [1.0 / r, -1.0 / r] {
                let (below, above) = (t * (1.0 - 1e-15), t * (1.0 + 1e-15));
                let (v0, v1) = (cf.velocity(below), cf.velocity(above));
                assert!((v0 - v1).norm() <= 1e-13 * v0.norm(), "q̇ at {t}");
                let (m0, m1) = (cf.multiplier(below), cf.multiplier(above));
                assert!((m0 - m1).abs() <= 1e-13 * r, "μ at {t}");
            }
            for x in [-700.0, -30.0, -3.0, 3.0, 30.0, 300.0, 700.0, 2000.0] {
                let t = x / r;
                let v = cf.velocity(t);
                let k = 0.5 * p.mass.component_mul(&v).dot(&v);
                assert!(
                    (k - cf.k0).abs() <= 1e-14 * cf.k0,
                    "γ = {}, x = {x}: K = {k}",
                    cf.gamma
                );
                let mu = cf.multiplier(t);
                assert!(mu.abs() <= r * (1.0 + 1e-15), "μ = {mu}");
                assert!(cf.position(t).iter().all(|q| q.is_finite()), "x = {x}");
            }
        }
    }

    #[test]
    fn a_velocity_a_hair_off_against_the_field_turns_round_however_small_the_hair() {
        // One particle, m = 1, F = (0, −2), q̇0 = (ε, 1) (γ = ε to first order; √b = 2): the
        // velocity turns over near √b t = ln(2/γ) and ends along the field, μ → −√b. Squares of
        // components below 1e-154 underflow, and γ² below 1e-308: neither may make the motion
        // uniform, nor the position NaN. The last case has γ = 1e-70 of components 1e-170, 1e-100.
        for qd0 in [
            [1e-3, 1.0],
            [1e-9, 1.0],
            [1e-160, 1.0],
            [1e-200, 1.0],
            [1e-170, 1e-100],
        ] {
            let p = Params::<2> {
                mass: SVector::from([1.0, 1.0]),
                force: SVector::from([0.0, -2.0]),
                q0: SVector::zeros(),
                qd0: SVector::from(qd0),
            };
            let cf = ClosedForm::new(&p).expect("valid");
            let speed = qd0[0].hypot(qd0[1]);
            let gamma = qd0[0] / speed;
            assert!(
                (cf.gamma - gamma).abs() <= 1e-15 * gamma,
                "{qd0:?}: γ = {}",
                cf.gamma
            );
            let r = cf.b.sqrt();
            let turn = (2.0 / gamma).ln();
            for x in [3.0, 0.5 * turn, turn, 2.0 * turn, 2000.0] {
                let t = x / r;
                let v = cf.velocity(t);
                // Near the turn the speed is exact to the rounding of the exponent `x` (ε x).
                assert!(
                    (v.norm() - speed).abs() <= 4.0 * f64::EPSILON * (1.0 + x) * speed,
                    "{qd0:?}, x = {x}: {v}"
                );
                let mu = cf.multiplier(t);
                assert!(mu.is_finite() && mu.abs() <= r * (1.0 + 1e-15), "μ = {mu}");
                let q = cf.position(t);
                assert!(q.iter().all(|q| q.is_finite()), "{qd0:?}, x = {x}: {q}");
            }
            // Long after the turn: along the field, where μ = −√b.
            let t = 2000.0 / r;
            assert!((cf.multiplier(t) + r).abs() <= 1e-14 * r, "{qd0:?}");
            assert!(
                (cf.velocity(t)[1] + speed).abs() <= 1e-14 * speed,
                "{qd0:?}"
            );
        }
    }
}
