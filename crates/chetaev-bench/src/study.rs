//! The work-precision study: every method on a scene over a range of tolerances, with the error
//! at the end time, the median run time and the work counters.

use chetaev::integrate::driver::{solve_ode, OdeOptions};
use chetaev::integrate::system::{OdeSystem, Stats};
use chetaev::prelude::*;
use chetaev_ode_solvers::{solve_with_ode_solvers, OdeSolversMethod};

use crate::handwritten::{Full, Reduced};
use crate::measure::{time_interleaved, time_median, Budget, Run};

/// What happened to one configuration of the study.
#[derive(Clone, Debug, PartialEq)]
pub enum PointOutcome {
    /// Integrated to the end time; the error and timing are measured.
    Measured,
    /// Not run, with the reason (the configuration makes no sense, or the solver refuses it).
    Skipped(String),
    /// Run, and the integration failed (the counters are those of the failed run).
    Failed(String),
}

/// One point of a work-precision curve.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    /// The scene's key.
    pub scene: String,
    /// The method (the ode_solvers backend and the hand-written systems say so in the name).
    pub method: String,
    /// The tolerance asked for (`rtol`, and `atol` as the scene says); NaN for a fixed step.
    pub tolerance: f64,
    /// The fixed step; NaN for adaptive methods.
    pub step: f64,
    /// What happened.
    pub outcome: PointOutcome,
    /// The error at the end time, as the scene measures it; NaN unless measured.
    pub error: f64,
    /// Median wall time, seconds; NaN unless measured.
    pub seconds: f64,
    /// Timed runs.
    pub repeats: usize,
    /// Right-hand-side evaluations.
    pub rhs_evaluations: usize,
    /// Jacobian evaluations.
    pub jacobian_evaluations: usize,
    /// Evaluations for recorded diagnostics.
    pub output_evaluations: usize,
    /// Accepted steps.
    pub accepted_steps: usize,
    /// Rejected steps.
    pub rejected_steps: usize,
}

impl Point {
    fn new(scene: &str, method: &str, tolerance: f64, step: f64, outcome: PointOutcome) -> Self {
        Self {
            scene: scene.to_string(),
            method: method.to_string(),
            tolerance,
            step,
            outcome,
            error: f64::NAN,
            seconds: f64::NAN,
            repeats: 0,
            rhs_evaluations: 0,
            jacobian_evaluations: 0,
            output_evaluations: 0,
            accepted_steps: 0,
            rejected_steps: 0,
        }
    }

    fn with_stats(mut self, s: &Stats) -> Self {
        self.rhs_evaluations = s.rhs_evaluations;
        self.jacobian_evaluations = s.jacobian_evaluations;
        self.output_evaluations = s.output_evaluations;
        self.accepted_steps = s.accepted_steps;
        self.rejected_steps = s.rejected_steps;
        self
    }

    /// Whether the point was measured.
    pub fn is_measured(&self) -> bool {
        self.outcome == PointOutcome::Measured
    }
}

/// The `(error, seconds)` curve of one method, in the order of the points (tightening tolerance
/// or shrinking step), measured points only.
pub fn curve(points: &[Point], method: &str) -> Vec<(f64, f64)> {
    points
        .iter()
        .filter(|p| p.method == method && p.is_measured())
        .map(|p| (p.error, p.seconds))
        .collect()
}

/// The error measure of a scene: the end state `(q, q̇)` against its reference, as one number.
pub type ErrorFn = Box<dyn Fn(&[f64], &[f64]) -> f64>;

/// One scene of the study: a problem of model `M` with its end time, its reference and the
/// settings of the methods on it.
pub struct StudyScene<M> {
    /// Short name, used for file names.
    pub key: &'static str,
    /// Title for tables and diagrams.
    pub title: String,
    /// What the error is measured against, and how it is scaled.
    pub reference: String,
    /// The problem.
    pub problem: Problem<M>,
    /// The end time.
    pub t_end: f64,
    /// The error of the end state.
    pub error: ErrorFn,
    /// The options of chetaev's adaptive methods at tolerance `tol` (without output settings).
    pub options: Box<dyn Fn(f64) -> Options>,
    /// The absolute tolerance handed to ode_solvers (one scalar) at tolerance `tol`.
    pub ode_solvers_atol: Box<dyn Fn(f64) -> f64>,
    /// Step counts for the methods without error control (`Rk4`), or why they are not run.
    pub fixed_steps: Result<Vec<usize>, String>,
    /// Why ode_solvers is not run, if it is not.
    pub ode_solvers_skip: Option<String>,
}

/// The settings of a study.
#[derive(Clone, Debug, PartialEq)]
pub struct StudyConfig {
    /// Tolerances, loosest first.
    pub tolerances: Vec<f64>,
    /// Timing of each configuration.
    pub budget: Budget,
    /// Step limit of every run (accepted plus rejected).
    pub max_steps: usize,
}

impl Default for StudyConfig {
    fn default() -> Self {
        Self {
            tolerances: (3..=14).map(|k| 10f64.powi(-k)).collect(),
            budget: Budget::default(),
            max_steps: 200_000,
        }
    }
}

/// The largest step limit of the ode_solvers runs: ode_solvers' own default (`n_max = 100 000` of
/// its `Dopri5::new` and `Dop853::new`). A study's smaller `max_steps` applies to them too.
pub const ODE_SOLVERS_MAX_STEPS: usize = 100_000;

/// One untimed run of `method` on `scene`: the point with its error and counters, not yet timed
/// (a refused configuration is skipped, a failed run is reported with its counters).
fn chetaev_evaluate<M, Me>(
    scene: &StudyScene<M>,
    method: Me,
    tolerance: f64,
    step: f64,
    options: &Options,
) -> Point
where
    M: Model,
    Me: Method + Copy,
{
    let name = method.name();
    match solve(&scene.problem, method, options) {
        Err(e) => Point::new(
            scene.key,
            name,
            tolerance,
            step,
            PointOutcome::Skipped(e.to_string()),
        ),
        Ok(sol) => end_point(scene, name, tolerance, step, &sol),
    }
}

/// The point of a finished run: its counters, and its end-state error where it reached `t_end`.
fn end_point<M>(
    scene: &StudyScene<M>,
    name: &str,
    tolerance: f64,
    step: f64,
    sol: &Solution,
) -> Point {
    let mut p =
        Point::new(scene.key, name, tolerance, step, PointOutcome::Measured).with_stats(&sol.stats);
    if let Some(e) = sol.error() {
        p.outcome = PointOutcome::Failed(e.to_string());
        return p;
    }
    match sol.last() {
        Some((t, q, qd)) if (t - scene.t_end).abs() <= 1e-12 * scene.t_end.abs().max(1.0) => {
            p.error = (scene.error)(q, qd);
        }
        Some((t, _, _)) => {
            p.outcome =
                PointOutcome::Failed(format!("stopped at t = {t} before t_end = {}", scene.t_end));
        }
        None => p.outcome = PointOutcome::Failed("nothing recorded".to_string()),
    }
    p
}

/// Fills in the median time of `run` when `p` was measured.
fn timed<T, E: std::fmt::Display>(
    mut p: Point,
    budget: &Budget,
    run: impl FnMut() -> Result<T, E>,
) -> Point {
    if !p.is_measured() {
        return p;
    }
    match time_median(budget, run) {
        Ok((_, timing)) => {
            p.seconds = timing.median;
            p.repeats = timing.repeats;
        }
        Err(e) => p.outcome = PointOutcome::Failed(e.to_string()),
    }
    p
}

/// Times `method` on `scene` with `options`, returning the point.
fn chetaev_point<M, Me>(
    scene: &StudyScene<M>,
    method: Me,
    tolerance: f64,
    step: f64,
    options: &Options,
    budget: &Budget,
) -> Point
where
    M: Model,
    Me: Method + Copy,
{
    let p = chetaev_evaluate(scene, method, tolerance, step, options);
    timed(p, budget, || solve(&scene.problem, method, options))
}

/// The options of the ode_solvers runs on `scene` at `tol`: `rtol = tol` and the scene's one
/// scalar `atol`, everything recorded (`Record::Energy`) at every accepted step, ode_solvers' own
/// step-size control, and its own step limit ([`ODE_SOLVERS_MAX_STEPS`]) or the study's
/// `max_steps`, whichever is smaller.
pub fn ode_solvers_options<M>(scene: &StudyScene<M>, tol: f64, max_steps: usize) -> Options {
    Options::until(scene.t_end)
        .tolerances(tol, (scene.ode_solvers_atol)(tol))
        .record(Record::Energy)
        .max_steps(max_steps.min(ODE_SOLVERS_MAX_STEPS))
}

fn ode_solvers_point<M>(
    scene: &StudyScene<M>,
    method: OdeSolversMethod,
    tolerance: f64,
    config: &StudyConfig,
) -> Point
where
    M: Model,
{
    let name = method.name();
    if let Some(reason) = &scene.ode_solvers_skip {
        return Point::new(
            scene.key,
            name,
            tolerance,
            f64::NAN,
            PointOutcome::Skipped(reason.clone()),
        );
    }
    let options = ode_solvers_options(scene, tolerance, config.max_steps);
    let run = || solve_with_ode_solvers(&scene.problem, method, &options);
    let p = match run() {
        Err(e) => {
            return Point::new(
                scene.key,
                name,
                tolerance,
                f64::NAN,
                PointOutcome::Skipped(e.to_string()),
            )
        }
        Ok(sol) => end_point(scene, name, tolerance, f64::NAN, &sol),
    };
    timed(p, &config.budget, run)
}

/// The options of the adaptive methods on `scene` at `tol`: no diagnostics, output at the end.
fn adaptive_options<M>(scene: &StudyScene<M>, config: &StudyConfig, tol: f64) -> Options {
    (scene.options)(tol)
        .output_final()
        .record(Record::State)
        .max_steps(config.max_steps)
}

/// The options of a method without error control taking `n` steps to the end of `scene`.
fn fixed_step_options<M>(scene: &StudyScene<M>, config: &StudyConfig, n: usize) -> Options {
    Options::until(scene.t_end)
        .output_final()
        .record(Record::State)
        .max_steps(config.max_steps.max(n + 1))
}

/// `method` on `scene` over the tolerances of `config`, timed.
fn adaptive_points<M, Me>(scene: &StudyScene<M>, config: &StudyConfig, method: Me) -> Vec<Point>
where
    M: Model,
    Me: Method + Copy,
{
    config
        .tolerances
        .iter()
        .map(|&tol| {
            let o = adaptive_options(scene, config, tol);
            chetaev_point(scene, method, tol, f64::NAN, &o, &config.budget)
        })
        .collect()
}

/// Runs `$body` with `$m` bound to the method of the library's list called `$name` (step `$step`
/// for a method without error control), by its own type for the methods named here, as a user
/// calls them, and through `AnyMethod` for any other: the run-time choice of method is compiled
/// differently and takes a measurably different time, so a method added to the list is studied at
/// once, and measured as its users call it once it is named here.
macro_rules! with_method {
    ($name:expr, $step:expr, |$m:ident| $body:expr, |$e:ident| $refused:expr) => {
        match $name {
            "Dopri5" => {
                let $m = Dopri5::default();
                $body
            }
            "Dop853" => {
                let $m = Dop853::default();
                $body
            }
            "Tsit5" => {
                let $m = Tsit5::default();
                $body
            }
            "Rk4" => {
                let $m = Rk4::new($step);
                $body
            }
            "Rodas4" => {
                let $m = Rodas4;
                $body
            }
            "Rodas5P" => {
                let $m = Rodas5P;
                $body
            }
            other => match AnyMethod::from_name(other, Some($step)) {
                Ok($m) => $body,
                Err($e) => $refused,
            },
        }
    };
}

/// Whether the method of the library's list called `name` has a fixed step (no error control).
fn has_fixed_step(name: &str) -> bool {
    AnyMethod::from_name(name, Some(1.0)).is_ok_and(|m| m.info().fixed_step.is_some())
}

/// The methods of the library's list (`AnyMethod::NAMES`) in the order the study runs them and
/// its tables list them: those with error control first, then those without.
pub fn study_methods() -> Vec<&'static str> {
    let (fixed, adaptive): (Vec<&'static str>, Vec<&'static str>) = AnyMethod::NAMES
        .iter()
        .partition(|name| has_fixed_step(name));
    adaptive.into_iter().chain(fixed).collect()
}

/// Makes the scene's right-hand side as machine code before its first solve, where the host has
/// it. A problem otherwise switches to it after `NATIVE_AFTER` right-hand sides counted over all
/// its solves, so an item's last bits would depend on the items run before it in the process
/// (a shard of the sweep or the whole of it).
fn with_machine_code<M: Model>(scene: &StudyScene<M>) {
    if let Some(compiled) = scene.problem.compiled() {
        compiled.native_operations();
    }
}

/// Runs the whole study on one scene: every method of the library's list ([`study_methods`]),
/// those with error control over the tolerances and those without over the step counts, and
/// ode_solvers' `Dopri5`, `Dop853` over the tolerances. `progress` is told the name of each method
/// as it starts.
pub fn run_scene<M>(
    scene: &StudyScene<M>,
    config: &StudyConfig,
    progress: &mut dyn FnMut(&str),
) -> Vec<Point>
where
    M: Model,
{
    with_machine_code(scene);
    let mut points = Vec::new();
    let b = &config.budget;
    for name in study_methods() {
        progress(name);
        let skipped = |reason: String| {
            Point::new(
                scene.key,
                name,
                f64::NAN,
                f64::NAN,
                PointOutcome::Skipped(reason),
            )
        };
        if !has_fixed_step(name) {
            points.extend(with_method!(
                name,
                1.0,
                |m| adaptive_points(scene, config, m),
                |e| vec![skipped(e.to_string())]
            ));
            continue;
        }
        match &scene.fixed_steps {
            Ok(steps) => {
                for &n in steps {
                    let h = scene.t_end / n as f64;
                    let o = fixed_step_options(scene, config, n);
                    points.push(with_method!(
                        name,
                        h,
                        |m| chetaev_point(scene, m, f64::NAN, h, &o, b),
                        |e| skipped(e.to_string())
                    ));
                }
            }
            Err(reason) => points.push(skipped(reason.clone())),
        }
    }
    for m in OdeSolversMethod::ALL {
        progress(m.name());
        for &tol in &config.tolerances {
            points.push(ode_solvers_point(scene, m, tol, config));
        }
    }
    points
}

/// The error of a hand-written system's end state `y` (the system is passed for what it knows,
/// such as a velocity eliminated from the state).
pub type StateErrorFn<S> = Box<dyn Fn(&S, &[f64]) -> f64>;

/// A hand-written system with its initial state and the error of its end state.
pub struct HandWritten<S> {
    /// Name in tables and diagrams.
    pub name: &'static str,
    /// A fresh system (counters at zero).
    pub system: Box<dyn Fn() -> S>,
    /// The initial state.
    pub y0: Vec<f64>,
    /// The end time.
    pub t_end: f64,
    /// The error of the end state.
    pub error: StateErrorFn<S>,
}

/// The counters a hand-written system keeps.
pub trait Counted {
    /// `(right-hand sides, Jacobians)` so far.
    fn counted(&self) -> (usize, usize);
}

impl Counted for Reduced {
    fn counted(&self) -> (usize, usize) {
        (self.counts.rhs, self.counts.jacobians)
    }
}

impl Counted for Full {
    fn counted(&self) -> (usize, usize) {
        (self.counts.rhs, self.counts.jacobians)
    }
}

/// One untimed run of a hand-written system: the point with its error and counters.
fn handwritten_evaluate<S, Me>(
    scene_key: &str,
    hw: &HandWritten<S>,
    method: Me,
    tolerance: f64,
    step: f64,
    options: &OdeOptions,
) -> Point
where
    S: OdeSystem + Counted,
    Me: Method + Copy,
{
    let name = format!("{} {}", method.name(), hw.name);
    let mut sys = (hw.system)();
    let sol = match solve_ode(&mut sys, method, 0.0, &hw.y0, options) {
        Ok(sol) => sol,
        Err(e) => {
            return Point::new(
                scene_key,
                &name,
                tolerance,
                step,
                PointOutcome::Skipped(e.to_string()),
            )
        }
    };
    let (rhs, jac) = sys.counted();
    let mut p = Point::new(scene_key, &name, tolerance, step, PointOutcome::Measured);
    p.rhs_evaluations = rhs;
    p.jacobian_evaluations = jac;
    p.accepted_steps = sol.stats.accepted_steps;
    p.rejected_steps = sol.stats.rejected_steps;
    if let Some(e) = sol.error {
        p.outcome = PointOutcome::Failed(e.to_string());
        return p;
    }
    match (sol.t.last(), sol.y.last()) {
        (Some(&t), Some(y)) if (t - hw.t_end).abs() <= 1e-12 * hw.t_end.abs().max(1.0) => {
            p.error = (hw.error)(&sys, y);
        }
        _ => p.outcome = PointOutcome::Failed("did not reach t_end".to_string()),
    }
    p
}

/// chetaev on `scene` and the two hand-written systems with the same method and setting, timed
/// interleaved ([`time_interleaved`]) so that all three see the same background load.
#[allow(clippy::too_many_arguments)]
fn limit_triple<M, Me>(
    scene: &StudyScene<M>,
    reduced: &HandWritten<Reduced>,
    full: &HandWritten<Full>,
    method: Me,
    tolerance: f64,
    step: f64,
    options: &Options,
    ode_options: &OdeOptions,
    budget: &Budget,
) -> [Point; 3]
where
    M: Model,
    Me: Method + Copy,
{
    let mut points = [
        chetaev_evaluate(scene, method, tolerance, step, options),
        handwritten_evaluate(scene.key, reduced, method, tolerance, step, ode_options),
        handwritten_evaluate(scene.key, full, method, tolerance, step, ode_options),
    ];
    let mut which = Vec::new();
    let mut runs: Vec<Run<'_, chetaev::Error>> = Vec::new();
    if points[0].is_measured() {
        which.push(0);
        runs.push(Box::new(|| {
            solve(&scene.problem, method, options).map(|_| ())
        }));
    }
    if points[1].is_measured() {
        which.push(1);
        runs.push(Box::new(|| {
            let mut sys = (reduced.system)();
            solve_ode(&mut sys, method, 0.0, &reduced.y0, ode_options).map(|_| ())
        }));
    }
    if points[2].is_measured() {
        which.push(2);
        runs.push(Box::new(|| {
            let mut sys = (full.system)();
            solve_ode(&mut sys, method, 0.0, &full.y0, ode_options).map(|_| ())
        }));
    }
    match time_interleaved(budget, &mut runs) {
        Ok(timings) => {
            for (&i, t) in which.iter().zip(timings) {
                points[i].seconds = t.median;
                points[i].repeats = t.repeats;
            }
        }
        Err(e) => {
            for &i in &which {
                points[i].outcome = PointOutcome::Failed(e.to_string());
            }
        }
    }
    points
}

/// `method` on the paper's model through chetaev and on the two hand-written systems over the
/// tolerances of `config` (`rtol = atol = tol` for all three), timed interleaved.
fn limit_adaptive<M, Me>(
    scene: &StudyScene<M>,
    reduced: &HandWritten<Reduced>,
    full: &HandWritten<Full>,
    config: &StudyConfig,
    method: Me,
) -> Vec<Point>
where
    M: Model,
    Me: Method + Copy,
{
    let mut points = Vec::new();
    for &tol in &config.tolerances {
        let o = adaptive_options(scene, config, tol);
        let mut oo = OdeOptions::until(scene.t_end).tolerances(tol, tol);
        oo.output = Output::Final;
        oo.max_steps = config.max_steps;
        points.extend(limit_triple(
            scene,
            reduced,
            full,
            method,
            tol,
            f64::NAN,
            &o,
            &oo,
            &config.budget,
        ));
    }
    points
}

/// The limit: every method of the library's list, those with error control over the tolerances
/// and those without over `fixed_steps`, each on the paper's model through chetaev (`scene`, the
/// uniform motion) and on the two hand-written systems through the same driver ([`solve_ode`]),
/// the three timed interleaved at every setting.
pub fn run_limit<M>(
    scene: &StudyScene<M>,
    reduced: &HandWritten<Reduced>,
    full: &HandWritten<Full>,
    config: &StudyConfig,
    fixed_steps: &[usize],
) -> Vec<Point>
where
    M: Model,
{
    with_machine_code(scene);
    let mut points = Vec::new();
    for name in study_methods() {
        let refused = |e: chetaev::Error| {
            vec![Point::new(
                scene.key,
                name,
                f64::NAN,
                f64::NAN,
                PointOutcome::Skipped(e.to_string()),
            )]
        };
        if !has_fixed_step(name) {
            points.extend(with_method!(
                name,
                1.0,
                |m| limit_adaptive(scene, reduced, full, config, m),
                |e| refused(e)
            ));
            continue;
        }
        for &n in fixed_steps {
            let h = scene.t_end / n as f64;
            let o = fixed_step_options(scene, config, n);
            let mut oo = OdeOptions::until(scene.t_end);
            oo.output = Output::Final;
            oo.max_steps = config.max_steps.max(n + 1);
            points.extend(with_method!(
                name,
                h,
                |m| limit_triple(
                    scene,
                    reduced,
                    full,
                    m,
                    f64::NAN,
                    h,
                    &o,
                    &oo,
                    &config.budget
                )
                .to_vec(),
                |e| refused(e)
            ));
        }
    }
    points
}
