#!/usr/bin/env python3
"""scipy's LSODA on the stiff uniform projectile, the counterpart of chetaev's Rodas4 (rust/).

The paper's particle in gravity held at constant speed by the constraint xdot^2 + ydot^2 = v0^2,
with v0 = 1e-3, g = 9.81, h0 = 1, m = 1, from (x, y) = (0, h0), (xdot, ydot) = (v0, 0). Its reduced
equation in Newton form, state s = (x, y, xdot, ydot):

    qddot = g_vec - (g_vec . qdot / |qdot|^2) qdot,   g_vec = (0, -g).

Variants (--variants):
  lsoda      solve_ivp(method="LSODA"), hand-written right-hand side, Jacobian by LSODA's own
             finite differences;
  lsoda_jac  the same with the hand-written Jacobian (jac=...);
  odeint     scipy.integrate.odeint (the same ODEPACK LSODA, the whole integration in one call
             instead of solve_ivp's one call per step), with the hand-written Jacobian; a reference
             only, for the share of solve_ivp's Python overhead.

Every variant integrates from t = 0 to the fixed end time --t-end (default 999.9 s, a little before
the impact T = 1000.000071 s, where the closed form is well conditioned; no event), at
rtol = atol = tol. Error: each component of s(t_end) minus the closed form (42.29)-(42.30) divided
by its scale (x: v0^2/g = 1.019e-7 m, y: h0 = 1 m, velocities: v0 = 1e-3 m/s), largest magnitude;
the unscaled largest magnitude is printed too (abs_error). Time: time.perf_counter around one
solve, median of --runs solves after one untimed solve (which gives the error and the counters).

Prints CSV: solver,tol,error,abs_error,median_s,runs,batch,rhs,jac,steps,rejected
(rejected is not reported by scipy: empty).
"""

import argparse
import math
import statistics
import sys
import time

import numpy as np
import scipy
from scipy.integrate import odeint, solve_ivp

V0 = 1e-3
G = 9.81
H0 = 1.0
M = 1.0
L = V0 * V0 / G  # the length scale v0^2/g
SCALES = (L, H0, V0, V0)
T_IMPACT = (V0 / G) * (G * H0 / V0**2 + math.log1p(math.sqrt(-math.expm1(-2.0 * G * H0 / V0**2))))


def rhs(t, s):
    """qddot = g_vec - (g_vec . qdot / |qdot|^2) qdot, written out: k = g ydot / |qdot|^2."""
    vx = s[2]
    vy = s[3]
    k = G * vy / (vx * vx + vy * vy)
    return np.array([vx, vy, k * vx, k * vy - G])


def jac(t, s):
    """d rhs / d s. With r = |qdot|^2 and k = g ydot / r, the accelerations are (k xdot, k ydot - g)."""
    vx = s[2]
    vy = s[3]
    r = vx * vx + vy * vy
    k = G * vy / r
    dk_dvx = -2.0 * G * vy * vx / (r * r)
    dk_dvy = G / r - 2.0 * G * vy * vy / (r * r)
    return np.array(
        [
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
            [0.0, 0.0, k + vx * dk_dvx, vx * dk_dvy],
            [0.0, 0.0, vy * dk_dvx, k + vy * dk_dvy],
        ]
    )


def closed_form(t):
    """(42.29)-(42.30) in the forms of crates/uniform-projectile/src/closed_form.rs (t >= 0)."""
    u = G * t / V0
    x = L * 2.0 * math.atan(math.tanh(0.5 * u))  # L gd(u)
    if u < 1.0:
        y = H0 - L * math.log1p(2.0 * math.sinh(0.5 * u) ** 2)
    else:  # L ln cosh u = v0 t - L (ln 2 - ln1p(e^-2u))
        y = H0 + L * (math.log(2.0) - math.log1p(math.exp(-2.0 * u))) - V0 * t
    e = math.exp(-u)
    vx = V0 * 2.0 * e / (1.0 + e * e)  # v0 sech u
    vy = -V0 * math.tanh(u)
    return (x, y, vx, vy)


def errors(t_end, s):
    ref = closed_form(t_end)
    diff = [float(a) - b for a, b in zip(s, ref)]
    scaled = max(abs(d) / sc for d, sc in zip(diff, SCALES))
    plain = max(abs(d) for d in diff)
    return scaled, plain


Y0 = np.array([0.0, H0, V0, 0.0])


def solver(variant, t_end, tol):
    """A function doing one solve: returns (final state, rhs evaluations, jacobians, steps)."""
    if variant == "lsoda":

        def run():
            sol = solve_ivp(rhs, (0.0, t_end), Y0, method="LSODA", rtol=tol, atol=tol)
            if sol.status != 0:
                raise RuntimeError(sol.message)
            return sol.y[:, -1], sol.nfev, sol.njev, len(sol.t) - 1

    elif variant == "lsoda_jac":

        def run():
            sol = solve_ivp(rhs, (0.0, t_end), Y0, method="LSODA", jac=jac, rtol=tol, atol=tol)
            if sol.status != 0:
                raise RuntimeError(sol.message)
            return sol.y[:, -1], sol.nfev, sol.njev, len(sol.t) - 1

    elif variant == "odeint":

        def run():
            ys, info = odeint(
                rhs, Y0, [0.0, t_end], Dfun=jac, rtol=tol, atol=tol, tfirst=True,
                full_output=True, mxstep=10**6,
            )
            if info["message"] != "Integration successful.":
                raise RuntimeError(info["message"])
            return ys[-1], int(info["nfe"][-1]), int(info["nje"][-1]), int(info["nst"][-1])

    else:
        raise ValueError(f"unknown variant {variant}")
    return run


def check_jacobian():
    """The hand-written Jacobian against central differences of rhs at a few states."""
    worst = 0.0
    for s in ([0.0, 1.0, V0, 0.0], [1e-7, 0.5, 3e-4, -9.5e-4], [1.5e-7, 1e-3, 1e-9, -V0]):
        s = np.array(s)
        j = jac(0.0, s)
        for c in (2, 3):
            h = 1e-6 * V0
            sp, sm = s.copy(), s.copy()
            sp[c] += h
            sm[c] -= h
            fd = (rhs(0.0, sp) - rhs(0.0, sm)) / (2 * h)
            scale = max(np.max(np.abs(j[:, c])), 1.0)
            worst = max(worst, float(np.max(np.abs(fd - j[:, c]))) / scale)
    return worst


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--t-end", type=float, default=999.9)
    ap.add_argument("--runs", type=int, default=51, help="timed solves per tolerance and variant")
    ap.add_argument("--tols", default="1e-4,1e-5,1e-6,1e-7,1e-8,1e-9,1e-10")
    ap.add_argument("--variants", default="lsoda,lsoda_jac")
    ap.add_argument("--check", action="store_true", help="check the Jacobian and the closed form, then exit")
    a = ap.parse_args(argv)

    if a.check:
        print(f"python {sys.version.split()[0]}, numpy {np.__version__}, scipy {scipy.__version__}")
        print(f"jacobian vs central differences, worst relative difference: {check_jacobian():.2e}")
        print(f"impact time T = {T_IMPACT:.9f}")
        print("closed form at t_end:", ", ".join(f"{v:.17e}" for v in closed_form(a.t_end)))
        return 0

    tols = [float(t) for t in a.tols.split(",")]
    print("solver,tol,error,abs_error,median_s,runs,batch,rhs,jac,steps,rejected")
    for variant in a.variants.split(","):
        for tol in tols:
            run = solver(variant, a.t_end, tol)
            try:
                y, nfev, njev, steps = run()
            except RuntimeError as e:
                print(f"lsoda.py: {variant} tol {tol:g}: {e}", file=sys.stderr)
                continue
            err, abs_err = errors(a.t_end, y)
            times = []
            for _ in range(a.runs):
                t0 = time.perf_counter()
                run()
                times.append(time.perf_counter() - t0)
            print(
                f"{variant},{tol:e},{err:.6e},{abs_err:.6e},{statistics.median(times):.6e},"
                f"{a.runs},1,{nfev},{njev},{steps},",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
