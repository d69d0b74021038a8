"""Scene files (docs/scenes.md) from Python: the paper's scene parsed and loaded, solved with its
own options and with others, against the closed form; mistakes reported at their place."""

from __future__ import annotations

import pathlib
import re

import numpy as np
import pytest

import chetaev
from models import particle_closed_form, particle_impact_time

# tests -> chetaev-py -> crates -> the repository
SCENE = pathlib.Path(__file__).resolve().parents[3] / "scenes" / "uniform-projectile.toml"
T_IMPACT = particle_impact_time()
# The scene asks rtol = atol = 1e-12; over ~1 s the global error is a modest multiple: 1e-9.
SCENE_GLOBAL = 1e-9


@pytest.fixture(scope="module")
def scene_text():
    return SCENE.read_text(encoding="utf-8")


@pytest.mark.parametrize("how", ["parse", "load str", "load Path"])
def test_the_paper_scene_solved_with_its_own_options_hits_the_ground_at_the_closed_form_time(
    scene_text, how
):
    scene = {"parse": lambda: chetaev.Scene.parse(scene_text),
             "load str": lambda: chetaev.Scene.load(str(SCENE)),
             "load Path": lambda: chetaev.Scene.load(SCENE)}[how]()
    assert scene.coordinates == ["x", "y"]
    sol = scene.solve()
    assert sol.status == "terminated" and sol.terminated_by == 0
    hit = sol.events[0]
    assert hit.name == "impact"  # the scene's name for its event
    assert hit.t == pytest.approx(T_IMPACT, abs=SCENE_GLOBAL)
    q, qd, mu = particle_closed_form(hit.t)
    assert hit.q[0] == pytest.approx(q[0], abs=10 * SCENE_GLOBAL)  # the range R
    # the scene's [output] times: 101 from 0 to the end (the impact)
    assert len(sol) == 101 and sol.t[0] == 0.0 and sol.t[-1] == hit.t
    q, qd, mu = particle_closed_form(sol.t)
    np.testing.assert_allclose(sol.q, q, rtol=0, atol=10 * SCENE_GLOBAL)
    np.testing.assert_allclose(sol.mu, mu, rtol=0, atol=SCENE_GLOBAL)


def test_a_scenes_problem_solved_with_other_options_follows_the_closed_form(scene_text):
    problem = chetaev.Scene.parse(scene_text).problem()
    assert problem.model is None and problem.coordinates == ["x", "y"]
    np.testing.assert_array_equal(problem.q0, [0.0, 5.0])  # "h0" resolved
    np.testing.assert_array_equal(problem.qd0, [10.0, 0.0])  # "v0" resolved
    tol = 1e-10
    times = np.linspace(0.0, 1.0, 5)
    sol = chetaev.solve(problem, 1.0, method="rodas5p", rtol=tol, atol=tol, output=times)
    np.testing.assert_array_equal(sol.t, times)
    q, _, mu = particle_closed_form(times)
    # global error a modest multiple of tol over 1 s: 100 * tol
    np.testing.assert_allclose(sol.q, q, rtol=0, atol=1000 * tol)
    np.testing.assert_allclose(sol.mu, mu, rtol=0, atol=100 * tol)


def test_events_on_a_scenes_problem_are_refused_pointing_to_the_scene_file(scene_text):
    problem = chetaev.Scene.parse(scene_text).problem()
    with pytest.raises(chetaev.ChetaevError, match=r"\[\[events\]\]"):
        chetaev.solve(problem, 1.0, events=[chetaev.Event("impact", "y")])


def test_a_typo_in_an_expression_is_a_scene_error_at_its_line_and_column(scene_text):
    bad = scene_text.replace("x_dot^2 + y_dot^2 - v0^2", "x_dot^^2 + y_dot^2 - v0^2")
    assert bad != scene_text
    lines = bad.splitlines()
    line = next(i for i, text in enumerate(lines, 1) if "^^" in text)
    column = lines[line - 1].index("^^") + 2  # 1-based, at the second '^'
    with pytest.raises(chetaev.SceneError) as info:
        chetaev.Scene.parse(bad, name="typo.toml")
    message = str(info.value)
    assert message.startswith(f"typo.toml:{line}:{column}:"), message
    assert "^" in message.splitlines()[-1]  # the snippet's marker


def test_a_misspelt_key_is_a_scene_error_naming_the_keys_it_expected(scene_text):
    bad = scene_text.replace("t_end", "t_ned")
    with pytest.raises(chetaev.SceneError) as info:
        chetaev.Scene.parse(bad)
    message = str(info.value)
    assert re.match(r"<scene>:\d+:\d+:", message), message
    assert "t_ned" in message and "`t_end`" in message


def test_a_missing_scene_file_is_a_scene_error_naming_the_path(tmp_path):
    path = tmp_path / "nowhere.toml"
    with pytest.raises(chetaev.SceneError, match="nowhere.toml"):
        chetaev.Scene.load(path)


def test_an_initial_velocity_off_the_constraint_in_a_scene_is_refused(scene_text):
    bad = scene_text.replace('q_dot = ["v0", 0.0]', 'q_dot = ["v0", 1.0]')
    assert bad != scene_text
    scene = chetaev.Scene.parse(bad)  # read fine: the state is checked when the problem is made
    with pytest.raises(chetaev.ChetaevError, match="q_dot|velocity"):
        scene.problem()


def test_a_scene_describes_its_derived_equations(scene_text):
    scene = chetaev.Scene.parse(scene_text)
    text = scene.describe()
    assert "W = ∂²L/∂q̇²" in text and "J = ∂f/∂q̇" in text
    latex = scene.describe(latex=True)
    assert "\\begin{align*}" in latex and "\\end{align*}" in latex


def test_a_scene_with_sensitivities_gives_the_impact_times_derivatives_of_the_closed_form():
    import sympy as sp

    scene = chetaev.Scene.load(SCENE.with_name("uniform-projectile-sensitivities.toml"))
    sol = scene.solve()
    g, v0, h0 = sp.symbols("g v0 h0", positive=True)
    T = v0 / g * sp.acosh(sp.exp(g * h0 / v0**2))
    values = {g: 10.0, v0: 10.0, h0: 5.0}
    hit = sol.events[0]
    assert set(hit.dt) == {"v0", "g", "h0"} and set(sol.sensitivities) == {"v0", "g", "h0"}
    for name, symbol in (("v0", v0), ("g", g), ("h0", h0)):
        # the scene asks rtol = atol = 1e-12 with control = true: SCENE_GLOBAL
        assert hit.dt[name] == pytest.approx(float(sp.diff(T, symbol).subs(values)),
                                             abs=SCENE_GLOBAL), name


PUSHED_PENDULUM = """
[parameters]
m = 1.5
g = 9.81
l = 2.0
c = 6.0
F = 4.0

[model]
coordinates = ["theta"]
lagrangian = "0.5*m*l^2*theta_dot^2 + m*g*l*cos(theta)"
dissipation = "0.5*c*theta_dot^2"
{forces}
{loads}
[initial]
q = [0.1]
q_dot = [0.5]

[solve]
t_end = 80.0
rtol = 1e-11
atol = 1e-12

[output]
tables = ["state"]
times = "steps"
"""

PUSH = """
[[loads]]
point = ["l*sin(theta)", "-l*cos(theta)"]
force = ["F", "0"]
"""


def test_a_scene_with_a_load_at_the_bob_moves_as_with_its_generalised_force_and_settles_at_atan():
    by_load = chetaev.Scene.parse(PUSHED_PENDULUM.format(forces="", loads=PUSH)).solve()
    by_hand = chetaev.Scene.parse(
        PUSHED_PENDULUM.format(forces='forces = ["F*l*cos(theta)"]', loads="")
    ).solve()
    assert by_load.status == "success" and len(by_load) == len(by_hand) > 20
    np.testing.assert_allclose(by_load.q, by_hand.q, rtol=0, atol=1e-14)
    np.testing.assert_allclose(by_load.qd, by_hand.qd, rtol=0, atol=1e-14)
    # damped at c/(2 m l^2) = 0.5 per second: at t = 80 the swing has decayed by e^-40
    assert by_load.q[-1, 0] == pytest.approx(np.arctan(4.0 / (1.5 * 9.81)), abs=1e-9)


def test_a_scenes_warnings_name_their_place_and_are_empty_without_any(scene_text):
    assert chetaev.Scene.parse(scene_text).warnings == []
    text = PUSHED_PENDULUM.format(forces='forces = ["e*F*l*cos(theta)"]', loads="")
    warnings = chetaev.Scene.parse(text, "euler.toml").warnings
    line = text.splitlines().index('forces = ["e*F*l*cos(theta)"]') + 1
    assert len(warnings) == 1
    assert warnings[0].startswith(f"euler.toml:{line}:12: ")
    assert "Euler's number" in warnings[0]
