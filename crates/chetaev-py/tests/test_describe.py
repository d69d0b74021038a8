"""problem.describe(): what the library derived, as text and LaTeX, with the numbers at a state."""

from __future__ import annotations

import re

import pytest

import sympy as sp
import sympy.physics.mechanics as me

import chetaev
from models import particle_closed_form


@pytest.fixture(scope="module")
def description(particle_problem):
    return particle_problem.describe()


def test_the_description_names_the_blocks_of_the_chetaev_equations(description):
    text = str(description)
    assert "W = ∂²L/∂q̇²" in text and "J = ∂f/∂q̇" in text
    assert text.startswith("coordinates q = (x, y)")
    assert repr(description) == text
    assert isinstance(description, chetaev.Description)


def test_the_description_proves_the_particles_structure(description):
    text = str(description)
    # W = m I is constant; J = 2 q' depends on the velocities only
    assert re.search(r"W = ∂²L/∂q̇²\s+constant", text)
    assert re.search(r"J = ∂f/∂q̇\s+depends on q̇", text)


def test_the_description_has_latex_and_renders_in_jupyter_as_display_math(description):
    assert description.latex.strip()
    assert "\\begin{align*}" in description.latex
    rendered = description._repr_latex_()
    assert rendered.startswith("$$")
    assert "\\begin{aligned}" in rendered and "align*" not in rendered
    assert "q = (x, y)" in rendered


def test_the_description_at_a_state_gives_the_closed_form_multiplier(particle_problem):
    t = 0.4
    q, qd, mu = particle_closed_form(t)
    text = str(particle_problem.describe(t, list(q), list(qd)))
    printed = re.search(r"μ\s+=\s+\[([^\]]+)\]", text)
    assert printed, text
    # printed with 7 significant digits: half a unit of the 7th
    assert float(printed.group(1)) == pytest.approx(mu[0], rel=5e-7)


def test_the_description_of_a_state_off_the_model_is_refused(particle_problem):
    with pytest.raises(chetaev.ChetaevError):
        particle_problem.describe(0.0, [0.0, 5.0, 1.0], [10.0, 0.0, 0.0])


def test_the_latex_writes_the_coordinates_by_their_sympy_names():
    x, th = me.dynamicsymbols("x theta")
    g, v0 = sp.symbols("g v0")
    L = (x.diff() ** 2 + th.diff() ** 2) / 2 - g * x
    f = x.diff() ** 2 + th.diff() ** 2 - v0**2
    model = chetaev.Model.from_sympy(L, [x, th], constraints=[f], parameters={g: 10, v0: 10})
    d = chetaev.Problem(model, q0=[0, 5], qd0=[10, 0]).describe()
    assert r"\dot{\theta}" in d.latex and r"\dot{x}" in d.latex
    assert "q_{" not in d.latex
    assert d._repr_latex_().startswith(r"$$q = (x, \theta)$$")
