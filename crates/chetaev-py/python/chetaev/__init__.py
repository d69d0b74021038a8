"""chetaev: mechanics under nonholonomic constraints, including constraints nonlinear in the
velocities, with the equations derived and solved in Rust.

A model is a Lagrangian ``L(t, q, q̇)`` with velocity constraints ``f(t, q, q̇) = 0``, holonomic
constraints ``h(t, q) = 0``, generalised forces ``Q`` and a Rayleigh function ``D``, written in
sympy (``from_sympy``) or as a scene file (``Scene``). chetaev derives every derivative by automatic
differentiation and solves Chetaev's equations in Newton form,

    d/dt ∂L/∂q̇ − ∂L/∂q = Σ_a μ_a ∂f_a/∂q̇ + Q,    f(t, q, q̇) = 0,

with the multipliers ``μ`` eliminated by a block solve. ``Φ = Σ_a μ_a ∂f_a/∂q̇`` is the Chetaev
force; the energy ``E = q̇·∂L/∂q̇ − L`` obeys ``dE/dt = q̇·Φ + q̇·Q − ∂L/∂t``.

>>> import sympy as sp, chetaev
>>> from sympy.physics.mechanics import dynamicsymbols
>>> x, y = dynamicsymbols("x y"); g, v0 = sp.symbols("g v0")
>>> L = (x.diff()**2 + y.diff()**2) / 2 - g * y
>>> f = x.diff()**2 + y.diff()**2 - v0**2
>>> model = chetaev.Model.from_sympy(L, [x, y], constraints=[f], parameters={g: 10.0, v0: 10.0})
>>> problem = chetaev.Problem(model, q0=[0.0, 5.0], qd0=[10.0, 0.0])
>>> impact = chetaev.Event("impact", y, direction="falling", terminal=True)
>>> sol = chetaev.solve(problem, 10.0, rtol=1e-12, atol=1e-12, events=[impact])
>>> round(sol.events[0].t, 10)   # T = (v0/g) arccosh(exp(g h0/v0²))
1.0850385019
"""

from ._chetaev import (
    ChetaevError,
    Description,
    Event,
    EventHit,
    Linearization,
    Model,
    Problem,
    Scene,
    SceneError,
    Seed,
    Solution,
    SweepTable,
    __version__,
    complete,
    merge_sweeps,
    methods,
    solve,
)
from ._sympy import ConversionError, from_sympy

__all__ = [
    "ChetaevError",
    "ConversionError",
    "Description",
    "Event",
    "EventHit",
    "Linearization",
    "Model",
    "Problem",
    "Scene",
    "SceneError",
    "Seed",
    "Solution",
    "SweepTable",
    "__version__",
    "complete",
    "from_sympy",
    "merge_sweeps",
    "methods",
    "solve",
]
