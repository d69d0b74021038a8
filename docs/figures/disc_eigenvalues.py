#!/usr/bin/env python3
"""The rolling disc's upright rolling: chetaev's eigenvalues against forward speed and the
closed form.

Draws docs/figures/disc-eigenvalues.png. The disc is models.rolling_disc() of
crates/chetaev-py/tests/models.py (thin and uniform, m = 1 kg, r = 0.5 m, g = 9.81 m/s²;
q = [q1 yaw, q2 lean, q3 spin, x, y], two rolling constraints). Rolling upright along N.x at
speed v (spin q3' = v / r), its lean mode has, linearised (docs/linearization.md),

    λ² = (m g r − (J + m r²) J ω² / I) / (I + m r²) = 4 (g r − 3 v²) / (5 r²),

with I = m r²/4, J = m r²/2 and ω = v / r: two real roots ±λ below the critical speed
v_c = sqrt(g r / 3) (the disc falls over), a pair ±i|λ| above it (it wobbles and stays up), and
the other six eigenvalues zero. The script prints chetaev's eigenvalues against that, and v_c as
found by brentq on the sign of λ² of chetaev's eigenvalue of largest modulus.

Usage, from the repository root, with the chetaev package installed:
  python3 docs/figures/disc_eigenvalues.py            # writes docs/figures/disc-eigenvalues.png
  python3 docs/figures/disc_eigenvalues.py OUT.png
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from scipy.optimize import brentq  # noqa: E402

import chetaev  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "crates" / "chetaev-py" / "tests"))
import models  # noqa: E402

R = models.DISC_PARAMETERS["r"]
G = models.DISC_PARAMETERS["g"]


def closed_form(v: float) -> complex:
    """The lean mode's eigenvalue with non-negative real and imaginary part."""
    return complex(np.sqrt(complex(4.0 * (G * R - 3.0 * v * v) / (5.0 * R * R))))


def main() -> None:
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).with_name("disc-eigenvalues.png")
    disc = models.rolling_disc()
    model = chetaev.Model.from_sympy(disc["L"], disc["q"], constraints=disc["constraints"],
                                     parameters=disc["parameters"])

    def linearize(v: float) -> chetaev.Linearization:
        # Upright, heading along N.x, spinning at v / r; the constraints give x' = v, y' = 0.
        return chetaev.Problem(model, [0.0] * 5, [0.0, 0.0, v / R, v, 0.0]).linearize()

    v_c = math.sqrt(G * R / 3.0)
    print(f"closed form: v_c = sqrt(g r / 3) = {v_c:.15f} m/s")
    lin = linearize(1.0)
    print(f"v = 1 m/s: states {lin.states}, cyclic {lin.cyclic}")

    def lean_squared(v: float) -> float:
        values = linearize(v).eigenvalues
        return float((values[np.argmax(np.abs(values))] ** 2).real)

    found = brentq(lean_squared, 1.0, 1.5, xtol=1e-14)
    print(f"brentq on λ² of chetaev's largest eigenvalue: v_c = {found:.15f} m/s "
          f"(relative difference {found / v_c - 1:.1e})")

    speeds = np.linspace(0.0, 3.0, 601)
    worst, zeros, numpy_zeros = 0.0, 0.0, 0.0
    chetaev_values = []
    for v in speeds:
        lin = linearize(v)
        values = lin.eigenvalues
        chetaev_values.append(values)
        order = np.argsort(np.abs(values))
        lean, small = values[order[6:]], values[order[:6]]
        if abs(v - v_c) > 0.01:
            exact = closed_form(v)
            for value in lean:
                worst = max(worst, min(abs(value - exact), abs(value + exact)) / abs(exact))
            zeros = max(zeros, float(np.abs(small).max()))
            numpy_values = np.linalg.eigvals(lin.a)
            numpy_zeros = max(numpy_zeros, float(np.sort(np.abs(numpy_values))[:6].max()))
    print(f"v = 0 to 3 m/s in steps of 0.005, |v − v_c| > 0.01: the lean pair against the closed "
          f"form, largest relative difference {worst:.1e}; the six zero eigenvalues at most "
          f"{zeros:.1e} in modulus (numpy.linalg.eigvals of the same lin.a: {numpy_zeros:.1e})")
    near = linearize(v_c).eigenvalues
    print(f"at v_c itself chetaev's eigenvalues are at most {np.abs(near).max():.1e} in modulus "
          f"(numpy.linalg.eigvals of lin.a: {np.abs(np.linalg.eigvals(linearize(v_c).a)).max():.1e}): "
          f"a zero eigenvalue of multiplicity eight there, defective")
    chetaev_values = np.array(chetaev_values)

    exact = np.array([closed_form(v) for v in speeds])
    fig, ax = plt.subplots(figsize=(8, 4.8), layout="constrained")
    ax.axvspan(v_c, speeds[-1], color="0.92", zorder=0)
    ax.axhline(0.0, color="0.5", lw=0.8, zorder=1)
    ax.plot(speeds, exact.real, color="C0", lw=1.6, label="closed form: Re λ = ±Re sqrt(4(g r − 3v²)/(5r²))")
    ax.plot(speeds, -exact.real, color="C0", lw=1.6)
    ax.plot(speeds, exact.imag, color="C1", lw=1.6, label="closed form: Im λ")
    ax.plot(speeds, -exact.imag, color="C1", lw=1.6)
    every = slice(0, None, 20)
    ax.plot(np.repeat(speeds[every], 8), chetaev_values[every].real.ravel(), "o", ms=4.5,
            mfc="none", mec="k", mew=0.9, label="chetaev: Re λ (all eight)")
    ax.plot(np.repeat(speeds[every], 8), chetaev_values[every].imag.ravel(), "x", ms=4.5,
            color="C3", mew=0.9, label="chetaev: Im λ (all eight)")
    ax.axvline(v_c, color="0.3", lw=1.0, ls="--")
    ax.annotate(f"v_c = sqrt(g r / 3)\n= {v_c:.4f} m/s", (v_c, 0.0), xytext=(v_c - 0.75, 6.0),
                arrowprops={"arrowstyle": "->", "color": "0.3"}, fontsize="small")
    ax.set_xlim(0.0, 3.0)
    ax.set_xlabel("rolling speed v = r q3' [m/s]")
    ax.set_ylabel("eigenvalue λ [1/s]")
    ax.set_title("Thin uniform disc rolling upright (m = 1 kg, r = 0.5 m): the lean mode\n"
                 "(shaded: stable in the linear sense, every Re λ = 0)", fontsize="medium")
    ax.legend(loc="lower left", fontsize="x-small", framealpha=0.95)
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
