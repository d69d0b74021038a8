//! The verification of `chetaev` against the paper's closed forms: the verdict, Table 42.1
//! rebuilt, the largest errors along both motions, observed orders of convergence, and error
//! against run time.
//!
//! Everything here returns values; the binary prints them.

use std::time::Instant;

use chetaev::integrate::{Method, MethodInfo};
use chetaev::prelude::*;
use serde::Serialize;

use crate::closed_form::{classical, table, uniform, Kinematics, Params};
use crate::model::{
    classical_problem, impact, scaled_atol, seeds, uniform_problem, UniformProblem,
};
use chetaev::num_dual::Dual64;

/// One quantity: numerical beside closed form.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Compared {
    /// From the integration.
    pub numerical: f64,
    /// From the closed form.
    pub closed_form: f64,
    /// `|numerical − closed_form| / |closed_form|`.
    pub rel_error: f64,
}

/// One row of Table 42.1 as five numbers (JSON field names as in the paper).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Row {
    /// Time of flight.
    #[serde(rename = "T")]
    pub t: f64,
    /// Range.
    #[serde(rename = "R")]
    pub r: f64,
    /// Impact speed.
    #[serde(rename = "v_R")]
    pub v_r: f64,
    /// Impact angle below the horizontal, degrees.
    pub impact_angle_deg: f64,
    /// Length of the trajectory.
    pub s: f64,
}

impl From<Kinematics> for Row {
    fn from(k: Kinematics) -> Self {
        Self {
            t: k.t_impact,
            r: k.range,
            v_r: k.impact_speed,
            impact_angle_deg: k.impact_angle_deg(),
            s: k.length,
        }
    }
}

/// One motion's row, numerical and closed form, with relative errors.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct TableRow {
    /// From `chetaev`.
    pub numerical: Row,
    /// From the closed forms.
    pub closed_form: Row,
    /// Relative errors, field by field.
    pub rel_error: Row,
}

/// Table 42.1.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Table {
    /// The classical projectile.
    pub classical: TableRow,
    /// The uniform projectile.
    pub uniform: TableRow,
}

/// Largest errors along a motion, each relative to the scale named in its doc.
#[derive(Clone, Debug, Default, Serialize)]
pub struct MotionErrors {
    /// `x`, relative to the range.
    pub x: f64,
    /// `y`, relative to `h0`.
    pub y: f64,
    /// `ẋ`, relative to `v0`.
    pub xd: f64,
    /// `ẏ`, relative to the impact speed.
    pub yd: f64,
    /// `ẍ`, relative to `g`.
    pub xdd: f64,
    /// `ÿ`, relative to `g`.
    pub ydd: f64,
    /// Curvature (42.13)/(42.36), relative to its largest value `g/v0²`.
    pub curvature: f64,
    /// `μ` (42.40), relative to `m g / (2 v0)` (uniform motion only).
    pub mu: Option<f64>,
    /// `|Φ|` (42.42), relative to `m g` (uniform motion only).
    pub phi: Option<f64>,
    /// Largest constraint residual `|f|`, relative to `v0²` (uniform motion only).
    pub residual: Option<f64>,
    /// Largest `|W_Φ − m g (y − h0)|`, relative to `m g h0`: the work of the Chetaev force against the
    /// change of potential energy (uniform motion only).
    pub work_vs_potential: Option<f64>,
    /// Largest `|E − E0 − W_Φ + ∫∂L/∂t|`, relative to `m v0² + m g h0`.
    pub energy_balance: f64,
    /// Points compared.
    pub points: usize,
}

/// An observed order of convergence.
#[derive(Clone, Debug, Serialize)]
pub struct Convergence {
    /// The method.
    pub method: String,
    /// What was refined: `"h"` (fixed steps halving: the order of the method) or `"tolerance"`
    /// (the exponent α of error ∝ tol^α as the tolerance tightens: 1 for proportionality).
    pub against: String,
    /// `(parameter, error)` pairs.
    pub points: Vec<(f64, f64)>,
    /// Observed order (least-squares slope of `log error` against `log h` or `log tol`); `None`
    /// where the errors show none ([`observed_order`]).
    pub order: Option<f64>,
    /// The theoretical order.
    pub expected: f64,
}

/// One point of the error-against-run-time study.
#[derive(Clone, Debug, Serialize)]
pub struct WorkPoint {
    /// The method.
    pub method: String,
    /// The tolerance asked for (or the step for a fixed-step method).
    pub tolerance: f64,
    /// Whether `tolerance` is the step of a fixed-step method.
    pub fixed_step: bool,
    /// Largest error of `(q, q̇)` at the end (positions relative to `max(h0, R)`, velocities to `v0`).
    pub error: f64,
    /// Median wall time of repeated runs, seconds.
    pub seconds: f64,
    /// Repetitions timed.
    pub repeats: usize,
    /// Right-hand-side evaluations.
    pub rhs_evaluations: usize,
    /// Accepted steps.
    pub steps: usize,
}

/// A study of [`Report::convergence`] or [`Report::work_precision`] that stopped: a solve of it
/// ended before its end time (a stiff problem for an explicit method, the step limit, a step so
/// long that the motion leaves the constraints' domain); the rest of that method's study is not
/// run, and a convergence study is left out.
#[derive(Clone, Debug, Serialize)]
pub struct Stopped {
    /// The method.
    pub method: String,
    /// `"h"` (fixed steps) or `"tolerance"`, as in [`Convergence::against`].
    pub study: String,
    /// The step or tolerance of the run that stopped.
    pub at: f64,
    /// Why, as the library says it.
    pub error: String,
}

/// Which of the optional studies [`build`] computes. The verdict's quantities (Table 42.1, the
/// errors along both motions, the impact's derivatives) are always computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Studies {
    /// Observed orders of convergence: every method in fixed steps, and the adaptive ones against
    /// the tolerance.
    pub orders: bool,
    /// Error against run time: every method, timed over repeated runs.
    pub timing: bool,
}

impl Studies {
    /// Both studies.
    pub const ALL: Self = Self {
        orders: true,
        timing: true,
    };
    /// Neither: the verdict alone.
    pub const NONE: Self = Self {
        orders: false,
        timing: false,
    };
}

/// The relative error accepted by default, as a multiple of the tolerance asked for.
///
/// Dop853 at `rtol = atol = tol` keeps every compared quantity of the paper's data within about
/// `tol` (largest observed: 0.23 `tol`, for `y` along the uniform motion at `tol = 1e-12`); the
/// limit leaves a margin of a hundred for other parameters and machines.
pub const LIMIT_PER_TOLERANCE: f64 = 100.0;

/// Whether the numerics agree with the closed forms, and how closely.
#[derive(Clone, Debug, Serialize)]
pub struct Verdict {
    /// Every compared quantity is finite and at or below `limit`.
    pub verified: bool,
    /// The largest relative error over every compared quantity (NaN if one of them is NaN).
    pub largest: f64,
    /// Which quantity has the largest error (the first NaN if there is one), e.g.
    /// `"uniform motion: y"`.
    pub largest_of: String,
    /// The largest relative error accepted.
    pub limit: f64,
    /// The number of quantities compared.
    pub compared: usize,
}

impl Verdict {
    /// Judges `(name, relative error)` pairs against `limit`: verified when every error is a
    /// number at or below `limit` (a NaN or an infinity fails, and is reported as the largest).
    /// No pairs at all is not verified.
    #[must_use]
    pub fn judge(errors: &[(String, f64)], limit: f64) -> Self {
        let worst = errors
            .iter()
            .find(|(_, e)| !e.is_finite())
            .or_else(|| errors.iter().max_by(|a, b| a.1.total_cmp(&b.1)));
        let (largest_of, largest) =
            worst.map_or((String::new(), f64::NAN), |(n, e)| (n.clone(), *e));
        Self {
            verified: !errors.is_empty() && largest.is_finite() && largest <= limit,
            largest,
            largest_of,
            limit,
            compared: errors.len(),
        }
    }
}

/// Everything the verification computes.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Every quantity below compared against its closed form, judged against
    /// [`LIMIT_PER_TOLERANCE`] `× tolerance` (see [`Report::judge`] for another limit).
    pub verdict: Verdict,
    /// The parameters.
    pub params: ParamsOut,
    /// The method of the table, error and derivative runs, as in the literature (`"Dop853"`).
    pub method: String,
    /// The tolerance of the table and error runs (relative and absolute).
    pub tolerance: f64,
    /// The absolute tolerances of `x`, `y`, `ẋ`, `ẏ` in those runs: `tolerance`, or less where the
    /// motion's scale is below one (see [`absolute_tolerances`]).
    pub atol: [f64; 4],
    /// Table 42.1 rebuilt.
    pub table: Table,
    /// Largest errors along the classical motion.
    pub classical_errors: MotionErrors,
    /// Largest errors along the uniform motion.
    pub uniform_errors: MotionErrors,
    /// Observed orders.
    pub convergence: Vec<Convergence>,
    /// The end of the fixed-step runs of [`Report::convergence`]: the impact `T`, or `4 v0/g` if
    /// that is earlier (see [`orders_until`]).
    pub orders_until: f64,
    /// Error against run time.
    pub work_precision: Vec<WorkPoint>,
    /// The studies that stopped before their end time, with why (empty when every run reached
    /// it).
    pub stopped: Vec<Stopped>,
    /// Derivatives of the impact's time `T` and place `R` with respect to `v0`, `g`, `h0`, from
    /// the library's sensitivities, against the closed forms' own derivatives.
    pub sensitivities: Vec<Derivative>,
    /// The derivatives ([`Derivative::error`]) judged against the same limit.
    pub sensitivity_verdict: Verdict,
}

/// One derivative of the impact, numerical and closed-form.
#[derive(Clone, Debug, Serialize)]
pub struct Derivative {
    /// Which, e.g. `"∂T/∂v0"`.
    pub name: String,
    /// From the solve's sensitivities.
    pub numerical: f64,
    /// From the closed form (42.38) differentiated by dual numbers.
    pub closed_form: f64,
    /// Relative error, `|numerical − closed_form| / |closed_form|`.
    pub rel_error: f64,
    /// The derivative's natural scale `|Q/θ|`, for `∂Q/∂θ`.
    pub scale: f64,
    /// The error judged by the verdict: `|numerical − closed_form| /
    /// max(|closed_form|, scale)`, the relative error except where the derivative is much smaller
    /// than its scale. There it is a difference of terms of the size of the scale (`∂T/∂v0` tends
    /// to zero as `z = g h0/v0² → 0`, the classical limit; `∂R/∂h0` as `z → ∞`), and no solve in
    /// `f64` could give it to a fixed number of its own digits.
    pub error: f64,
}

/// The parameters, for the report.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ParamsOut {
    /// Initial speed.
    pub v0: f64,
    /// Gravity.
    pub g: f64,
    /// Initial height.
    pub h0: f64,
    /// Mass.
    pub m: f64,
}

impl Report {
    /// Every relative error compared against a closed form (or, for the residual and the energy
    /// balance, against zero): the five columns of both rows of Table 42.1, and the largest errors
    /// along both motions, named as in the text output.
    #[must_use]
    pub fn compared(&self) -> Vec<(String, f64)> {
        let mut v = Vec::new();
        for (motion, row) in [
            ("classical", &self.table.classical),
            ("uniform", &self.table.uniform),
        ] {
            let e = &row.rel_error;
            for (name, x) in [
                ("T", e.t),
                ("R", e.r),
                ("v_R", e.v_r),
                ("impact angle", e.impact_angle_deg),
                ("s", e.s),
            ] {
                v.push((format!("Table 42.1, {motion}: {name}"), x));
            }
        }
        for (motion, e) in [
            ("classical", &self.classical_errors),
            ("uniform", &self.uniform_errors),
        ] {
            for (name, x) in [
                ("x", Some(e.x)),
                ("y", Some(e.y)),
                ("ẋ", Some(e.xd)),
                ("ẏ", Some(e.yd)),
                ("ẍ", Some(e.xdd)),
                ("ÿ", Some(e.ydd)),
                ("curvature", Some(e.curvature)),
                ("μ", e.mu),
                ("|Φ|", e.phi),
                ("|f|", e.residual),
                ("W_Φ − ΔV", e.work_vs_potential),
                ("energy balance", Some(e.energy_balance)),
            ] {
                if let Some(x) = x {
                    v.push((format!("{motion} motion: {name}"), x));
                }
            }
        }
        v
    }

    /// Judges [`Report::compared`] and the derivatives' errors against `limit`.
    pub fn judge(&mut self, limit: f64) {
        self.verdict = Verdict::judge(&self.compared(), limit);
        let derivatives: Vec<_> = self
            .sensitivities
            .iter()
            .map(|d| (format!("sensitivity {}", d.name), d.error))
            .collect();
        self.sensitivity_verdict = Verdict::judge(&derivatives, limit);
    }
}

fn rel(a: f64, b: f64) -> f64 {
    if b == 0.0 {
        a.abs()
    } else {
        ((a - b) / b).abs()
    }
}

fn row_errors(n: &Row, c: &Row) -> Row {
    Row {
        t: rel(n.t, c.t),
        r: rel(n.r, c.r),
        v_r: rel(n.v_r, c.v_r),
        impact_angle_deg: rel(n.impact_angle_deg, c.impact_angle_deg),
        s: rel(n.s, c.s),
    }
}

/// Gauss–Legendre nodes and weights on [−1, 1], 8 points.
const GL8: [(f64, f64); 8] = [
    (-0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
    (-0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (-0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (-0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
];

/// Solves to the impact, then measures the length `s = ∫|q̇| dt` on the dense output by composite
/// Gauss–Legendre quadrature (8 nodes on each of [`length_panels`]).
fn numerical_row<M: Model, Me: Method + Copy>(
    p: &Params,
    problem: &Problem<M>,
    method: Me,
    tol: f64,
    t_max: f64,
) -> Result<(Row, Solution), Error> {
    let opts = within(Options::until(t_max), p, tol).event(impact());
    let sol = solve(problem, method, &opts)?;
    if let Some(e) = sol.error() {
        return Err(e.clone());
    }
    let hit = sol.events.first().ok_or(Error::InvalidOption {
        name: "t_max",
        value: t_max,
        hint: "no impact before t_max",
    })?;
    let (t_imp, q, qd) = (hit.t, &hit.q, &hit.qd);
    let mut times = Vec::new();
    let mut weights = Vec::new();
    for (mid, half) in length_panels(t_imp, p.v0 / p.g) {
        for (x, wt) in GL8 {
            times.push(mid + half * x);
            weights.push(half * wt);
        }
    }
    let dense = solve(
        problem,
        method,
        &within(Options::until(t_imp), p, tol)
            .output_times(times.clone())
            .record(Record::State),
    )?;
    let mut s = 0.0;
    for (i, t) in dense.t.iter().enumerate() {
        if let Some(j) = times.iter().position(|x| x == t) {
            s += weights[j] * norm(&dense.qd[i]);
        }
    }
    Ok((
        Row {
            t: t_imp,
            r: q[0],
            v_r: norm(qd),
            impact_angle_deg: (-qd[1]).atan2(qd[0]).to_degrees(),
            s,
        },
        sol,
    ))
}

/// The panels, as `(midpoint, half-width)`, of the length's quadrature over `[0, t_imp]`: 64 of
/// equal width, each halved until it is at most 0.4 of its distance from `±i c`, where `c = v0/g`
/// is the time in which gravity turns the velocity. Both speeds, `√(v0² + g²t²)` and the uniform
/// motion's, are analytic but for points at that distance from the real axis, and 8 nodes give
/// about 16 digits on a panel that short. At the paper's data (`c = T`) no panel is halved. At
/// `z = g h0/v0² = 1e7` the first is halved 8 times for the classical motion (`c = 2.2e-4 T`) and
/// 19 times for the uniform one (`c = 1e-7 T`); with 64 equal panels the classical length was off
/// by `1.4e-8`.
fn length_panels(t_imp: f64, c: f64) -> Vec<(f64, f64)> {
    let panels = 64;
    let w = t_imp / panels as f64;
    let mut out = Vec::with_capacity(panels);
    for k in 0..panels {
        let mut todo = vec![((k as f64 + 0.5) * w, 0.5 * w)];
        while let Some((mid, half)) = todo.pop() {
            let start = mid - half;
            if 2.0 * half <= 0.4 * start.hypot(c) {
                out.push((mid, half));
            } else {
                todo.push((mid + 0.5 * half, 0.5 * half));
                todo.push((mid - 0.5 * half, 0.5 * half));
            }
        }
    }
    out
}

/// `opts` at `rtol = tol` and `atol = tol`, tightened per component to `tol` times the motion's
/// scale where that is below one ([`scaled_atol`]: `min(v0 √(2 h0/g), v0²/g)` for `x`, `h0` for
/// `y`, `min(v0, √(2 g h0))` for the velocities). The errors are judged relative to such scales,
/// and an absolute tolerance of `tol` on a speed of `1e-3 m/s` would allow `1e3 tol` of it. At the
/// paper's data every scale is above one and `atol = tol`.
fn within(opts: Options, p: &Params, tol: f64) -> Options {
    let [x, y, xd, yd] = absolute_tolerances(p, tol);
    opts.tolerances(tol, tol)
        .atol_per_component(&[x, y], &[xd, yd])
}

/// The absolute tolerances of `x`, `y`, `ẋ`, `ẏ` in the table's runs at the tolerance `tol`:
/// `tol`, tightened to `tol` times the motion's scale ([`scaled_atol`]) where that is below one.
pub fn absolute_tolerances(p: &Params, tol: f64) -> [f64; 4] {
    let ([x, y], [xd, yd]) = scaled_atol(p, tol);
    [x, y, xd, yd].map(|a| a.min(tol))
}

/// The Euclidean norm, scaled by a power of two so that the squares neither overflow (`|Φ| ≈ m g`
/// at `m = 1e155`) nor underflow. Scaling by a power of two is exact, so wherever the squares fit
/// in `f64` this is the plain `√(Σ x²)` to the last bit.
fn norm(v: &[f64]) -> f64 {
    let scaled = |scale: f64| {
        v.iter()
            .map(|x| (x * scale) * (x * scale))
            .sum::<f64>()
            .sqrt()
            / scale
    };
    let largest = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if !(largest >= f64::MIN_POSITIVE && largest.is_finite()) || v.iter().any(|x| x.is_nan()) {
        return scaled(1.0);
    }
    scaled(2f64.powi(-(largest.log2().floor() as i32)))
}

fn motion_errors(p: &Params, sol: &Solution, k: &Kinematics, uniform_motion: bool) -> MotionErrors {
    let mut e = MotionErrors {
        points: sol.len(),
        ..Default::default()
    };
    let (mut mu, mut phi, mut res, mut work) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let balance = sol.energy_balance();
    let e_scale = p.m * p.v0 * p.v0 + p.m * p.g * p.h0;
    for (i, bal) in balance.iter().enumerate() {
        let t = sol.t[i];
        let (x, v, a, kappa) = if uniform_motion {
            (
                uniform::position(p, t),
                uniform::velocity(p, t),
                uniform::acceleration(p, t),
                uniform::curvature(p, t),
            )
        } else {
            (
                classical::position(p, t),
                classical::velocity(p, t),
                classical::acceleration(p, t),
                classical::curvature(p, t),
            )
        };
        let (q, qd, qdd) = (&sol.q[i], &sol.qd[i], &sol.qdd[i]);
        e.x = e.x.max((q[0] - x[0]).abs() / k.range);
        e.y = e.y.max((q[1] - x[1]).abs() / p.h0);
        e.xd = e.xd.max((qd[0] - v[0]).abs() / p.v0);
        e.yd = e.yd.max((qd[1] - v[1]).abs() / k.impact_speed);
        e.xdd = e.xdd.max((qdd[0] - a[0]).abs() / p.g);
        e.ydd = e.ydd.max((qdd[1] - a[1]).abs() / p.g);
        let speed = norm(qd);
        let kn = if speed.powi(3).is_normal() {
            (qd[0] * qdd[1] - qdd[0] * qd[1]).abs() / speed.powi(3)
        } else {
            // |q̇|³ overflows (v0 near 1e103) or underflows (v0 below 1e-102): the same quotient
            // with q̇ scaled by its norm.
            (qd[0] / speed * qdd[1] - qdd[0] * (qd[1] / speed)).abs() / speed / speed
        };
        e.curvature = e.curvature.max((kn - kappa).abs() / (p.g / (p.v0 * p.v0)));
        e.energy_balance = e.energy_balance.max(bal.abs() / e_scale);
        if uniform_motion {
            mu = mu
                .max((sol.mu[i][0] - uniform::multiplier(p, t)).abs() / (p.m * p.g / (2.0 * p.v0)));
            phi = phi.max(
                (norm(&sol.phi[i]) - uniform::chetaev_force_magnitude(p, t)).abs() / (p.m * p.g),
            );
            res = res.max(sol.residual[i][0].abs() / (p.v0 * p.v0));
            work = work.max((sol.work[i] - p.m * p.g * (q[1] - p.h0)).abs() / (p.m * p.g * p.h0));
        }
    }
    if uniform_motion {
        e.mu = Some(mu);
        e.phi = Some(phi);
        e.residual = Some(res);
        e.work_vs_potential = Some(work);
    }
    e
}

/// Least-squares slope of `log y` against `log x`.
pub fn log_slope(points: &[(f64, f64)]) -> f64 {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    let n = pts.len() as f64;
    let (sx, sy) = pts.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
    let (mx, my) = (sx / n, sy / n);
    let (num, den) = pts.iter().fold((0.0, 0.0), |a, p| {
        (a.0 + (p.0 - mx) * (p.1 - my), a.1 + (p.0 - mx).powi(2))
    });
    num / den
}

/// The errors below which a study shows no order: where even its coarsest run is this close to
/// rounding (about `1e-14` relative here), the differences between runs are rounding.
pub const ORDER_SIGNAL: f64 = 1e-11;

/// The least-squares slope of `log error` against `log h` (or `log tol`) over `points`, or `None`
/// where it would mean nothing: fewer than two points, or every error below [`ORDER_SIGNAL`] (near
/// the classical limit `z → 0` the motion is so nearly a parabola that every run is exact to
/// rounding, and the slope of rounding errors came out negative or NaN).
pub fn observed_order(points: &[(f64, f64)]) -> Option<f64> {
    let signal = points.iter().any(|&(_, e)| e >= ORDER_SIGNAL);
    (points.len() >= 2 && signal).then(|| log_slope(points))
}

/// Where the fixed-step runs of the orders end: the impact `t_impact`, or `4 v0/g` if that is
/// earlier. In `v0/g` gravity turns the velocity; after a few of it the uniform motion falls
/// straight down, where its equations are stiff with `|λ| ≈ g/v0` (large `z = g h0/v0²`). Steps
/// `h = T/2^k` would then be many times `v0/g` and cross the turn in one step, outside every
/// method's asymptotic range (and the explicit methods' stability region). At the paper's data
/// `4 v0/g = 4 s` is after `T = 1.09 s`.
pub fn orders_until(p: &Params, t_impact: f64) -> f64 {
    t_impact.min(4.0 * p.v0 / p.g)
}

/// The halvings `k` of the step `h = T/2^k` over which a method of order `order` shows its order
/// on the uniform motion: from where the error is below about 1e-3 to where it nears rounding
/// (about 1e-13), fewer and coarser steps the higher the order.
fn halvings(order: u32) -> std::ops::Range<u32> {
    match order {
        0..=4 => 3..9,
        5 | 6 => 2..7,
        _ => 1..5,
    }
}

/// Largest error of the end state of the uniform motion at `t_end`, scaled as in [`WorkPoint`].
fn end_error(p: &Params, sol: &Solution, t_end: f64, range: f64) -> f64 {
    let Some((_, q, qd)) = sol.last() else {
        return f64::NAN;
    };
    let (x, v) = (uniform::position(p, t_end), uniform::velocity(p, t_end));
    ((q[0] - x[0]).abs() / range.max(p.h0))
        .max((q[1] - x[1]).abs() / range.max(p.h0))
        .max((qd[0] - v[0]).abs() / p.v0)
        .max((qd[1] - v[1]).abs() / p.v0)
}

/// Times one configuration: the median of repeated runs (at least 5, and until 20 ms have passed,
/// at most 200); one run when not `repeat`, or when the first did not succeed.
fn time_runs<Me: Method + Copy>(
    problem: &UniformProblem,
    method: Me,
    opts: &Options,
    repeat: bool,
) -> Result<(Solution, f64, usize), Error> {
    let mut times = Vec::new();
    let start = Instant::now();
    let mut last: Option<Solution> = None;
    let more = |n: usize, last: &Option<Solution>| {
        n == 0
            || repeat
                && last.as_ref().is_some_and(|s| s.error().is_none())
                && (n < 5 || (start.elapsed().as_secs_f64() < 0.02 && n < 200))
    };
    while more(times.len(), &last) {
        let t0 = Instant::now();
        let sol = solve(problem, method, opts)?;
        times.push(t0.elapsed().as_secs_f64());
        last = Some(sol);
    }
    times.sort_by(f64::total_cmp);
    let median = times[times.len() / 2];
    let n = times.len();
    last.map(|s| (s, median, n)).ok_or(Error::InvalidOption {
        name: "repeats",
        value: 0.0,
        hint: "no run",
    })
}

/// The uniform motion, the ground of the optional studies: the tolerances and the timing run to
/// its impact `t_end`, the fixed steps to `t_orders` (see [`Report::orders_until`]).
struct Study<'a> {
    p: &'a Params,
    problem: &'a UniformProblem,
    t_end: f64,
    t_orders: f64,
    range: f64,
}

impl Study<'_> {
    /// Solves with `method` and `opts` (whose tolerance, or step, is `at`) to `until`, timed when
    /// `repeat`; `Err` with the reason when the solve stopped before.
    fn run(
        &self,
        method: AnyMethod,
        opts: &Options,
        (at, until): (f64, f64),
        repeat: bool,
    ) -> Result<Result<WorkPoint, String>, Error> {
        let (sol, seconds, repeats) = time_runs(self.problem, method, opts, repeat)?;
        if let Some(e) = sol.error() {
            return Ok(Err(e.to_string()));
        }
        Ok(Ok(WorkPoint {
            method: method.name().into(),
            tolerance: at,
            fixed_step: method.info().fixed_step.is_some(),
            error: end_error(self.p, &sol, until, self.range),
            seconds,
            repeats,
            rhs_evaluations: sol.stats.rhs_evaluations,
            steps: sol.stats.accepted_steps,
        }))
    }

    /// One study of the method named `name`: each run of `runs`, `(step or tolerance, method,
    /// options)`, to `until`, up to the first that stops, which is said in `stopped`. The points
    /// before it, and whether every run reached `until`.
    fn sweep(
        &self,
        (name, study): (&str, &str),
        until: f64,
        repeat: bool,
        runs: impl Iterator<Item = Result<(f64, AnyMethod, Options), Error>>,
        stopped: &mut Vec<Stopped>,
    ) -> Result<(Vec<WorkPoint>, bool), Error> {
        let mut out = Vec::new();
        for run in runs {
            let (at, method, opts) = run?;
            match self.run(method, &opts, (at, until), repeat)? {
                Ok(w) => out.push(w),
                Err(error) => {
                    stopped.push(Stopped {
                        method: name.into(),
                        study: study.into(),
                        at,
                        error,
                    });
                    return Ok((out, false));
                }
            }
        }
        Ok((out, true))
    }

    /// The observed order of a method in fixed steps `h = T/2^k` (see [`halvings`]) to
    /// `t_orders`. An adaptive method is held to the step `h` by a first and largest step `h` and
    /// a tolerance that never rejects. `None` when a run stopped (said in `stopped`).
    fn order_in_h(
        &self,
        info: MethodInfo,
        stopped: &mut Vec<Stopped>,
    ) -> Result<Option<Convergence>, Error> {
        let until = self.t_orders;
        let runs = halvings(info.order).map(|k| {
            let h = until / f64::from(1u32 << k);
            let opts = Options::until(until)
                .tolerances(1e3, 1e3)
                .initial_step(h)
                .max_step(h)
                .output_final()
                .record(Record::State);
            Ok((h, AnyMethod::from_name(info.name, Some(h))?, opts))
        });
        let (runs, complete) = self.sweep((info.name, "h"), until, false, runs, stopped)?;
        let points: Vec<(f64, f64)> = runs.iter().map(|w| (w.tolerance, w.error)).collect();
        Ok(complete.then(|| Convergence {
            method: info.name.into(),
            against: "h".into(),
            order: observed_order(&points),
            points,
            expected: f64::from(info.order),
        }))
    }

    /// An adaptive method at `rtol = atol` from 1e-3 to 1e-13 to `t_end`, timed when `repeat`.
    fn over_tolerances(
        &self,
        method: AnyMethod,
        repeat: bool,
        stopped: &mut Vec<Stopped>,
    ) -> Result<(Vec<WorkPoint>, bool), Error> {
        let runs = (3..=13).map(|e| {
            let tol = 10f64.powi(-e);
            let opts = within(Options::until(self.t_end), self.p, tol)
                .output_final()
                .record(Record::State);
            Ok((tol, method, opts))
        });
        let name = (method.name(), "tolerance");
        self.sweep(name, self.t_end, repeat, runs, stopped)
    }

    /// A fixed-step method at `h = T/4 … T/512` to `t_end`, timed.
    fn over_steps(
        &self,
        info: MethodInfo,
        stopped: &mut Vec<Stopped>,
    ) -> Result<Vec<WorkPoint>, Error> {
        let runs = (2..10).map(|k| {
            let h = self.t_end / f64::from(1u32 << k);
            let opts = Options::until(self.t_end)
                .output_final()
                .record(Record::State);
            Ok((h, AnyMethod::from_name(info.name, Some(h))?, opts))
        });
        let (runs, _) = self.sweep((info.name, "h"), self.t_end, true, runs, stopped)?;
        Ok(runs)
    }
}

/// Tolerance proportionality: error ∝ tol^α with α ≈ 1 for a well-behaved controller, fitted from
/// 1e-6 down to where rounding sets in.
fn proportionality(method: &str, runs: &[WorkPoint]) -> Convergence {
    let points: Vec<(f64, f64)> = runs
        .iter()
        .filter(|w| w.tolerance <= 1e-6 && w.error > 1e-14)
        .map(|w| (w.tolerance, w.error))
        .collect();
    Convergence {
        method: method.into(),
        against: "tolerance".into(),
        order: observed_order(&points),
        points,
        expected: 1.0,
    }
}

/// `∂T/∂θ` and `∂R/∂θ` for `θ = v0, g, h0`: the sensitivities of the impact event (by `method`,
/// the sensitivities under error control at `tol`) against the closed form (42.38) differentiated by
/// dual numbers.
fn impact_derivatives(
    p: &Params,
    up: &UniformProblem,
    method: AnyMethod,
    tol: f64,
    t_max: f64,
) -> Result<Vec<Derivative>, Error> {
    let mut opts = within(Options::until(t_max), p, tol)
        .output_final()
        .record(Record::State)
        .event(impact())
        .sensitivity_control(true);
    for seed in seeds() {
        opts = opts.sensitivity(seed);
    }
    let sol = solve(up, method, &opts)?;
    if let Some(e) = sol.error() {
        return Err(e.clone());
    }
    if sol.events.is_empty() {
        return Err(Error::InvalidOption {
            name: "t_max",
            value: t_max,
            hint: "no impact before t_max",
        });
    }
    let hit = sol
        .sensitivities
        .as_ref()
        .and_then(|s| s.events.first().cloned().flatten())
        .ok_or_else(|| Error::Sensitivity {
            what: format!(
                "the impact at t = {:e} has no derivatives (the event is crossed tangentially, or \
                 they are not finite numbers for these data)",
                sol.events[0].t
            ),
        })?;
    let mut out = Vec::new();
    for (j, theta) in ["v0", "g", "h0"].iter().enumerate() {
        let seeded = |i: usize, x: f64| Dual64::new(x, if i == j { 1.0 } else { 0.0 });
        let (t, r) = uniform::impact(seeded(0, p.v0), seeded(1, p.g), seeded(2, p.h0));
        let value = [p.v0, p.g, p.h0][j];
        for (quantity, numerical, closed_form) in [("T", hit.t[j], t), ("R", hit.q[j][0], r)] {
            let scale = (closed_form.re / value).abs();
            let difference = (numerical - closed_form.eps).abs();
            out.push(Derivative {
                name: format!("∂{quantity}/∂{theta}"),
                numerical,
                closed_form: closed_form.eps,
                rel_error: rel(numerical, closed_form.eps),
                scale,
                error: difference / closed_form.eps.abs().max(scale),
            });
        }
    }
    Ok(out)
}

/// Builds the report for `p`: Table 42.1, the errors along both motions and the impact's
/// derivatives by `method` at `rtol = atol = tol`, and the `studies` asked for, by every method of
/// the library. `method` must have error control (not `Rk4`).
pub fn build(p: &Params, tol: f64, method: AnyMethod, studies: Studies) -> Result<Report, Error> {
    if method.info().fixed_step.is_some() {
        return Err(Error::InvalidOption {
            name: "method",
            value: f64::NAN,
            hint: "the table is integrated to a tolerance: choose a method with error control",
        });
    }
    let closed = table(p);
    let t_max = 10.0 * closed.uniform.t_impact.max(closed.classical.t_impact);

    let cp = classical_problem(p)?;
    let up = uniform_problem(p)?;
    let (c_row, c_sol) = numerical_row(p, &cp, method, tol, t_max)?;
    let (u_row, u_sol) = numerical_row(p, &up, method, tol, t_max)?;
    let table_out = Table {
        classical: TableRow {
            numerical: c_row,
            closed_form: closed.classical.into(),
            rel_error: row_errors(&c_row, &closed.classical.into()),
        },
        uniform: TableRow {
            numerical: u_row,
            closed_form: closed.uniform.into(),
            rel_error: row_errors(&u_row, &closed.uniform.into()),
        },
    };
    let classical_errors = motion_errors(p, &c_sol, &closed.classical, false);
    let uniform_errors = motion_errors(p, &u_sol, &closed.uniform, true);

    let study = Study {
        p,
        problem: &up,
        t_end: closed.uniform.t_impact,
        t_orders: orders_until(p, closed.uniform.t_impact),
        range: closed.uniform.range,
    };
    let mut stopped = Vec::new();
    let mut convergence = Vec::new();
    let mut work_precision = Vec::new();
    let every_method = AnyMethod::all(1.0);
    if studies.orders {
        for m in &every_method {
            convergence.extend(study.order_in_h(m.info(), &mut stopped)?);
        }
    }
    if studies.orders || studies.timing {
        // The adaptive methods over the tolerances, then the fixed-step ones over halving steps;
        // timed over repeated runs only when the timing is asked for.
        let repeat = studies.timing;
        let (adaptive, fixed_step): (Vec<AnyMethod>, Vec<AnyMethod>) = every_method
            .into_iter()
            .partition(|m| m.info().fixed_step.is_none());
        for &m in &adaptive {
            let (points, complete) = study.over_tolerances(m, repeat, &mut stopped)?;
            if studies.orders && complete {
                convergence.push(proportionality(m.name(), &points));
            }
            work_precision.extend(points);
        }
        if studies.timing {
            for m in &fixed_step {
                work_precision.extend(study.over_steps(m.info(), &mut stopped)?);
            }
        } else {
            work_precision.clear();
        }
    }

    let sensitivities = impact_derivatives(p, &up, method, tol, t_max)?;
    let mut report = Report {
        verdict: Verdict::judge(&[], 0.0),
        method: method.name().to_string(),
        params: ParamsOut {
            v0: p.v0,
            g: p.g,
            h0: p.h0,
            m: p.m,
        },
        tolerance: tol,
        atol: absolute_tolerances(p, tol),
        table: table_out,
        classical_errors,
        uniform_errors,
        convergence,
        orders_until: study.t_orders,
        work_precision,
        stopped,
        sensitivity_verdict: Verdict::judge(&[], 0.0),
        sensitivities,
    };
    report.judge(LIMIT_PER_TOLERANCE * tol);
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::Verdict;

    fn pairs(v: &[f64]) -> Vec<(String, f64)> {
        v.iter()
            .enumerate()
            .map(|(i, x)| (format!("q{i}"), *x))
            .collect()
    }

    #[test]
    fn verdict_names_the_largest_error_and_accepts_it_at_the_limit() {
        let v = Verdict::judge(&pairs(&[1e-14, 3e-13, 0.0, 1e-13]), 3e-13);
        assert!(v.verified);
        assert_eq!(
            (v.largest, v.largest_of.as_str(), v.compared),
            (3e-13, "q1", 4)
        );
    }

    #[test]
    fn verdict_fails_above_the_limit() {
        let v = Verdict::judge(&pairs(&[1e-14, 2e-10]), 1e-10);
        assert!(!v.verified);
        assert_eq!(v.largest_of, "q1");
    }

    #[test]
    fn verdict_fails_on_nan_or_infinity_however_small_the_rest() {
        for bad in [f64::NAN, f64::INFINITY] {
            let v = Verdict::judge(&pairs(&[1e-14, bad, 1e-15]), 1e-10);
            assert!(!v.verified, "{bad}");
            assert_eq!(v.largest_of, "q1");
        }
    }

    #[test]
    fn verdict_without_comparisons_is_not_verified() {
        assert!(!Verdict::judge(&[], 1.0).verified);
    }
}
