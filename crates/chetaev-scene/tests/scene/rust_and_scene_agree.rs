//! The two guides solve one system: the sled on a slope with a prescribed speed, written in Rust in
//! `docs/adding-a-constraint.md` and as the scene `scenes/your-own-constraint.toml` of
//! `docs/scenes.md`. The Rust model and its solve below are the guide's, word for word (checked),
//! and the two motions agree at every grid point and at the events.

use std::f64::consts::PI;

use chetaev::prelude::*;
use chetaev_scene::Scene;

const GUIDE: &str = include_str!("../../../../docs/adding-a-constraint.md");
const SCENE: &str = include_str!("../../../../scenes/your-own-constraint.toml");
const THIS_FILE: &str = include_str!("rust_and_scene_agree.rs");

// The guide's model and solve, from here to the matching end marker.

/// A sled of mass `m` on a plane inclined by `alpha`, driven so that its speed is `v0 + a t`.
/// `q = (x, y, z)`: x across the slope (horizontal), y horizontal and pointing downhill, z up.
struct Sled {
    m: f64,
    g: f64,
    alpha: f64,
    v0: f64,
    a: f64,
}

/// L = ½ m |q̇|² − m g z
impl Lagrangian<3> for Sled {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 3>, qd: &SVector<R, 3>) -> R {
        qd.dot(qd) * (0.5 * self.m) - q[2] * (self.m * self.g)
    }
}

/// f₁ = |q̇|² − (v0 + a t)²    the speed: nonlinear in q̇, and dependent on time
/// f₂ = ż + tan α ẏ            the plane z = h0 − y tan α as a velocity constraint: linear in q̇
impl Constraints<3, 2> for Sled {
    fn constraints<R: Real>(&self, t: R, _q: &SVector<R, 3>, qd: &SVector<R, 3>) -> SVector<R, 2> {
        let v = t * self.a + self.v0;
        SVector::from([qd.dot(qd) - v * v, qd[2] + qd[1] * self.alpha.tan()])
    }
}

/// The sled from height `h0`, starting across the slope at speed `v0`, until it reaches the bottom
/// (`z = 0`) or `t = 20`: a run that locates the events, and the motion on 201 equally spaced
/// times.
fn slide(sled: Sled, h0: f64) -> Result<(Solution, Solution), chetaev::Error> {
    let (v0, cos, sin) = (sled.v0, sled.alpha.cos(), sled.alpha.sin());
    // Both constraints hold at the start: `Problem::new` checks, and says by how much if not.
    let (q0, qd0) = (SVector::from([0.0, 0.0, h0]), SVector::from([v0, 0.0, 0.0]));
    let problem = Problem::new(sled, 0.0, q0, qd0)?;

    // 1. The events, and where the motion stops. Event 0: the velocity has turned halfway from
    //    across to downhill. Event 1: the bottom, where the integration stops. Only the state at
    //    the start and at the end is recorded: the cheapest record.
    let half = Event::new("heading 45 degrees", move |_t, _q, qd| {
        qd[0] - (qd[1] * cos - qd[2] * sin)
    });
    let bottom = Event::new("bottom", |_t, q, _qd| q[2]).terminal();
    let options = Options::until(20.0)
        .tolerances(1e-10, 1e-10)
        .event(half.falling())
        .event(bottom.falling())
        .output_final()
        .record(Record::State);
    let events = solve(&problem, Dop853::default(), &options)?.ok()?;
    let t_end = events.t.last().copied().unwrap_or(options.t_end);

    // 2. The motion on 201 equally spaced times from 0 to there, with everything recorded.
    let options = Options::until(t_end)
        .tolerances(1e-10, 1e-10)
        .output_grid(0.0, 201)
        .record(Record::Energy);
    let motion = solve(&problem, Dop853::default(), &options)?.ok()?;
    Ok((events, motion))
}

// The end of the guide's model and solve.

/// The guide's parameters: those of the scene's `[parameters]`.
fn sled() -> Sled {
    Sled {
        m: 1.0,
        g: 9.81,
        alpha: PI / 9.0,
        v0: 2.0,
        a: 0.5,
    }
}
const H0: f64 = 3.0;

/// The part of this file between the two markers.
fn guide_part() -> &'static str {
    let begin = "// The guide's model and solve, from here to the matching end marker.\n\n";
    let start = THIS_FILE.find(begin).expect("begin marker") + begin.len();
    let len = THIS_FILE[start..]
        .find("\n// The end of the guide's model and solve.")
        .expect("end marker");
    &THIS_FILE[start..start + len]
}

#[test]
fn the_guide_shows_this_model_and_solve_verbatim() {
    let part = guide_part();
    assert!(part.contains("impl Constraints<3, 2> for Sled"));
    assert!(
        GUIDE.contains(part),
        "docs/adding-a-constraint.md no longer shows the model and solve of this test:\n{part}"
    );
    // And the guide's program uses the scene's parameters (`sled()` and `H0` here).
    assert!(GUIDE.contains("Sled { m: 1.0, g: 9.81, alpha: PI / 9.0, v0: 2.0, a: 0.5 }"));
    assert!(GUIDE.contains("slide(sled, 3.0)"));
}

#[test]
fn the_scene_states_the_same_system_and_options() {
    let scene = Scene::parse(SCENE, "your-own-constraint.toml").unwrap_or_else(|e| panic!("{e}"));
    let p: std::collections::HashMap<&str, f64> = scene
        .parameters
        .iter()
        .map(|(n, v)| (n.as_str(), *v))
        .collect();
    let s = sled();
    assert_eq!(
        (p["m"], p["g"], p["alpha"], p["v0"], p["a"], p["h0"]),
        (s.m, s.g, s.alpha, s.v0, s.a, H0)
    );
    assert_eq!((scene.t0, scene.q0.as_slice()), (0.0, &[0.0, 0.0, H0][..]));
    assert_eq!(scene.qd0, [s.v0, 0.0, 0.0]);
    assert!(!scene.project_velocity);
    assert_eq!(scene.solve.method.name(), Dop853::default().name());
    assert_eq!(
        (scene.solve.t_end, scene.solve.rtol, &scene.solve.atol),
        (20.0, 1e-10, &Atol::Scalar(1e-10))
    );
    assert!(!scene.solve.projection);
    let events: Vec<_> = scene
        .events
        .iter()
        .map(|e| (e.name.as_str(), e.direction, e.terminal))
        .collect();
    assert_eq!(
        events,
        [
            ("heading 45 degrees", Direction::Falling, false),
            ("bottom", Direction::Falling, true)
        ]
    );
}

/// The events: the Rust guide's first run and the scene's runs are Dop853 at `rtol = atol = 1e-10`
/// on the same equations with the same events, so they take the same steps, and differ only by
/// the rounding of the equations evaluated by compiled Rust (fixed-size dual passes) or by the
/// scene's expression graph (a tape): a few units in the last place. 1e-12 absolute, on numbers of
/// size 1 to 10.
const SAME_STEPS: f64 = 1e-12;

/// The grid: the same steps, except the last one. The guide's second run ends at the bottom and
/// clips its last step there; the scene's runs past it and stops at the event located inside it.
/// Between the last grid point before that step and the bottom, each is the dense output of its own
/// last step, within what `rtol = atol = 1e-10` allows of the exact motion, so the two agree to
/// twice that, `2e-10 (1 + |y|)` (they are identical before that step, and about 2e-11 apart
/// inside it).
fn grid_tolerance(y: f64) -> f64 {
    2e-10 * (1.0 + y.abs())
}

#[test]
fn the_rust_model_and_the_scene_give_the_same_motion_and_events() {
    let (events, motion) = slide(sled(), H0).unwrap_or_else(|e| panic!("{e}"));
    let scene = Scene::parse(SCENE, "your-own-constraint.toml").unwrap_or_else(|e| panic!("{e}"));
    let toml = scene.solve().unwrap_or_else(|e| panic!("{e}"));

    // Both stop at the bottom, after the same steps.
    assert_eq!(events.status, Status::Terminated { event: 1 });
    assert_eq!(toml.status, events.status);
    assert_eq!(motion.status, Status::Success);
    assert_eq!(toml.passes, 2);
    let steps = |s: &Solution| (s.stats.accepted_steps, s.stats.rejected_steps);
    assert_eq!(steps(&events), steps(&toml), "the same steps");
    assert_eq!(steps(&motion), steps(&toml), "the same number of steps");

    let close = |what: &str, t: f64, a: &[f64], b: &[f64], tol: &dyn Fn(f64) -> f64| {
        assert_eq!(a.len(), b.len(), "{what} at t = {t}: lengths");
        for (j, (x, y)) in a.iter().zip(b).enumerate() {
            assert!(
                (x - y).abs() <= tol(*y),
                "{what}[{j}] at t = {t}: Rust {x}, scene {y}, apart {:e}",
                (x - y).abs()
            );
        }
    };

    // The events: the same, in the same order, at the same times and states.
    assert_eq!(events.events.len(), 2);
    assert_eq!(toml.events.len(), events.events.len());
    for (r, s) in events.events.iter().zip(&toml.events) {
        assert_eq!(r.index, s.index);
        let what = toml.event_name(s.index);
        let same = |_: f64| SAME_STEPS;
        close(what, s.t, &[r.t], &[s.t], &same);
        close(what, s.t, &r.q, &s.q, &same);
        close(what, s.t, &r.qd, &s.qd, &same);
    }
    assert_eq!(toml.event_name(1), "bottom");

    // The grid: 201 times from 0 to the bottom.
    assert_eq!((motion.len(), toml.len()), (201, 201));
    let (last, bottom) = (motion.t.last(), toml.events.last().map(|e| e.t));
    close(
        "end",
        0.0,
        &[*last.expect("recorded")],
        &[bottom.expect("an event")],
        &|_| SAME_STEPS,
    );
    for i in 0..motion.len() {
        let t = toml.t[i];
        close("t", t, &[motion.t[i]], &[t], &|_| SAME_STEPS);
        close("q", t, &motion.q[i], &toml.q[i], &grid_tolerance);
        close("q̇", t, &motion.qd[i], &toml.qd[i], &grid_tolerance);
        close("μ", t, &motion.mu[i], &toml.mu[i], &grid_tolerance);
    }
}

#[test]
fn the_guide_quotes_what_its_program_prints() {
    let (events, _) = slide(sled(), H0).unwrap_or_else(|e| panic!("{e}"));
    for hit in &events.events {
        let printed = format!("`t = {:.13}`", hit.t);
        assert!(GUIDE.contains(&printed), "the guide should quote {printed}");
    }
    // The error it shows for a start straight downhill without the plane's ż.
    let qd0 = SVector::from([0.0, sled().v0, 0.0]);
    let e = Problem::new(sled(), 0.0, SVector::from([0.0, 0.0, H0]), qd0)
        .err()
        .expect("inconsistent");
    assert!(matches!(
        e,
        chetaev::Error::InconsistentInitialState { index: 2, .. }
    ));
    let printed = format!("error: {e}\n");
    assert!(GUIDE.contains(&printed), "the guide should show {printed}");
}
