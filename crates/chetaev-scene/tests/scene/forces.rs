//! Forces not derivable from `L` in scene files: the paper's particle with linear drag
//! (`scenes/uniform-projectile-with-drag.toml`) against its closed form (docs/forces.md), and the
//! located errors of a wrong `forces` list.

use chetaev_scene::Scene;
use uniform_projectile::closed_form::{uniform, Params};

#[test]
fn the_drag_scene_keeps_the_paper_motion_and_shifts_mu_by_c_over_2() {
    let text = include_str!("../../../../scenes/uniform-projectile-with-drag.toml");
    let scene = Scene::parse(text, "scenes/uniform-projectile-with-drag.toml").expect("parses");
    let o = scene.solve().expect("solves");
    assert!(o.is_success(), "{:?}", o.status);
    let p = Params::PAPER;
    let c = 0.7;
    assert!(o.len() > 50);
    for (i, &t) in o.t.iter().enumerate() {
        let x = uniform::position(&p, t);
        assert!((o.q[i][0] - x[0]).abs() < 1e-9, "x at t = {t}");
        assert!((o.q[i][1] - x[1]).abs() < 1e-9, "y at t = {t}");
        let mu = uniform::multiplier(&p, t) + c / 2.0;
        assert!((o.mu[i][0] - mu).abs() < 1e-9, "μ at t = {t}");
        assert!(
            (o.work_forces[i] + c * p.v0 * p.v0 * t).abs() < 1e-8,
            "W_Q at t = {t}"
        );
        assert!(o.balance[i].abs() < 1e-8, "balance at t = {t}");
    }
}

#[test]
fn a_forces_list_of_the_wrong_length_is_a_located_error() {
    let text = include_str!("../../../../scenes/uniform-projectile-with-drag.toml")
        .replace("dissipation = ", "forces = [\"-c*x_dot\"]\ndissipation = ");
    let err = Scene::parse(&text, "bad.toml").expect_err("one force for two coordinates");
    let message = err.to_string();
    assert!(message.contains("1 force for 2 coordinates"), "{message}");
}
