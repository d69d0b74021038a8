//! The two benchmark problems: their data, references, and right-hand sides written by hand in
//! Rust for chetaev's driver (the same expressions, in the same order, as `fortran/rhs.f`).

use chetaev::integrate::system::{Jacobian, OdeSystem};
use chetaev::Error;
use uniform_projectile::closed_form::{uniform, Params};

/// Which problem (also selects the Fortran right-hand side).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProblemId {
    /// The Arenstorf orbit of the restricted three-body problem.
    Arenstorf,
    /// The particle under the constant-speed constraint (the paper's uniform horizontal projectile).
    Particle,
}

/// A problem `y' = F(t, y)`, `y(t0) = y0`, integrated to `t1`, with the exact `y(t1)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    /// Which problem.
    pub id: ProblemId,
    /// Short name for tables.
    pub name: &'static str,
    /// Initial time.
    pub t0: f64,
    /// Final time.
    pub t1: f64,
    /// Initial state.
    pub y0: [f64; 4],
    /// Parameters (Hairer's RPAR): `[mu]` or `[g]`.
    pub params: Vec<f64>,
    /// The exact state at `t1`.
    pub reference: [f64; 4],
    /// Where the reference comes from.
    pub reference_source: &'static str,
}

impl Problem {
    /// The Euclidean norm of `y − reference`, the error reported by the benchmark.
    pub fn error(&self, y: &[f64]) -> f64 {
        y.iter()
            .zip(&self.reference)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt()
    }
}

/// The Arenstorf orbit (Hairer, Nørsett, Wanner, *Solving ODEs I*, Section II.0, eq. (0.1)):
/// `μ = 0.012277471`, `y0 = (0.994, 0, 0, −2.00158510637908252240537862224)`, one period
/// `T = 17.0652165601579625588917206249`.
///
/// The orbit closes for these 30-digit data; the problem integrated here has their
/// double-precision values instead, and the orbit amplifies that difference (up to 1e-16) to
/// `1.4e-11` after one period. The reference is therefore the solution of the double-precision
/// problem, computed by DOP853 in quadruple precision at `rtol = atol = 1e-28`
/// (`fortran/reference_quad.f90`; the run at `1e-25` agrees to `1e-23`), rounded to double.
#[allow(clippy::excessive_precision)] // the digits as published and as computed
pub fn arenstorf() -> Problem {
    Problem {
        id: ProblemId::Arenstorf,
        name: "Arenstorf",
        t0: 0.0,
        t1: 17.0652165601579625588917206249,
        y0: [0.994, 0.0, 0.0, -2.00158510637908252240537862224],
        params: vec![0.012277471],
        reference: [
            9.939999999999739957652582332713219e-1,
            -8.855134620122372318957576577185312e-14,
            -1.438866735732021112700751489924004e-11,
            -2.001585106383129019842013162394493,
        ],
        reference_source: "DOP853 in quadruple precision at 1e-28 (the orbit closes to 1.5e-11)",
    }
}

/// The particle under the constant-speed constraint `|v| = v0` in the field `(0, −g)`
/// (Swaczyna and Volný, Section 42.3), with the data of Section 42.5: `g = 10`, `v0 = 10`,
/// `h0 = 5`, from `(0, 5, 10, 0)` to the impact `T = (v0/g) arccosh(exp(g h0 / v0²)) =
/// arccosh(e^0.5)`. The reference is the closed form (42.29)–(42.30) at `T`:
/// `x = (v0²/g) · 2 atan(tanh(gT / 2v0))`, `y = h0 − (v0²/g) ln cosh(gT/v0) = 0`,
/// `v = v0 (sech(gT/v0), −tanh(gT/v0))`.
pub fn particle() -> Problem {
    let p = Params::PAPER;
    let t1 = uniform::kinematics(&p).t_impact;
    let [x, y] = uniform::position(&p, t1);
    let [vx, vy] = uniform::velocity(&p, t1);
    Problem {
        id: ProblemId::Particle,
        name: "particle",
        t0: 0.0,
        t1,
        y0: [0.0, p.h0, p.v0, 0.0],
        params: vec![p.g],
        reference: [x, y, vx, vy],
        reference_source: "the closed form (42.29)-(42.30) of uniform-projectile",
    }
}

/// The Arenstorf right-hand side, state `(y1, y2, y1', y2')`, with `μ' = 1 − μ`,
/// `D1 = ((y1 + μ)² + y2²)^(3/2)`, `D2 = ((y1 − μ')² + y2²)^(3/2)`:
///
/// ```text
/// y1'' = y1 + 2 y2' − μ' (y1 + μ) / D1 − μ (y1 − μ') / D2
/// y2'' = y2 − 2 y1' − μ' y2 / D1 − μ y2 / D2
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArenstorfRhs {
    /// The mass ratio `μ`.
    pub mu: f64,
    /// Right-hand side evaluations so far.
    pub evaluations: usize,
}

impl ArenstorfRhs {
    /// The system for the problem's `μ`.
    pub fn new(problem: &Problem) -> Self {
        Self {
            mu: problem.params[0],
            evaluations: 0,
        }
    }
}

impl OdeSystem for ArenstorfRhs {
    fn dim(&self) -> usize {
        4
    }
    fn controlled_dim(&self) -> usize {
        4
    }
    #[inline]
    fn rhs(&mut self, _t: f64, y: &[f64], f: &mut [f64]) -> Result<(), Error> {
        self.evaluations += 1;
        let amu = self.mu;
        let amup = 1.0 - amu;
        f[0] = y[2];
        f[1] = y[3];
        let mut r1 = (y[0] + amu) * (y[0] + amu) + y[1] * y[1];
        r1 *= r1.sqrt();
        let mut r2 = (y[0] - amup) * (y[0] - amup) + y[1] * y[1];
        r2 *= r2.sqrt();
        f[2] = y[0] + 2.0 * y[3] - amup * (y[0] + amu) / r1 - amu * (y[0] - amup) / r2;
        f[3] = y[1] - 2.0 * y[2] - amup * y[1] / r1 - amu * y[1] / r2;
        Ok(())
    }
    /// `∂F/∂y`, row-major 4 × 4; with `d1 = y1 + μ`, `d2 = y1 − μ'`, `r_i² = d_i² + y2²`:
    /// `∂y1''/∂y1 = 1 − Σ m_i (1/r_i³ − 3 d_i²/r_i⁵)`, `∂y1''/∂y2 = ∂y2''/∂y1 = Σ 3 m_i d_i y2/r_i⁵`,
    /// `∂y2''/∂y2 = 1 − Σ m_i (1/r_i³ − 3 y2²/r_i⁵)`, `∂y1''/∂y2' = 2`, `∂y2''/∂y1' = −2`, with
    /// `m_1 = μ'`, `m_2 = μ`. Only implicit methods call it.
    fn jacobian(&mut self, _t: f64, y: &[f64], out: &mut Jacobian) -> Result<(), Error> {
        let Jacobian { dy: jac, dt: dfdt } = out;
        let (amu, amup) = (self.mu, 1.0 - self.mu);
        let (mut a11, mut a12, mut a22) = (1.0, 0.0, 1.0);
        for (m, d) in [(amup, y[0] + amu), (amu, y[0] - amup)] {
            let r2 = d * d + y[1] * y[1];
            let r3 = r2 * r2.sqrt();
            let r5 = r3 * r2;
            a11 -= m * (1.0 / r3 - 3.0 * d * d / r5);
            a12 += 3.0 * m * d * y[1] / r5;
            a22 -= m * (1.0 / r3 - 3.0 * y[1] * y[1] / r5);
        }
        jac.fill(0.0);
        dfdt.fill(0.0);
        jac[2] = 1.0;
        jac[4 + 3] = 1.0;
        jac[8] = a11;
        jac[8 + 1] = a12;
        jac[8 + 3] = 2.0;
        jac[12] = a12;
        jac[12 + 1] = a22;
        jac[12 + 2] = -2.0;
        Ok(())
    }
}

/// The constant-speed particle, state `(x, y, vx, vy)`: `a = g⃗ − (g⃗·v) v / |v|²`, `g⃗ = (0, −g)`,
/// i.e. with `c = g vy / |v|²`: `x'' = c vx`, `y'' = −g + c vy`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParticleRhs {
    /// Gravitational acceleration `g`.
    pub g: f64,
    /// Right-hand side evaluations so far.
    pub evaluations: usize,
}

impl ParticleRhs {
    /// The system for the problem's `g`.
    pub fn new(problem: &Problem) -> Self {
        Self {
            g: problem.params[0],
            evaluations: 0,
        }
    }
}

impl OdeSystem for ParticleRhs {
    fn dim(&self) -> usize {
        4
    }
    fn controlled_dim(&self) -> usize {
        4
    }
    #[inline]
    fn rhs(&mut self, _t: f64, y: &[f64], f: &mut [f64]) -> Result<(), Error> {
        self.evaluations += 1;
        let g = self.g;
        f[0] = y[2];
        f[1] = y[3];
        let v2 = y[2] * y[2] + y[3] * y[3];
        let c = g * y[3] / v2;
        f[2] = c * y[2];
        f[3] = -g + c * y[3];
        Ok(())
    }
    /// `∂F/∂y`, row-major 4 × 4; with `s = |v|²`: `∂x''/∂vx = g vy (s − 2vx²)/s²`,
    /// `∂x''/∂vy = g vx (s − 2vy²)/s²`, `∂y''/∂vx = −2 g vx vy²/s²`, `∂y''/∂vy = 2 g vy vx²/s²`.
    /// Only implicit methods call it.
    fn jacobian(&mut self, _t: f64, y: &[f64], out: &mut Jacobian) -> Result<(), Error> {
        let Jacobian { dy: jac, dt: dfdt } = out;
        let (vx, vy, g) = (y[2], y[3], self.g);
        let s = vx * vx + vy * vy;
        let s2 = s * s;
        jac.fill(0.0);
        dfdt.fill(0.0);
        jac[2] = 1.0;
        jac[4 + 3] = 1.0;
        jac[8 + 2] = g * vy * (s - 2.0 * vx * vx) / s2;
        jac[8 + 3] = g * vx * (s - 2.0 * vy * vy) / s2;
        jac[12 + 2] = -2.0 * g * vx * vy * vy / s2;
        jac[12 + 3] = 2.0 * g * vy * vx * vx / s2;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hairer;

    fn states() -> Vec<[f64; 4]> {
        vec![
            [0.994, 0.0, 0.0, -2.001585106379082],
            [-0.3, 0.7, 1.1, -0.4],
            [1.2, -0.05, -0.2, 0.9],
            [3.0, 4.2, 9.0, -4.3],
        ]
    }

    fn within_ulps(a: f64, b: f64, ulps: f64) -> bool {
        (a - b).abs() <= ulps * f64::EPSILON * a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
    }

    fn agrees_with_fortran<S: OdeSystem>(mut sys: S, p: &Problem) -> Result<(), Error> {
        for y in states() {
            let (mut fr, mut ff) = ([0.0; 4], [0.0; 4]);
            sys.rhs(0.3, &y, &mut fr)?;
            hairer::rhs(p.id, &p.params, 0.3, &y, &mut ff);
            for i in 0..4 {
                assert!(
                    within_ulps(fr[i], ff[i], 4.0),
                    "{}: component {i} at {y:?}: Rust {} vs Fortran {}",
                    p.name,
                    fr[i],
                    ff[i]
                );
            }
        }
        Ok(())
    }

    #[test]
    fn rust_right_hand_sides_agree_with_the_fortran_ones() -> Result<(), Error> {
        let (a, b) = (arenstorf(), particle());
        agrees_with_fortran(ArenstorfRhs::new(&a), &a)?;
        agrees_with_fortran(ParticleRhs::new(&b), &b)
    }

    fn jacobian_matches_differences<S: OdeSystem>(mut sys: S) -> Result<(), Error> {
        for y in states() {
            let mut jacobian = Jacobian::new(4);
            sys.jacobian(0.0, &y, &mut jacobian)?;
            let jac = jacobian.dy;
            for j in 0..4 {
                let h = 1e-6 * y[j].abs().max(1.0);
                let (mut yp, mut ym) = (y, y);
                yp[j] += h;
                ym[j] -= h;
                let (mut fp, mut fm) = ([0.0; 4], [0.0; 4]);
                sys.rhs(0.0, &yp, &mut fp)?;
                sys.rhs(0.0, &ym, &mut fm)?;
                for i in 0..4 {
                    let fd = (fp[i] - fm[i]) / (2.0 * h);
                    let exact = jac[i * 4 + j];
                    // Central differences: error O(h²·|F'''|) plus rounding O(ε|F|/h).
                    assert!(
                        (fd - exact).abs() <= 1e-6 * exact.abs().max(1.0),
                        "∂F{i}/∂y{j} at {y:?}: {exact} vs difference {fd}"
                    );
                }
            }
        }
        Ok(())
    }

    #[test]
    fn jacobians_match_central_differences() -> Result<(), Error> {
        jacobian_matches_differences(ArenstorfRhs::new(&arenstorf()))?;
        jacobian_matches_differences(ParticleRhs::new(&particle()))
    }

    #[test]
    fn arenstorf_reference_is_one_period_of_a_closed_orbit() {
        let p = arenstorf();
        // The double-precision data close the orbit to about 1.5e-11 (see `arenstorf`).
        let gap = p.error(&p.y0);
        assert!(gap > 1e-12 && gap < 2e-11, "|y(T) - y0| = {gap}");
    }

    #[test]
    fn particle_reference_lands_on_the_ground_at_the_constant_speed() {
        let p = particle();
        let [_, y, vx, vy] = p.reference;
        assert!(y.abs() < 1e-14, "y(T) = {y}");
        assert!(((vx * vx + vy * vy).sqrt() - 10.0).abs() < 1e-13);
        // T = arccosh(e^0.5) for g = v0 = 10, h0 = 5.
        assert!((p.t1 - 0.5f64.exp().acosh()).abs() < 1e-15);
    }
}
