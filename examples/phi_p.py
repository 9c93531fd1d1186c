#!/usr/bin/env python3
"""φ(P) of an omnidirectional compression, as in Fig. 8 of Seizinger et al. (2012), drawn
from Python: the simulated rows, their envelope (as the sweep analysis reads the curve), the
Eq. 13 fit to it and the measured law of Güttler et
al. (2009).

    python examples/phi_p.py                      # runs a 400-monomer compression (seconds)
    python examples/phi_p.py runs/omni_quick      # or draws an existing run
    python examples/phi_p.py --out figure.png

Needs the dustdem package (maturin develop -m python/Cargo.toml) and matplotlib.
"""

from __future__ import annotations

import argparse
import re
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import dustdem  # noqa: E402

#: A small version of configs/omni_quick.toml: 400 monomers, up to 1 MPa.
SMALL = {
    "sample": {"source": "rbd", "monomers": 400, "footprint": "box", "seed": 1},
    "experiment": {"kind": "omni", "wall_speed_m_s": 1.0, "pressure_stop_pa": 1e6},
    "output": {"snapshot_format": "none"},
}


def load(run_dir: str | None) -> dustdem.Run:
    """The run to draw: the one given, or a fresh small compression."""
    if run_dir:
        return dustdem.read_run(run_dir)
    out = Path(tempfile.mkdtemp(prefix="dustdem_phi_p_")) / "run"
    return dustdem.run(SMALL, out=out, backend="cpu")


def draw(run: dustdem.Run, png: Path) -> dustdem.Eq13Fit | None:
    """Writes the φ(P) figure to `png`; returns the Eq. 13 fit (None if it failed)."""
    p, phi = run.pressure, run.phi
    keep = np.isfinite(p) & (p > 0)
    env_phi, env_p = run.envelope()
    fig, ax = plt.subplots(figsize=(6.4, 4.4), dpi=120)
    ax.semilogx(p[keep], phi[keep], ".", ms=2, color="0.75", label="simulation (rows)")
    ax.semilogx(env_p, env_phi, "-", color="C1", lw=1.5, label="simulation (envelope)")
    grid = np.logspace(1, 7, 200)
    ax.semilogx(grid, dustdem.eq13(grid, *dustdem.GUETTLER_2009_OMNI), "k--",
                label="Güttler et al. (2009), Eq. 13")
    try:
        fit = dustdem.fit_eq13(env_phi, env_p, p_min=10.0)
    except ValueError as e:
        print(f"no Eq. 13 fit: {e}")
        fit = None
    if fit is not None:
        lo, hi = max(env_p.min(), 10.0), env_p.max()
        span = np.logspace(np.log10(lo), np.log10(hi), 200)
        ax.semilogx(span, fit(span), "C0-", lw=2,
                    label=f"Eq. 13 fit: φ₂ = {fit.phi2:.2f}, p_m = {fit.p_m:.3g} Pa, "
                          f"Δ = {fit.delta:.2f}")
    ax.set_xlabel("pressure P [Pa]")
    ax.set_ylabel("filling factor φ")
    n = re.search(r"^monomers = (\d+)", run.config, re.MULTILINE)
    ax.set_title("omnidirectional compression" + (f", {n.group(1)} monomers" if n else ""))
    ax.set_xlim(10, 1e7)
    ax.legend(loc="upper left", fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png)
    plt.close(fig)
    return fit


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", nargs="?", help="a run directory (default: run a small one)")
    parser.add_argument("--out", default="docs/figures/python_phi_p.png", type=Path)
    args = parser.parse_args()
    run = load(args.run)
    fit = draw(run, args.out)
    if fit is not None:
        print(f"Eq. 13 fit to the envelope ({fit.points} rows): phi1 {fit.phi1:.4f}, phi2 {fit.phi2:.4f}, "
              f"p_m {fit.p_m:.4g} Pa, Delta {fit.delta:.4f}")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
