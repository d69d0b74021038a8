//! The five scenes of the work-precision study, each with its reference and error measure.

use chetaev::model::Fixed;
use chetaev::prelude::*;
use chetaev_catalogue::benchmarks::{Launch3d, Particle3d, TwoRunners};
use chetaev_catalogue::Error;
use uniform_projectile::closed_form::{classical, table, uniform, Params};
use uniform_projectile::model::{
    classical_problem, scaled_atol, uniform_problem, Projectile, UniformProjectile,
};

use crate::handwritten::{Full, Reduced};
use crate::study::{HandWritten, StudyScene};

/// Step counts of the methods without error control (`Rk4`) on the non-stiff scenes: 8, 16, …,
/// 32768.
pub fn fixed_steps() -> Vec<usize> {
    (3..=15).map(|k| 1usize << k).collect()
}

/// The paper's data (Table 42.1): `v0 = 10`, `g = 10`, `h0 = 5`, `m = 1`.
pub const PAPER: Params = Params::PAPER;

/// The stiff scene: `v0 = 1e-3`, `g = 9.81`, `h0 = 1`, `m = 1`.
pub const STIFF: Params = Params {
    v0: 1e-3,
    g: 9.81,
    h0: 1.0,
    m: 1.0,
};

/// `max(|q_i − x_i| / L_i, |q̇_i − v_i| / V)` over the components of the end state `(q, q̇)`
/// against the reference `(x, v)`, with a length scale `L_i` per coordinate and one speed `V`.
fn scaled_error(q: &[f64], qd: &[f64], x: &[f64], v: &[f64], length: &[f64], speed: f64) -> f64 {
    let mut e = 0.0f64;
    for i in 0..q.len() {
        e = e.max((q[i] - x[i]).abs() / length[i]);
        e = e.max((qd[i] - v[i]).abs() / speed);
    }
    e
}

/// The end-state error of the paper's uniform motion at `t_end`: positions relative to
/// `max(R, h0)`, velocities relative to `v0`. Shared by chetaev's runs and the hand-written ones.
pub fn uniform_error(p: &Params, t_end: f64, q: [f64; 2], qd: [f64; 2]) -> f64 {
    let k = table(p).uniform;
    let length = k.range.max(p.h0);
    let (x, v) = (uniform::position(p, t_end), uniform::velocity(p, t_end));
    scaled_error(&q, &qd, &x, &v, &[length, length], p.v0)
}

/// What the error of the uniform scene ([`uniform_error`]) compares the end state with, and how
/// it scales its components; the hand-written forms of the limit share it.
pub const UNIFORM_REFERENCE: &str =
    "closed form (42.29)–(42.30) at the closed-form impact time T (42.38); positions relative to \
     max(R, h0), velocities to v0, largest component";

/// The paper's uniform motion (42.29)–(42.30) to the closed-form impact time (42.38).
pub fn uniform_scene() -> Result<StudyScene<Fixed<UniformProjectile, 2, 1>>, Error> {
    let p = PAPER;
    let t_end = table(&p).uniform.t_impact;
    Ok(StudyScene {
        key: "uniform",
        title: "Uniform motion (paper, v0 = 10, g = 10, h0 = 5)".to_string(),
        reference: UNIFORM_REFERENCE.to_string(),
        problem: uniform_problem(&p)?,
        t_end,
        error: Box::new(move |q, qd| uniform_error(&p, t_end, [q[0], q[1]], [qd[0], qd[1]])),
        options: Box::new(move |tol| Options::until(t_end).tolerances(tol, tol)),
        ode_solvers_atol: Box::new(|tol| tol),
        fixed_steps: Ok(fixed_steps()),
        ode_solvers_skip: None,
    })
}

/// The classical motion (42.4)–(42.6) of the same particle to its impact time.
pub fn classical_scene() -> Result<StudyScene<Fixed<Unconstrained<Projectile>, 2, 0>>, Error> {
    let p = PAPER;
    let k = table(&p).classical;
    let t_end = k.t_impact;
    let length = k.range.max(p.h0);
    let speed = k.impact_speed;
    Ok(StudyScene {
        key: "classical",
        title: "Classical motion (paper, v0 = 10, g = 10, h0 = 5)".to_string(),
        reference:
            "closed form (42.4), (42.6) at the impact time T = √(2h0/g); positions relative \
                    to max(R, h0), velocities to the impact speed. The motion is a quadratic \
                    polynomial in t, which every method here integrates exactly: the error is \
                    rounding only, whatever the tolerance"
                .to_string(),
        problem: classical_problem(&p)?,
        t_end,
        error: Box::new(move |q, qd| {
            let (x, v) = (
                classical::position(&p, t_end),
                classical::velocity(&p, t_end),
            );
            scaled_error(q, qd, &x, &v, &[length, length], speed)
        }),
        options: Box::new(move |tol| Options::until(t_end).tolerances(tol, tol)),
        ode_solvers_atol: Box::new(|tol| tol),
        fixed_steps: Ok(fixed_steps()),
        ode_solvers_skip: None,
    })
}

/// The stiff scene to its closed-form impact time, with per-component absolute tolerances
/// ([`scaled_atol`]).
pub fn stiff_scene(max_steps: usize) -> Result<StudyScene<Fixed<UniformProjectile, 2, 1>>, Error> {
    let p = STIFF;
    let t_end = table(&p).uniform.t_impact;
    let (aq, av) = scaled_atol(&p, 1.0);
    let lambda = p.g / p.v0;
    // Classical Runge–Kutta is stable for h|λ| ≤ 2.785 on the negative real axis.
    let h_stable = 2.785 / lambda;
    let rk4_needed = (t_end / h_stable).ceil();
    Ok(StudyScene {
        key: "stiff",
        title: "Stiff scene (v0 = 1e-3, g = 9.81, h0 = 1)".to_string(),
        reference: format!(
            "closed form (42.29)–(42.30) at the closed-form impact time T = {t_end:.6} s; each \
             component relative to the scale of scaled_atol (x: {:.3e} m, y: {} m, velocities: {:.1e} m/s)",
            aq[0], aq[1], av[0]
        ),
        problem: uniform_problem(&p)?,
        t_end,
        error: Box::new(move |q, qd| {
            let (x, v) = (uniform::position(&p, t_end), uniform::velocity(&p, t_end));
            scaled_error(q, qd, &x, &v, &aq, av[0])
        }),
        options: Box::new(move |tol| {
            let (atol_q, atol_qd) = scaled_atol(&p, tol);
            let mut o = Options::until(t_end).atol_per_component(&atol_q, &atol_qd);
            o.rtol = tol;
            o
        }),
        // ode_solvers takes one absolute tolerance: the smallest of the scaled ones.
        ode_solvers_atol: Box::new(move |tol| tol * aq[0].min(aq[1]).min(av[0])),
        fixed_steps: Err(format!(
            "not run: the reduced equations have an eigenvalue of about −g/v0 = {:.3e}/s, so Rk4 \
             is stable only for h ≤ 2.785·v0/g = {h_stable:.2e} s, {rk4_needed:.2e} steps to \
             T = {t_end:.1} s, over the step budget of {max_steps}",
            -lambda
        )),
        ode_solvers_skip: None,
    })
}

/// The three-dimensional particle at constant speed, launched upwards out of the coordinate
/// planes, to `t = 2 s`.
pub fn particle3d_scene() -> Result<StudyScene<Fixed<Particle3d, 3, 1>>, Error> {
    let launch = Launch3d {
        particle: Particle3d { g: 9.81, v0: 10.0 },
        h0: 5.0,
        theta: 40f64.to_radians(),
        phi: 30f64.to_radians(),
    };
    let t_end = 2.0;
    let (x_end, _) = launch.closed_form(t_end);
    let length = x_end.abs().map(|c| c.max(launch.h0));
    let v0 = launch.particle.v0;
    Ok(StudyScene {
        key: "particle3d",
        title: "3D particle at constant speed (v0 = 10, g = 9.81, launched at 40°, azimuth 30°)"
            .to_string(),
        reference: "closed form: the paper's uniform motion (42.29)–(42.30) shifted in time by \
                    τ0 = −(v0/g) artanh(sin 40°) and turned to the azimuth, at t = 2 s; each \
                    position relative to max(|q_i(2)|, h0), velocities to v0"
            .to_string(),
        problem: launch.problem()?,
        t_end,
        error: Box::new(move |q, qd| {
            let (x, v) = launch.closed_form(t_end);
            scaled_error(q, qd, x.as_slice(), v.as_slice(), length.as_slice(), v0)
        }),
        options: Box::new(move |tol| Options::until(t_end).tolerances(tol, tol)),
        ode_solvers_atol: Box::new(|tol| tol),
        fixed_steps: Ok(fixed_steps()),
        ode_solvers_skip: None,
    })
}

/// The two particles under three constraints ([`TwoRunners`]) to `t = 1.5 s`, against a reference
/// computed by `Dop853` at `rtol = atol = 1e-13` with at most `t_end/2000` per step, checked
/// against `Rodas4` at `1e-13`. (Many more steps only add rounding: with `t_end/200000` the end
/// state moves by some `1e-12`.)
pub fn two_runners_scene() -> Result<StudyScene<Fixed<TwoRunners, 4, 3>>, Error> {
    let problem = TwoRunners::problem()?;
    let t_end = 1.5;
    let end_state = |sol: Solution| -> Result<(Vec<f64>, Vec<f64>), chetaev::Error> {
        let sol = sol.ok()?;
        let (_, q, qd) = sol.last().ok_or(chetaev::Error::InvalidOption {
            name: "t_end",
            value: t_end,
            hint: "the reference run recorded nothing",
        })?;
        Ok((q.to_vec(), qd.to_vec()))
    };
    let o = Options::until(t_end)
        .tolerances(1e-13, 1e-13)
        .max_steps(10_000_000)
        .output_final()
        .record(Record::State);
    let (q, qd) = end_state(solve(
        &problem,
        Dop853::default(),
        &o.clone().max_step(t_end / 2000.0),
    )?)?;
    let (q2, qd2) = end_state(solve(&problem, Rodas4, &o)?)?;
    let length: Vec<f64> = q.iter().map(|c| c.abs().max(1.0)).collect();
    let m = problem.model();
    let speed = m.c1.sqrt().max(m.c2.sqrt());
    let spread = scaled_error(&q2, &qd2, &q, &qd, &length, speed);
    Ok(StudyScene {
        key: "two-runners",
        title: "Two particles, three constraints (two speeds, one linear)".to_string(),
        reference: format!(
            "no closed form: a reference end state at t = 1.5 s from Dop853 at rtol = atol = 1e-13 \
             with steps of at most t_end/2000, which differs from Rodas4 at 1e-13 by {spread:.1e} \
             (errors below that are not resolved); positions relative to max(|q_i|, 1), velocities \
             to the larger speed"
        ),
        problem,
        t_end,
        error: Box::new(move |q_end, qd_end| scaled_error(q_end, qd_end, &q, &qd, &length, speed)),
        options: Box::new(move |tol| Options::until(t_end).tolerances(tol, tol)),
        ode_solvers_atol: Box::new(|tol| tol),
        fixed_steps: Ok(fixed_steps()),
        ode_solvers_skip: None,
    })
}

/// The paper's reduced equation (42.28) with `ẋ` from (42.24), state `(x, y, ẏ)`, on the paper's
/// data, with the same end time and error measure as [`uniform_scene`].
pub fn reduced_handwritten() -> HandWritten<Reduced> {
    let p = PAPER;
    let t_end = table(&p).uniform.t_impact;
    HandWritten {
        name: "hand-written (42.28)",
        system: Box::new(move || Reduced::new(p.g, p.v0)),
        y0: vec![0.0, p.h0, 0.0],
        t_end,
        error: Box::new(move |sys, y| uniform_error(&p, t_end, [y[0], y[1]], sys.velocity(y))),
    }
}

/// The full-coordinate form `a = g − (g·v)v/|v|²`, state `(x, y, ẋ, ẏ)`, on the paper's data, with
/// the same end time and error measure as [`uniform_scene`].
pub fn full_handwritten() -> HandWritten<Full> {
    let p = PAPER;
    let t_end = table(&p).uniform.t_impact;
    HandWritten {
        name: "hand-written full",
        system: Box::new(move || Full::new(p.g)),
        y0: vec![0.0, p.h0, p.v0, 0.0],
        t_end,
        error: Box::new(move |_, y| uniform_error(&p, t_end, [y[0], y[1]], [y[2], y[3]])),
    }
}
