//! The figures of *Uniform horizontal projectile motion* (Swaczyna and Volný), redrawn from
//! `chetaev`'s solutions over the paper's closed forms, and the diagnostics of the uniform motion.
//!
//! ```sh
//! cargo run --release --example paper_figures [-- OUTDIR]      # default OUTDIR: docs/figures
//! ```
//!
//! Both motions are integrated by Dop853 at `rtol = atol = 1e-12` from `(0, h0)` with velocity
//! `(v0, 0)` (`v0 = 10 m/s`, `g = 10 m/s²`, `h0 = 5 m`, `m = 1 kg`), stopped by the impact event
//! `y = 0`, and recorded on a fine time grid by dense output. Written, as SVG:
//!
//! | file | what |
//! |---|---|
//! | `fig42_1_trajectory.svg` | Fig. 42.1: the explicit trajectory (42.37) over its first period, the realised part bold |
//! | `fig42_2_trajectories.svg` | Fig. 42.2: both trajectories from the start to the impact, equal scales |
//! | `multiplier.svg` | the multiplier `μ(t)` against (42.40) |
//! | `chetaev_force.svg` | the magnitude of the Chetaev force `|Φ|(t)` against (42.42) |
//! | `residual.svg` | the constraint residual `|f(t)|`, with and without projection, at two tolerances |
//! | `energy_balance.svg` | kinetic and potential energy, the work of `Φ`, and the energy balance |

use std::error::Error;
use std::f64::consts::FRAC_PI_2;
use std::io::{self, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use chetaev::prelude::*;
use chetaev_plot::{Figure, Legend, Style};
use chetaev_suite::finish;
use clap::Parser;
use uniform_projectile::closed_form::{classical, table, uniform, Params};
use uniform_projectile::model::{classical_problem, impact, uniform_problem};

/// The tolerance of the reference solutions.
const TOL: f64 = 1e-12;
/// Output points per second of motion, by dense output.
const POINTS_PER_SECOND: f64 = 400.0;
/// Markers drawn for a numerical solution over a whole motion.
const MARKERS: usize = 24;
/// How far the closed forms of `μ` and `|Φ|` are continued past the impact, in s (as if there were
/// no ground), to show their limits.
const T_CONTINUED: f64 = 2.5;

/// Points of one line, `(x, y)`.
type Curve = Vec<(f64, f64)>;

/// Colours kept fixed across the figures: each motion has one.
const UNIFORM: &str = "#0072B2";
const CLASSICAL: &str = "#D55E00";
const GUIDE: &str = "#777777";

/// The figures of "Uniform horizontal projectile motion" (Swaczyna and Volný), redrawn from
/// chetaev's solutions over the paper's closed forms, as SVG files.
#[derive(Parser)]
struct Cli {
    /// The folder the figures are written to (created if missing).
    #[arg(value_name = "OUTDIR", default_value = "docs/figures")]
    out: PathBuf,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    finish(run(&cli, &mut io::stdout().lock()))
}

fn run(cli: &Cli, stdout: &mut impl Write) -> Result<(), Box<dyn Error>> {
    let out = &cli.out;
    if out.exists() && !out.is_dir() {
        return Err(format!(
            "{} is a file, not a folder: give a folder for the figures (it is created if missing)",
            out.display()
        )
        .into());
    }
    let p = Params::PAPER;
    let kin = table(&p);

    // The reference solutions, recorded on a fine grid up to the impact.
    let grid_end = 1.2 * kin.uniform.t_impact.max(kin.classical.t_impact);
    let options = Options::until(2.0 * grid_end)
        .tolerances(TOL, TOL)
        .event(impact())
        .output_times(grid(0.0, grid_end, (grid_end * POINTS_PER_SECOND) as usize));
    let uni = checked(solve(&uniform_problem(&p)?, Dop853::default(), &options)?)?;
    let cla = checked(solve(&classical_problem(&p)?, Dop853::default(), &options)?)?;
    let (t_u, r_u) = impact_of(&uni)?;
    let (t_c, r_c) = impact_of(&cla)?;

    trajectory_figure(&p, &uni, r_u).save(out.join("fig42_1_trajectory.svg"))?;
    trajectories_figure(&p, &uni, &cla, (t_u, r_u), (t_c, r_c))
        .save(out.join("fig42_2_trajectories.svg"))?;
    multiplier_figure(&p, &uni, t_u).save(out.join("multiplier.svg"))?;
    chetaev_force_figure(&p, &uni, t_u).save(out.join("chetaev_force.svg"))?;
    residual_figure(&p)?.save(out.join("residual.svg"))?;
    energy_figure(&p, &uni).save(out.join("energy_balance.svg"))?;
    writeln!(stdout, "wrote 6 figures to {}", out.display())?;
    writeln!(stdout, "uniform:   T = {t_u:.12} s, R = {r_u:.12} m")?;
    writeln!(stdout, "classical: T = {t_c:.12} s, R = {r_c:.12} m")?;
    // What the markers show, in numbers: the largest distance from the closed forms.
    let largest = |f: &dyn Fn(usize) -> f64| (0..uni.len()).map(f).fold(0.0f64, f64::max);
    let position = largest(&|i| {
        let [x, y] = uniform::position(&p, uni.t[i]);
        (uni.q[i][0] - x).hypot(uni.q[i][1] - y)
    });
    let mu = largest(&|i| (uni.mu[i][0] - uniform::multiplier(&p, uni.t[i])).abs());
    let phi =
        largest(&|i| (norm(&uni.phi[i]) - uniform::chetaev_force_magnitude(&p, uni.t[i])).abs());
    writeln!(
        stdout,
        "uniform, largest deviation from (42.29): {position:.1e} m, from (42.40): {mu:.1e} kg/s, from (42.42): {phi:.1e} N"
    )?;
    Ok(())
}

/// `n + 1` equally spaced times from `a` to `b`.
fn grid(a: f64, b: f64, n: usize) -> Vec<f64> {
    let n = n.max(1);
    (0..=n).map(|i| a + (b - a) * i as f64 / n as f64).collect()
}

/// The Euclidean length of a recorded vector.
fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The solution if the integration reached the impact, its error otherwise.
fn checked(sol: Solution) -> Result<Solution, Box<dyn Error>> {
    match sol.error() {
        Some(e) => Err(format!("{} failed: {e}", sol.method).into()),
        None => Ok(sol),
    }
}

/// The impact time and range of a solution stopped by the impact event.
fn impact_of(sol: &Solution) -> Result<(f64, f64), Box<dyn Error>> {
    let hit = sol
        .events
        .first()
        .ok_or("the motion did not reach the ground before the end time; raise the end time")?;
    Ok((hit.t, hit.q[0]))
}

/// About `count` evenly spaced points of `points`, always with the last one.
fn thinned(points: &[(f64, f64)], count: usize) -> Vec<(f64, f64)> {
    let step = (points.len() / count.max(1)).max(1);
    let mut v: Vec<(f64, f64)> = points.iter().step_by(step).copied().collect();
    if let (Some(&last), Some(&kept)) = (points.last(), v.last()) {
        if last != kept {
            v.push(last);
        }
    }
    v
}

fn line(width: f64, color: &'static str) -> Style {
    Style {
        width,
        color: Some(color),
        ..Style::default()
    }
}

fn dashed(width: f64, color: &'static str) -> Style {
    Style {
        dashed: true,
        ..line(width, color)
    }
}

fn markers(color: &'static str) -> Style {
    Style {
        width: 0.0,
        markers: true,
        color: Some(color),
        ..Style::default()
    }
}

/// The recorded trajectory `(x, y)`.
fn path(sol: &Solution) -> Vec<(f64, f64)> {
    sol.q.iter().map(|q| (q[0], q[1])).collect()
}

/// Fig. 42.1: the explicit trajectory (42.37) `y(x) = h0 + (v0²/g) ln|cos(g x / v0²)|` over its
/// first period `|x| < π v0² / 2g`, where it falls to −∞ at both ends; the realised part from the
/// start `x = 0` to the impact `x = R` bold, `chetaev`'s trajectory as markers over it.
fn trajectory_figure(p: &Params, uni: &Solution, range: f64) -> Figure {
    let half = FRAC_PI_2 * p.v0 * p.v0 / p.g;
    let n = 2000;
    // The open interval (−half, half): midpoints of n cells.
    let period: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let x = -half + 2.0 * half * (i as f64 + 0.5) / n as f64;
            (x, uniform::trajectory_y(p, x))
        })
        .collect();
    let realised: Vec<(f64, f64)> = grid(0.0, range, 400)
        .into_iter()
        .map(|x| (x, uniform::trajectory_y(p, x)))
        .collect();
    let (y_lo, y_hi) = (-30.0, 10.0);
    let asymptote = |x: f64| [(x, y_lo), (x, y_hi)];
    Figure::new("Fig. 42.1: the explicit trajectory (42.37) over its first period")
        .x_label("x [m]")
        .y_label("y [m]")
        .x_range(-1.1 * half, 1.1 * half)
        .y_range(y_lo, y_hi)
        .line_styled("", &asymptote(-half), dashed(1.0, GUIDE))
        .line_styled(
            "asymptotes x = ±π v0²/(2g)",
            &asymptote(half),
            dashed(1.0, GUIDE),
        )
        .line_styled(
            "ground y = 0",
            &[(-1.1 * half, 0.0), (1.1 * half, 0.0)],
            line(1.0, "#000000"),
        )
        .line_styled("y(x), (42.37)", &period, line(1.2, UNIFORM))
        .line_styled(
            &format!("realised: 0 ≤ x ≤ R = {range:.2} m"),
            &realised,
            line(4.0, UNIFORM),
        )
        .line_styled(
            "chetaev (Dop853)",
            &thinned(&path(uni), MARKERS / 2),
            markers(CLASSICAL),
        )
}

/// Fig. 42.2: both trajectories from the start to the impact, on equal scales: the closed forms
/// (42.4) and (42.29) as lines, `chetaev`'s solutions as markers.
fn trajectories_figure(
    p: &Params,
    uni: &Solution,
    cla: &Solution,
    (t_u, r_u): (f64, f64),
    (t_c, r_c): (f64, f64),
) -> Figure {
    let closed = |f: fn(&Params, f64) -> [f64; 2], t_end: f64| -> Vec<(f64, f64)> {
        grid(0.0, t_end, 400)
            .into_iter()
            .map(|t| {
                let [x, y] = f(p, t);
                (x, y)
            })
            .collect()
    };
    Figure::new("Fig. 42.2: trajectories of both motions")
        .x_label("x [m]")
        .y_label("y [m]")
        .equal_aspect()
        .size(760.0, 520.0)
        .x_range(-0.5, r_c.max(r_u) + 0.5)
        .y_range(-0.5, p.h0 + 0.5)
        .legend(Legend::BottomLeft)
        .line_styled(
            &format!("classical, parabola (42.5): R = {r_c:.2} m, T = {t_c:.3} s"),
            &closed(classical::position, t_c),
            line(2.0, CLASSICAL),
        )
        .line_styled(
            &format!("uniform, (42.29): R = {r_u:.2} m, T = {t_u:.3} s"),
            &closed(uniform::position, t_u),
            line(2.0, UNIFORM),
        )
        .line_styled(
            "chetaev, classical",
            &thinned(&path(cla), MARKERS),
            markers(CLASSICAL),
        )
        .line_styled(
            "chetaev, uniform",
            &thinned(&path(uni), MARKERS),
            markers(UNIFORM),
        )
        .line_styled(
            "",
            &[(-0.5, 0.0), (r_c.max(r_u) + 0.5, 0.0)],
            line(1.0, "#000000"),
        )
}

/// The closed form `f(p, t)` on `[0, t_impact]` (solid) and continued to [`T_CONTINUED`] (dashed).
fn closed_form_curves(p: &Params, f: fn(&Params, f64) -> f64, t_impact: f64) -> (Curve, Curve) {
    let sample = |a, b| {
        grid(a, b, 300)
            .into_iter()
            .map(|t| (t, f(p, t)))
            .collect::<Vec<_>>()
    };
    (sample(0.0, t_impact), sample(t_impact, T_CONTINUED))
}

/// `μ(t)` from `chetaev` (markers) and (42.40) (line), continued past the impact to show its limit
/// `−m g / (2 v0)`.
fn multiplier_figure(p: &Params, uni: &Solution, t_u: f64) -> Figure {
    let mu: Vec<(f64, f64)> = uni
        .t
        .iter()
        .zip(uni.mu.iter())
        .map(|(&t, m)| (t, m[0]))
        .collect();
    let (before, after) = closed_form_curves(p, uniform::multiplier, t_u);
    let limit = -p.m * p.g / (2.0 * p.v0);
    Figure::new("Lagrange multiplier of the uniform motion")
        .x_label("t [s]")
        .y_label("μ [kg/s]")
        .y_range(1.1 * limit, -0.1 * limit)
        .line_styled(
            "μ(t) = −(m g/2v0) tanh(g t/v0), (42.40)",
            &before,
            line(2.0, UNIFORM),
        )
        .line_styled(
            "(42.40) past the impact, without ground",
            &after,
            dashed(1.5, UNIFORM),
        )
        .line_styled(
            "chetaev (Dop853)",
            &thinned(&mu, MARKERS),
            markers(CLASSICAL),
        )
        .line_styled(
            &format!("limit −m g/(2 v0) = −{}", -limit),
            &[(0.0, limit), (T_CONTINUED, limit)],
            dashed(1.0, GUIDE),
        )
        .line_styled(
            &format!("impact, T = {t_u:.3} s"),
            &[(t_u, 1.1 * limit), (t_u, -0.1 * limit)],
            line(1.0, "#000000"),
        )
}

/// `|Φ|(t)` from `chetaev` (markers) and (42.42) (line), continued past the impact to show its limit
/// `m g`.
fn chetaev_force_figure(p: &Params, uni: &Solution, t_u: f64) -> Figure {
    let phi: Vec<(f64, f64)> = uni
        .t
        .iter()
        .zip(uni.phi.iter())
        .map(|(&t, f)| (t, norm(f)))
        .collect();
    let (before, after) = closed_form_curves(p, uniform::chetaev_force_magnitude, t_u);
    let mg = p.m * p.g;
    let at_impact = uniform::chetaev_force_magnitude(p, t_u);
    Figure::new("Magnitude of the Chetaev force of the uniform motion")
        .x_label("t [s]")
        .y_label("|Φ| [N]")
        .y_range(-0.05 * mg, 1.1 * mg)
        .line_styled(
            "|Φ|(t) = m g tanh(g t/v0), (42.42)",
            &before,
            line(2.0, UNIFORM),
        )
        .line_styled(
            "(42.42) past the impact, without ground",
            &after,
            dashed(1.5, UNIFORM),
        )
        .line_styled(
            "chetaev (Dop853)",
            &thinned(&phi, MARKERS),
            markers(CLASSICAL),
        )
        .line_styled(
            &format!("limit m g = {mg} N"),
            &[(0.0, mg), (T_CONTINUED, mg)],
            dashed(1.0, GUIDE),
        )
        .line_styled(
            &format!("impact, T = {t_u:.3} s, |Φ| = {at_impact:.3} N"),
            &[(t_u, -0.05 * mg), (t_u, 1.1 * mg)],
            line(1.0, "#000000"),
        )
}

/// `|f(t)|` along the uniform motion by Dop853 at two tolerances, without and with projection onto
/// `f = 0`, recorded on a fine grid by dense output. The projection acts where the relative
/// residual `|f| / (|∂f/∂q̇| |q̇|) = |f| / (2 v0²)` exceeds its tolerance.
fn residual_figure(p: &Params) -> Result<Figure, Box<dyn Error>> {
    let problem = uniform_problem(p)?;
    let projection = Projection::default();
    let threshold = projection.tol * 2.0 * p.v0 * p.v0;
    let t_end = table(p).uniform.t_impact;
    let times = grid(0.0, 1.2 * t_end, (1.2 * t_end * POINTS_PER_SECOND) as usize);
    let mut fig = Figure::new("Constraint residual of the uniform motion, Dop853")
        .x_label("t [s]")
        .y_label("|f| = |ẋ² + ẏ² − v0²| [m²/s²]")
        .log_y()
        .size(760.0, 540.0)
        .y_range(1e-15, 1.0)
        .line_styled(
            &format!(
                "projection threshold {:.0e} · 2 v0² = {threshold:.0e}",
                projection.tol
            ),
            &[(0.0, threshold), (t_end, threshold)],
            dashed(1.0, GUIDE),
        );
    let runs = [
        (1e-6, false, "#E69F00"),
        (1e-6, true, "#8C564B"),
        (1e-9, false, "#009E73"),
        (1e-9, true, "#0072B2"),
    ];
    for (tol, project, color) in runs {
        let mut options = Options::until(10.0)
            .tolerances(tol, tol)
            .event(impact())
            .output_times(times.clone());
        if project {
            options = options.project(projection);
        }
        let sol = checked(solve(&problem, Dop853::default(), &options)?)?;
        let points: Vec<(f64, f64)> = sol
            .t
            .iter()
            .zip(sol.residual.iter())
            .map(|(&t, f)| (t, f[0].abs()))
            .collect();
        let name = format!(
            "rtol = atol = {tol:.0e}{}: {} steps, largest |f| {:.1e}",
            if project { ", projected" } else { "" },
            sol.stats.accepted_steps,
            sol.max_residual().unwrap_or(f64::NAN),
        );
        let style = Style {
            dashed: project,
            ..line(1.5, color)
        };
        fig = fig.line_styled(&name, &points, style);
    }
    Ok(fig)
}

/// The energy of the uniform motion: `T = ½ m |q̇|²` constant, `V = m g y` falling, the work `W_Φ`
/// of the Chetaev force equal to `V − V(0)`, and the balance `E − E(0) − W_Φ ≈ 0`.
fn energy_figure(p: &Params, uni: &Solution) -> Figure {
    let t = &uni.t;
    let kinetic: Vec<(f64, f64)> = t
        .iter()
        .zip(uni.qd.iter())
        .map(|(&t, qd)| (t, 0.5 * p.m * qd.iter().map(|v| v * v).sum::<f64>()))
        .collect();
    let potential: Vec<(f64, f64)> = t
        .iter()
        .zip(uni.q.iter())
        .map(|(&t, q)| (t, p.m * p.g * q[1]))
        .collect();
    let work: Vec<(f64, f64)> = t.iter().zip(&uni.work).map(|(&t, &w)| (t, w)).collect();
    let balance: Vec<(f64, f64)> = t
        .iter()
        .zip(uni.energy_balance())
        .map(|(&t, b)| (t, b))
        .collect();
    let largest = balance.iter().fold(0.0f64, |m, b| m.max(b.1.abs()));
    Figure::new("Energy of the uniform motion")
        .x_label("t [s]")
        .y_label("energy [J]")
        .line_styled("kinetic energy ½ m |q̇|²", &kinetic, line(2.0, "#CC79A7"))
        .line_styled("potential energy m g y", &potential, line(2.0, UNIFORM))
        .line_styled("work of the Chetaev force W_Φ", &work, line(2.0, CLASSICAL))
        .line_styled(
            &format!("balance E − E(0) − W_Φ (largest |·| = {largest:.1e} J)"),
            &balance,
            dashed(2.0, "#009E73"),
        )
}
