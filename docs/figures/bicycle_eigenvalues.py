#!/usr/bin/env python3
"""The benchmark bicycle's eigenvalues against forward speed, from chetaev's linearisation.

Draws docs/figures/bicycle-eigenvalues.png: the real parts of the eigenvalues of upright straight
running, linearised by chetaev (problem.linearize) on the full nonlinear model
(models.whipple_bicycle of crates/chetaev-py/tests/models.py), for v from 0 to 10 m/s, with the
eigenvalues of Meijaard et al. (2007), Table 2 overlaid, and the weave pair's imaginary part. It
prints how far chetaev's eigenvalues are from the table and the weave and capsize speeds it finds
(brentq on the real part of the weave pair and on the capsize eigenvalue).

Usage, from the repository root, with the chetaev package installed:
  python3 docs/figures/bicycle_eigenvalues.py            # writes docs/figures/bicycle-eigenvalues.png
  python3 docs/figures/bicycle_eigenvalues.py OUT.png
"""

from __future__ import annotations

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

COORDINATES = ["x", "y", "psi", "phi", "theta_R", "delta", "theta_F"]  # all but the pitch
SPEEDS = ["phi_dot", "theta_R_dot", "delta_dot"]  # roll rate, rear-wheel rate, steer rate


def main() -> None:
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).with_name("bicycle-eigenvalues.png")
    bike = models.whipple_bicycle()
    model = chetaev.Model.from_sympy(bike["L"], bike["q"], constraints=bike["constraints"],
                                     holonomic=bike["holonomic"], parameters=bike["parameters"])

    def eigenvalues(v: float) -> tuple[np.ndarray, np.ndarray]:
        """The six eigenvalues of least modulus (zero in exact arithmetic) and the other four."""
        lin = chetaev.Problem(model, *bike["upright"](v)).linearize(coordinates=COORDINATES,
                                                                     speeds=SPEEDS)
        order = np.argsort(np.abs(lin.eigenvalues))
        return lin.eigenvalues[order[:6]], lin.eigenvalues[order[6:]]

    # Against the table.
    worst, worst_at, zeros = 0.0, None, 0.0
    for v, published in models.MEIJAARD_TABLE_2.items():
        small, lateral = eigenvalues(v)
        zeros = max(zeros, float(np.abs(small).max()))
        for value in published:
            error = float(np.abs(lateral - value).min() / abs(value))
            if error > worst:
                worst, worst_at = error, (v, value)
    print(f"Table 2, v = 0, 1, ..., 10 m/s: largest relative difference {worst:.1e} "
          f"(at v = {worst_at[0]:g} m/s, published {worst_at[1].real:.14f}); "
          f"the six other eigenvalues at most {zeros:.1e} in modulus")

    def weave(v: float) -> float:
        lateral = eigenvalues(v)[1]
        return float(lateral[np.abs(lateral.imag) > 0].real.max())

    def capsize(v: float) -> float:
        lateral = eigenvalues(v)[1]
        return float(lateral[lateral.imag == 0].real.max())

    v_weave = brentq(weave, 4.0, 5.0, xtol=1e-12)
    v_capsize = brentq(capsize, 5.5, 6.5, xtol=1e-12)
    print(f"weave speed   {v_weave:.14f} m/s, published {models.MEIJAARD_WEAVE_SPEED:.14f} "
          f"(difference {v_weave - models.MEIJAARD_WEAVE_SPEED:.1e})")
    print(f"capsize speed {v_capsize:.14f} m/s, published {models.MEIJAARD_CAPSIZE_SPEED:.14f} "
          f"(difference {v_capsize - models.MEIJAARD_CAPSIZE_SPEED:.1e})")

    # The curves: at each speed the four lateral eigenvalues, sorted into the modes. Below the
    # speed where the weave pair forms (0.684 m/s) all four are real: ascending, castor, capsize,
    # and the two that become the weave pair.
    speeds = np.linspace(0.0, 10.0, 1001)
    castor, capsize_mode, weave_re, weave_im, zero_re = [], [], [], [], []
    for v in speeds:
        small, lateral = eigenvalues(v)
        zero_re.append(small.real)
        complex_pair = lateral[np.abs(lateral.imag) > 0]
        real = np.sort(lateral[lateral.imag == 0].real)
        castor.append(real[0])
        capsize_mode.append(real[1])
        if len(complex_pair) == 2:
            weave_re.append([complex_pair.real.max()] * 2)
            weave_im.append(np.abs(complex_pair.imag).max())
        else:
            weave_re.append(real[2:])
            weave_im.append(np.nan)
    weave_re = np.array(weave_re)

    fig, ax = plt.subplots(figsize=(10, 5.6), layout="constrained")
    ax.axvspan(v_weave, v_capsize, color="0.92", zorder=0)
    ax.axhline(0.0, color="0.5", lw=0.8, zorder=1)
    ax.plot(speeds, weave_re[:, 0], color="C0", lw=1.8, label="weave, Re λ (chetaev)")
    ax.plot(speeds, weave_re[:, 1], color="C0", lw=1.8)
    ax.plot(speeds, weave_im, color="C0", lw=1.2, ls=":", label="weave, |Im λ| (chetaev)")
    ax.plot(speeds, capsize_mode, color="C1", lw=1.8, label="capsize, λ (chetaev)")
    ax.plot(speeds, castor, color="C2", lw=1.8, label="castor, λ (chetaev)")
    zero_re = np.array(zero_re)
    print(f"v = 0 to 10 m/s in steps of 0.01: the six zero eigenvalues' real parts at most "
          f"{np.abs(zero_re).max():.1e} in modulus")
    ax.plot(speeds, zero_re[:, 0], color="0.3", lw=1.0, ls="--",
            label="six zero eigenvalues (chetaev):\nx, y, ψ, θ_R, θ_F, rear-wheel rate")
    table_v = np.array(sorted(models.MEIJAARD_TABLE_2))
    table = np.array([models.MEIJAARD_TABLE_2[v] for v in table_v])
    ax.plot(np.repeat(table_v, 4), table.real.ravel(), "o", ms=6, mfc="none", mec="k", mew=1.1,
            label="Meijaard et al. (2007), Table 2: Re λ")
    imag = np.abs(table.imag).max(axis=1)
    ax.plot(table_v[imag > 0], imag[imag > 0], "s", ms=5, mfc="none", mec="k", mew=1.0,
            label="Table 2: weave |Im λ|")
    ax.annotate(f"weave speed\n{v_weave:.6f} m/s", (v_weave, 0.0), xytext=(v_weave - 2.9, 7.5),
                arrowprops={"arrowstyle": "->", "color": "0.3"}, fontsize="small")
    ax.annotate(f"capsize speed\n{v_capsize:.6f} m/s", (v_capsize, 0.0),
                xytext=(v_capsize + 0.6, -7.5), arrowprops={"arrowstyle": "->", "color": "0.3"},
                fontsize="small")
    ax.set_xlim(0.0, 10.0)
    ax.set_ylim(-26.0, 12.0)
    ax.set_xlabel("forward speed v [m/s]")
    ax.set_ylabel("eigenvalue λ [1/s]")
    ax.set_title("Benchmark bicycle, upright straight running: chetaev's linearisation of the "
                 "nonlinear model\n(shaded: self-stable, every Re λ < 0 but the zeros)",
                 fontsize="medium")
    ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), fontsize="small")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
