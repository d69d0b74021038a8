//! The guide "Your own constraint in one file" (docs/scenes.md): the scene it shows is the file
//! `scenes/your-own-constraint.toml`, word for word, and it does what the guide says.

use std::f64::consts::PI;

use chetaev::prelude::Status;
use chetaev_scene::Scene;

const GUIDE: &str = include_str!("../../../../docs/scenes.md");
const SCENE: &str = include_str!("../../../../scenes/your-own-constraint.toml");

/// The first ```toml block after the guide's heading.
fn guide_block() -> &'static str {
    let at = GUIDE
        .find("## Your own constraint in one file")
        .expect("the guide's heading");
    let rest = &GUIDE[at..];
    let start = rest.find("```toml\n").expect("a toml block") + "```toml\n".len();
    let len = rest[start..].find("```").expect("the block's end");
    &rest[start..start + len]
}

#[test]
fn the_guide_shows_the_scene_file_verbatim() {
    assert_eq!(guide_block(), SCENE);
}

#[test]
fn the_guide_scene_runs_and_agrees_with_its_closed_forms() {
    let scene = Scene::parse(SCENE, "your-own-constraint.toml").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((scene.n(), scene.k()), (3, 2));
    scene.check().expect("consistent");
    let o = scene.solve().expect("solves");
    assert_eq!(o.status, Status::Terminated { event: 1 });
    assert_eq!(o.t.len(), 201);

    let p: std::collections::HashMap<&str, f64> = scene
        .parameters
        .iter()
        .map(|(n, v)| (n.as_str(), *v))
        .collect();
    let (m, g, alpha, v0, a, h0) = (p["m"], p["g"], p["alpha"], p["v0"], p["a"], p["h0"]);
    assert_eq!(alpha, PI / 9.0);
    let k = g * alpha.sin() / a;
    for i in 0..o.t.len() {
        let (t, q, qd) = (o.t[i], &o.q[i], &o.qd[i]);
        let speed = (qd[0] * qd[0] + qd[1] * qd[1] + qd[2] * qd[2]).sqrt();
        assert!((speed - (v0 + a * t)).abs() < 1e-9, "speed at t = {t}");
        assert!(
            (q[2] - (h0 - q[1] * alpha.tan())).abs() < 1e-12,
            "plane at t = {t}"
        );
        let heading = qd[0].atan2(qd[1] * alpha.cos() - qd[2] * alpha.sin());
        let exact = 2.0 * (v0 / (v0 + a * t)).powf(k).atan();
        assert!((heading - exact).abs() < 1e-9, "heading at t = {t}");
        // The normal force of the plane, constant.
        assert!((o.mu[i][1] - m * g * alpha.cos().powi(2)).abs() < 1e-9);
    }
    assert!((o.mu[0][0] - m * a / (2.0 * v0)).abs() < 1e-12);
    assert!(o.mu.iter().any(|mu| mu[0] < 0.0));

    // The event "heading 45 degrees" at t = (v0/a)(tan(π/8)^(−1/k) − 1).
    let half = &o.events[0];
    assert_eq!(o.event_name(half.index), "heading 45 degrees");
    let t_half = v0 / a * ((PI / 8.0).tan().powf(-1.0 / k) - 1.0);
    assert!((half.t - t_half).abs() < 1e-9, "{} vs {t_half}", half.t);
    let bottom = &o.events[1];
    assert_eq!(o.event_name(bottom.index), "bottom");
    assert!(bottom.q[2].abs() < 1e-9);
    // The numbers the guide quotes.
    assert!(GUIDE.contains(&format!(
        "`t = {}`",
        chetaev_scene::output::summary_number(half.t)
    )));
    assert!(GUIDE.contains(&format!(
        "`t = {}`",
        chetaev_scene::output::summary_number(bottom.t)
    )));
}

#[test]
fn the_summary_shown_in_the_guide_is_what_a_run_prints() {
    let start = GUIDE
        .find("$ chetaev run scenes/uniform-projectile.toml\n")
        .expect("the example run");
    let block = &GUIDE[start..];
    let block = &block[block.find('\n').expect("line") + 1..block.find("```").expect("end")];
    let shown: Vec<&str> = block.lines().filter(|l| !l.contains("  wrote  ")).collect();
    let text = include_str!("../../../../scenes/uniform-projectile.toml");
    let scene = Scene::parse(text, "scenes/uniform-projectile.toml").expect("parses");
    let outcome = scene.solve().expect("solves");
    let printed = chetaev_scene::output::summary(&scene, &outcome);
    assert_eq!(printed.lines().collect::<Vec<_>>(), shown);
}
