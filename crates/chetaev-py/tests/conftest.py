"""Shared fixtures of the chetaev test suite.

The sympy models are built once per session (their derivation is the slow part of the suite); the
chetaev models made from them are immutable (``frozen`` pyclasses), so sharing them is safe.
"""

from __future__ import annotations

import os
import sys

import pytest

sys.path.insert(0, os.path.dirname(__file__))  # `models` lives beside the tests

import chetaev  # noqa: E402
import models  # noqa: E402


@pytest.fixture(scope="session")
def particle_sympy():
    """The paper's particle: L = m/2 |q'|^2 - m g y, f = |q'|^2 - v0^2 (m, g, v0 = 1, 10, 10)."""
    return models.particle()


@pytest.fixture(scope="session")
def particle_model(particle_sympy):
    p = particle_sympy
    return chetaev.Model.from_sympy(p["L"], p["q"], constraints=p["constraints"],
                                    parameters=p["parameters"])


@pytest.fixture(scope="session")
def particle_problem(particle_model, particle_sympy):
    return chetaev.Problem(particle_model, q0=particle_sympy["q0"], qd0=particle_sympy["qd0"])


@pytest.fixture(scope="session")
def impact(particle_sympy):
    """The impact y = 0, crossed from above, ending the run."""
    y = particle_sympy["q"][1]
    return chetaev.Event("impact", y, direction="falling", terminal=True)


@pytest.fixture(scope="session")
def disc_sympy():
    return models.rolling_disc()
