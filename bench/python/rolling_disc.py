#!/usr/bin/env python3
"""The rolling disc from Python: sympy + scipy against chetaev, timed in one process.

Model: the rolling disc of sympy's tests (sympy/physics/mechanics/tests/test_kane.py,
test_lagrange.py): yaw q1, lean q2, spin q3 (3-1-2 rotations), with the contact point's ground
position x, y as coordinates, q = [q1, q2, q3, x, y]; m = 1, r = 0.5, g = 9.81; the Lagrangian
from me.Lagrangian(N, disc) with V = m g r cos(q2); rolling without slip as two constraints
linear in the velocities, x' - r cos(q1) q3' = 0, y' - r sin(q1) q3' = 0.

Both routes start from the same sympy expressions (L, q, constraints), built once beforehand:

  A  sympy + scipy: LagrangesMethod(L, q, nonhol_coneqs=constraints).form_lagranges_equations(),
     lambdify (cse=True) of the lower block of mass_matrix_full and forcing_full, then
     scipy.integrate.solve_ivp(method="DOP853") with a numpy.linalg.solve per right-hand side.
  B  chetaev: chetaev.Model.from_sympy(...) (conversion), chetaev.Problem(...),
     chetaev.solve(problem, method="dop853", ...).

The rounds run A, B, A, B, ... in this one process, after one untimed warm-up of each; sympy's
cache is cleared before every timed run of either route (--keep-sympy-cache: not), so A's
derivation is cold each time. Reported: medians (min and max beside them) per phase and in total,
the ratio A / B of the total medians, and each route's error at t_end against a reference: A's
equations integrated by solve_ivp DOP853 at rtol = atol = --ref-tol (1e-13); with chetaev, also
chetaev at --ref-tol, and how far the two references are apart.

Usage:
  python3 bench/python/rolling_disc.py --rounds 7 --tol 1e-10
  python3 bench/python/rolling_disc.py --only-sympy          # without the chetaev package
"""

from __future__ import annotations

import argparse
import platform
import statistics
import subprocess
import sys
import time
from typing import Any, Callable

from pathlib import Path
import numpy as np
import scipy
import sympy as sp
import sympy.physics.mechanics as me
from scipy.integrate import solve_ivp
from sympy.core.cache import clear_cache

from machine import machine



# ---------------------------------------------------------------------------------------------
# The model: the rolling disc of the package's tests (crates/chetaev-py/tests/models.py)
# ---------------------------------------------------------------------------------------------

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "crates" / "chetaev-py" / "tests"))
import models  # noqa: E402


def build_disc() -> dict[str, Any]:
    """L, q, constraints, parameters, frame and the initial state of the rolling disc."""
    return models.rolling_disc()


# ---------------------------------------------------------------------------------------------
# Route A: sympy's LagrangesMethod + lambdify + scipy's solve_ivp
# ---------------------------------------------------------------------------------------------


def derive(model: dict[str, Any]) -> tuple[sp.Matrix, sp.Matrix]:
    """[[Md, -C^T], [C, 0]] [q''; mu] = [Fd; Fc] (the lower block of mass_matrix_full).

    With sympy's mass_matrix_full, Md q'' = Fd + C^T lam, so lam is the Newton-form mu."""
    n = len(model["q"])
    lm = me.LagrangesMethod(model["L"], model["q"], nonhol_coneqs=model["constraints"], frame=model["frame"])
    lm.form_lagranges_equations()
    return lm.mass_matrix_full[n:, n:], lm.forcing_full[n:, :]


def lambdify_equations(model: dict[str, Any], mass: sp.Matrix, forcing: sp.Matrix) -> Callable:
    """A right-hand side (q, q') -> (q'', mu) with the parameters substituted."""
    n = len(model["q"])
    qs = sp.symbols(f"q0:{n}")
    vs = sp.symbols(f"v0:{n}")
    sub = {**dict(zip(model["qd"], vs)), **dict(zip(model["q"], qs))}
    params = list(model["parameters"])
    fm = sp.lambdify((qs, vs, params), mass.subs(sub), modules="numpy", cse=True)
    ff = sp.lambdify((qs, vs, params), forcing.subs(sub), modules="numpy", cse=True)
    pv = [model["parameters"][p] for p in params]

    def accelerations(q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        return np.linalg.solve(np.asarray(fm(q, qd, pv), dtype=float), np.asarray(ff(q, qd, pv), dtype=float).ravel())

    return accelerations


def integrate(accelerations: Callable, model: dict[str, Any], t_end: float, tol: float) -> dict[str, Any]:
    n = len(model["q"])

    def rhs(_t: float, s: np.ndarray) -> np.ndarray:
        return np.concatenate((s[n:], accelerations(s[:n], s[n:])[:n]))

    res = solve_ivp(rhs, (0.0, t_end), np.array(model["q0"] + model["qd0"], dtype=float),
                    method="DOP853", rtol=tol, atol=tol)
    if not res.success:
        raise RuntimeError(f"solve_ivp: {res.message}")
    y = res.y[:, -1]
    return {"t": float(res.t[-1]), "q": y[:n], "qd": y[n:], "mu": accelerations(y[:n], y[n:])[n:],
            "steps": len(res.t) - 1, "nfev": int(res.nfev)}


def route_sympy(model: dict[str, Any], t_end: float, tol: float) -> tuple[dict[str, float], dict[str, Any]]:
    """Route A, timed by phase."""
    t0 = time.perf_counter()
    mass, forcing = derive(model)
    t1 = time.perf_counter()
    acc = lambdify_equations(model, mass, forcing)
    t2 = time.perf_counter()
    out = integrate(acc, model, t_end, tol)
    t3 = time.perf_counter()
    return {"derive": t1 - t0, "lambdify": t2 - t1, "solve": t3 - t2, "total": t3 - t0}, out


# ---------------------------------------------------------------------------------------------
# Route B: chetaev
# ---------------------------------------------------------------------------------------------


def route_chetaev(chetaev: Any, model: dict[str, Any], t_end: float, tol: float) -> tuple[dict[str, float], dict[str, Any]]:
    """Route B, timed by phase: conversion (from_sympy + Problem) and solve."""
    t0 = time.perf_counter()
    cm = chetaev.Model.from_sympy(model["L"], q=model["q"], constraints=model["constraints"], holonomic=[],
                                  forces=None, loads=None, frame=None, rayleigh=None,
                                  parameters=model["parameters"])
    problem = chetaev.Problem(cm, q0=model["q0"], qd0=model["qd0"], t0=0.0)
    t1 = time.perf_counter()
    sol = chetaev.solve(problem, t_end=t_end, method="dop853", rtol=tol, atol=tol)
    t2 = time.perf_counter()
    if not sol.success:
        raise RuntimeError(f"chetaev.solve: status {sol.status}")
    out = {"t": float(np.asarray(sol.t)[-1]), "q": np.asarray(sol.q)[-1], "qd": np.asarray(sol.qd)[-1],
           "mu": np.asarray(sol.mu)[-1], "stats": dict(sol.stats)}
    return {"convert": t1 - t0, "solve": t2 - t1, "total": t2 - t0}, out


def import_chetaev() -> tuple[Any, str | None]:
    """The chetaev module, or None and why not."""
    try:
        import chetaev  # noqa: PLC0415
    except ImportError as e:
        return None, f"cannot import chetaev ({e})"
    missing = [name for name in ("Model", "Problem", "solve") if not hasattr(chetaev, name)]
    if not missing and not hasattr(chetaev.Model, "from_sympy"):
        missing = ["Model.from_sympy"]
    if missing:
        return None, f"chetaev ({getattr(chetaev, '__file__', '?')}) has no {', '.join(missing)}"
    return chetaev, None


# ---------------------------------------------------------------------------------------------
# Reporting
# ---------------------------------------------------------------------------------------------




def uptime() -> str:
    try:
        return subprocess.run(["uptime"], capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "?"


def fmt(s: float) -> str:
    return f"{s * 1e3:9.2f} ms" if s < 10 else f"{s:9.3f} s "


def summary(name: str, runs: list[dict[str, float]]) -> None:
    for phase in runs[0]:
        xs = [r[phase] for r in runs]
        print(f"  {name:<9} {phase:<9} median {fmt(statistics.median(xs))}   "
              f"(min {fmt(min(xs)).strip()}, max {fmt(max(xs)).strip()})")


def errors(out: dict[str, Any], ref: dict[str, Any]) -> str:
    dq = np.abs(out["q"] - ref["q"]).max()
    dqd = np.abs(out["qd"] - ref["qd"]).max()
    dmu = np.abs(out["mu"] - ref["mu"]).max()
    return f"max|dq| {dq:.2e}   max|dq'| {dqd:.2e}   max|dmu| {dmu:.2e}   (t_final {out['t']!r})"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=5, help="timed rounds, each A then B (default 5)")
    ap.add_argument("--tol", type=float, default=1e-10, help="rtol = atol of both routes (default 1e-10)")
    ap.add_argument("--t-end", type=float, default=5.0, help="end time (default 5)")
    ap.add_argument("--ref-tol", type=float, default=1e-13, help="rtol = atol of the references (default 1e-13)")
    ap.add_argument("--only-sympy", action="store_true", help="route A alone (no chetaev needed)")
    ap.add_argument("--keep-sympy-cache", action="store_true", help="do not clear sympy's cache before each run")
    a = ap.parse_args()
    if a.rounds < 1:
        ap.error("--rounds must be at least 1")

    chetaev = None
    if not a.only_sympy:
        chetaev, why = import_chetaev()
        if chetaev is None:
            print(f"rolling_disc.py: {why}.\nInstall the Python package built from crates/chetaev-py into this "
                  "environment, or run the sympy + scipy side alone with --only-sympy.", file=sys.stderr)
            return 2

    print(f"machine: {machine()}")
    print(f"load before: {uptime()}")
    versions = (f"python {platform.python_version()}, sympy {sp.__version__}, scipy {scipy.__version__}, "
                f"numpy {np.__version__}")
    if chetaev is not None:
        versions += f", chetaev {getattr(chetaev, '__version__', '?')}"
    print(versions)
    print(f"rolling disc, q = [q1, q2, q3, x, y], t_end = {a.t_end}, DOP853, rtol = atol = {a.tol:g}, "
          f"{a.rounds} rounds (A = sympy + scipy, B = chetaev), sympy cache "
          f"{'kept' if a.keep_sympy_cache else 'cleared before each run'}")

    t0 = time.perf_counter()
    model = build_disc()
    print(f"building L and the constraints (common to both, not in the times): {fmt(time.perf_counter() - t0).strip()}")

    # References (A's equations, derived once, at --ref-tol; chetaev at --ref-tol too).
    acc = lambdify_equations(model, *derive(model))
    ref = integrate(acc, model, a.t_end, a.ref_tol)
    print(f"reference: solve_ivp DOP853 at rtol = atol = {a.ref_tol:g}: {ref['steps']} steps, {ref['nfev']} evaluations")
    ref_c = None
    if chetaev is not None:
        _, ref_c = route_chetaev(chetaev, model, a.t_end, a.ref_tol)
        print(f"  chetaev at {a.ref_tol:g} against it: {errors(ref_c, ref)}")

    def run_a() -> tuple[dict[str, float], dict[str, Any]]:
        if not a.keep_sympy_cache:
            clear_cache()
        return route_sympy(model, a.t_end, a.tol)

    def run_b() -> tuple[dict[str, float], dict[str, Any]]:
        if not a.keep_sympy_cache:
            clear_cache()
        return route_chetaev(chetaev, model, a.t_end, a.tol)

    run_a()  # warm-up, untimed
    if chetaev is not None:
        run_b()
    times_a: list[dict[str, float]] = []
    times_b: list[dict[str, float]] = []
    out_a: dict[str, Any] = {}
    out_b: dict[str, Any] = {}
    for i in range(a.rounds):
        ta, out_a = run_a()
        times_a.append(ta)
        line = f"round {i + 1}: A {fmt(ta['total']).strip()}"
        if chetaev is not None:
            tb, out_b = run_b()
            times_b.append(tb)
            line += f", B {fmt(tb['total']).strip()}"
        print(line)

    print("\ntimes (median over the rounds):")
    summary("A sympy", times_a)
    if chetaev is not None:
        summary("B chetaev", times_b)
        ma = statistics.median(r["total"] for r in times_a)
        mb = statistics.median(r["total"] for r in times_b)
        print(f"  ratio A / B of the total medians: {ma / mb:.2f}")
        ratios = [x["total"] / y["total"] for x, y in zip(times_a, times_b)]
        print(f"  per round A / B: median {statistics.median(ratios):.2f} (min {min(ratios):.2f}, max {max(ratios):.2f})")

    print(f"\nerrors at t_end = {a.t_end} (last round) against solve_ivp at {a.ref_tol:g}:")
    print(f"  A sympy   ({out_a['steps']} steps, {out_a['nfev']} evaluations): {errors(out_a, ref)}")
    if chetaev is not None:
        print(f"  B chetaev (stats {out_b['stats']}): {errors(out_b, ref)}")
        print(f"against chetaev at {a.ref_tol:g}:")
        print(f"  A sympy   : {errors(out_a, ref_c)}")
        print(f"  B chetaev : {errors(out_b, ref_c)}")
    print(f"\nload after: {uptime()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
