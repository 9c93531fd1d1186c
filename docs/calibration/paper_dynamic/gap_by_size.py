#!/usr/bin/env python3
"""The gap between the paper's dynamic curves (measured.toml) and dustdem's runs of the same
set-up at each stored sample size, read as `dustdem calibrate` reads a baseline: the mean over
seeds of the filling factor at first passage of each measured pressure, against
noise = sqrt(measured sigma^2 + seed variance / seeds); chi2 per curve = the mean of
(gap / noise)^2 over its points (one degree of freedom per curve). Beside it, the Eq. 13 fit
(phi1, phi2 held) of the seed-mean curve: p_m and Delta, the numbers the paper compares.

Runs: sizes/cases/ (2000 to 16 000 monomers, sweep.toml; the rough-top variant,
sweep_rough_top.toml) and the paper tier's 40 000-monomer runs, which also give 15 and
20 m/s, speeds the calibration does not fit. Prints Markdown tables. Run from the repository
root; standard library only.
"""
import glob
import math
import statistics
import sys

sys.path.insert(0, "docs/calibration/paper_dynamic")
import measured as m  # noqa: E402

SIZES = "docs/calibration/paper_dynamic/sizes/cases"


def runs_of(v, monomers, variant="modified"):
    if monomers == 40000 and variant == "modified":
        pattern = f"{m.CASES}/v{v}_seed*_modified_n40000.curve.csv"
    else:
        pattern = f"{SIZES}/v{v}_seed*_{variant}_n{monomers}/curve.csv"
    return sorted(glob.glob(pattern))


def gap(v, runs, scatter_only=False):
    m.SCATTER_ONLY = scatter_only
    lo, hi, _, sigma, _ = m.curve(v)
    envs = [m.envelope(r) for r in runs]
    terms, sq_gap = [], []
    for p, s in zip(m.log_spaced(lo, hi, m.POINTS), sigma):
        phis = [m.phi_at(phi, env, p) for phi, env in envs]
        d = statistics.mean(phis) - m.eq13(p, m.p_m_pa(v), m.delta(v))
        terms.append(d * d / (s**2 + statistics.variance(phis) / len(phis)))
        sq_gap.append(d * d)
    return math.sqrt(statistics.mean(sq_gap)), statistics.mean(terms)


def table(cases):
    print("| monomers | set-up | wall speed | seeds | RMS gap | chi2 | chi2 (scatter only) "
          "| p_m [kPa] (paper) | Delta (paper) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for monomers, variant, speeds in cases:
        total = 0.0
        for v in speeds:
            runs = runs_of(v, monomers, variant)
            if len(runs) < 2:
                continue
            rms, chi2 = gap(v, runs)
            _, chi2_s = gap(v, runs, True)
            _, p_m, d = m.eq13_residual(runs)
            total += chi2 if v in m.SPEEDS else 0.0
            print(f"| {monomers} | {variant} | {v:g} m/s | {len(runs)} | {rms:.4f} | {chi2:.2f} "
                  f"| {chi2_s:.0f} | {p_m / 1e3:.3g} ({m.p_m_pa(v) / 1e3:.3g}) "
                  f"| {d:.3f} ({m.delta(v):.3f}) |")
        print(f"| {monomers} | {variant} | fitted speeds | | | **{total:.2f}** | | | |")


def main():
    fitted = m.SPEEDS
    table([(n, "modified", fitted) for n in (2000, 4000, 8000, 16000)]
          + [(8000, "modified_rough_top", fitted), (40000, "modified", fitted + [15.0, 20.0])])


if __name__ == "__main__":
    main()
