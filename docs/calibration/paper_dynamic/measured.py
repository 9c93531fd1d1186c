#!/usr/bin/env python3
"""Writes measured.toml: the dynamic compression curves of Seizinger et al. (2012) as measured
data for `dustdem calibrate`, each at its wall speed.

The curves are the paper's Eq. 13 with its fitted laws: p_m from Eq. 15 (1.340 v^1.93 + 0.307
kPa) and Delta from Eq. 17 ((v + 1.598)^-1.997 + 0.170), phi1 = 0.15 and phi2 = 0.58 held (the
paper does not refit them), sampled at the 12 log-spaced pressures dustdem samples an eq13 curve
at, between p_m 10^(-3 Delta) and p_m 10^(+3 Delta) (where the curve climbs from 5 % to 95 % of
its rise).

The 1-sigma per point has two parts, added in quadrature:
- the scatter of a mean of six 40 000-monomer runs (what the paper averaged): the sample standard
  deviation, over the stored 40 000-monomer seeds of the paper tier
  (docs/reproduction/paper/dynamic/cases, calibrated model), of the filling factor at which each
  run first held the pressure (its running-median envelope, as `dustdem calibrate` reads a run),
  divided by sqrt(6). It is 1e-4 to 1e-3 except where a point falls on a plateau (0.08);
- how far a mean dynamic curve lies from its own Eq. 13 fit: the RMS filling-factor residual of
  Eq. 13 (phi1, phi2 held; p_m and Delta fitted by least squares in phi) on the seed-mean
  40 000-monomer curve at the same speed (pressures averaged at fixed phi, as the paper's
  figures are). The paper gives its curves only as fits, so the data can be no closer to the
  paper's runs than a fit of this form is to a run (0.03 to 0.05 here; the plateau is the part
  Eq. 13 cannot follow).
With --scatter-only it writes measured_scatter_only.toml instead: the first part alone, floored
at 0.005 (below a plateau every seed starts at the same phi0), as if the paper's Eq. 13 curves
were its mean curves exactly; a sensitivity run, not a defended sigma.
Run from the repository root; standard library only (a few seconds).
"""
import csv
import glob
import math
import os
import statistics
import sys

SPEEDS = [2.5, 5.0, 10.0]
POINTS = 12  # src/calibrate/measured/file.rs EQ13_POINTS
MEDIAN_ROWS = 9  # src/analysis/envelope.rs
PHI1, PHI2 = 0.15, 0.58
CASES = "docs/reproduction/paper/dynamic/cases"
SCATTER_ONLY = "--scatter-only" in sys.argv[1:]
SCATTER_FLOOR = 0.005
OUT = "docs/calibration/paper_dynamic/measured%s.toml" % ("_scatter_only" if SCATTER_ONLY else "")


def p_m_pa(v):
    return 1e3 * (1.340 * v**1.93 + 0.307)


def delta(v):
    return (v + 1.598) ** -1.997 + 0.170


def log_spaced(lo, hi, n):
    a, b = math.log10(lo), math.log10(hi)
    return [10 ** (a + (b - a) * k / (n - 1)) for k in range(n)]


def data_lines(f):
    """A curve file's lines without its comment lines."""
    return (line for line in f if not line.startswith("#"))


def rows_of(path):
    out = []
    with open(path) as f:
        for r in csv.DictReader(data_lines(f)):
            p = float(r["p_top_pa"])
            if math.isfinite(p):
                out.append((float(r["phi"]), p))
    return out


def envelope(path):
    rows = [(phi, math.log10(p) if p > 0 else -10.0) for phi, p in rows_of(path)]
    half, running, env = MEDIAN_ROWS // 2, -math.inf, []
    for k in range(len(rows)):
        window = sorted(x for _, x in rows[max(0, k - half) : k + half + 1])
        running = max(running, window[len(window) // 2])
        env.append(running)
    return [phi for phi, _ in rows], env


def phi_at(phi, env, p):
    x = math.log10(p)
    for i, e in enumerate(env):
        if e >= x:
            if i == 0:
                return phi[0]
            t = (x - env[i - 1]) / (e - env[i - 1])
            return phi[i - 1] + t * (phi[i] - phi[i - 1])
    return math.nan


def pressure_at_phi(rows, phi):
    for i in range(1, len(rows)):
        if rows[i][0] >= phi:
            (f0, p0), (f1, p1) = rows[i - 1], rows[i]
            t = (phi - f0) / (f1 - f0) if f1 > f0 else 0.0
            return p0 + t * (p1 - p0)
    return math.nan


def eq13(p, p_m, d):
    return PHI2 - (PHI2 - PHI1) / (math.exp((math.log10(p) - math.log10(p_m)) / d) + 1)


def eq13_residual(runs):
    """RMS phi residual of the least-squares Eq. 13 fit to the seed-mean curve."""
    curves = [rows_of(r) for r in runs]
    top = min(max(phi for phi, _ in c) for c in curves)
    grid = [0.152 + 0.002 * k for k in range(int((top - 0.152) / 0.002))]
    mean = [(phi, statistics.mean(pressure_at_phi(c, phi) for c in curves)) for phi in grid]
    mean = [(phi, p) for phi, p in mean if p > 0]

    def sum_sq(log_p_m, d):
        return sum((phi - eq13(p, 10**log_p_m, d)) ** 2 for phi, p in mean)

    # Coarse grid, then two refinements around the best point.
    best = min((sum_sq(lp / 20, d / 100), lp / 20, d / 100) for lp in range(50, 130) for d in range(2, 60))
    for step in (0.01, 0.002):
        _, lp0, d0 = best
        cand = [(lp0 + i * step, d0 + j * step / 2) for i in range(-5, 6) for j in range(-5, 6)]
        best = min((sum_sq(lp, d), lp, d) for lp, d in cand if d > 0)
    return math.sqrt(best[0] / len(mean)), 10 ** best[1], best[2]


def curve(v):
    lo, hi = p_m_pa(v) * 10 ** (-3 * delta(v)), p_m_pa(v) * 10 ** (3 * delta(v))
    pressures = log_spaced(lo, hi, POINTS)
    runs = sorted(glob.glob(f"{CASES}/v{v}_seed*_modified_n40000.curve.csv"))
    envs = [envelope(r) for r in runs]
    residual, p_m_ours, d_ours = eq13_residual(runs)
    sigma = []
    for p in pressures:
        phis = [phi_at(phi, env, p) for phi, env in envs]
        if SCATTER_ONLY:
            sigma.append(max(math.sqrt(statistics.variance(phis) / 6), SCATTER_FLOOR))
        else:
            sigma.append(math.sqrt(statistics.variance(phis) / 6 + residual**2))
    return lo, hi, len(runs), sigma, (residual, p_m_ours, d_ours)


def main():
    out = [
        "# Written by docs/calibration/paper_dynamic/measured.py; do not edit.",
        "",
        "[source]",
        'citation = "Seizinger, Speith & Kley 2012, A&A 541, A59, Sect. 5.2: Eq. 13 with p_m '
        'from Eq. 15 and Delta from Eq. 17"',
        'what = "the paper\'s dynamic compression curves (calibrated model, about 40 000 '
        "monomers, six samples averaged) as its fitted laws give them, phi1 = 0.15 and "
        "phi2 = 0.58 held, sampled from p_m 10^(-3 Delta) to p_m 10^(3 Delta); not the raw "
        'curves"',
        ('notes = "1-sigma per point: the seed-to-seed standard deviation of the filling factor '
         "at first passage of each pressure over the stored 40 000-monomer runs of dustdem's "
         "paper tier (calibrated model) divided by sqrt(6), floored at 0.005: a sensitivity "
         'run, as if the Eq. 13 curves were the mean curves exactly"')
        if SCATTER_ONLY
        else ('notes = "1-sigma per point, in quadrature: the seed-to-seed standard deviation of the '
        "filling factor at first passage of each pressure over the stored 40 000-monomer runs "
        "of dustdem's paper tier (calibrated model) divided by sqrt(6), the scatter of a mean "
        "of six runs; and the RMS phi residual of an Eq. 13 fit to the seed-mean curve at that "
        'speed, how far a mean curve lies from a fit of the form the paper publishes"'),
    ]
    for v in SPEEDS:
        lo, hi, n, sigma, (residual, p_m_ours, d_ours) = curve(v)
        out += [
            "",
            f"# sigma: {n} stored 40 000-monomer seeds at {v} m/s, their mean's Eq. 13 fit "
            f"(p_m {p_m_ours / 1e3:.3g} kPa, Delta {d_ours:.3g}) off by {residual:.4f} RMS in phi",
            "[[compression]]",
            f'name = "Seizinger et al. 2012, {v:g} m/s"',
            'geometry = "omni"',
            f"wall_speed_m_s = {v}",
            f"eq13 = {{ phi1 = {PHI1}, phi2 = {PHI2}, p_m_pa = {p_m_pa(v):.6g}, "
            f"delta = {delta(v):.6g} }}",
            f"pressure_min_pa = {lo:.6g}",
            f"pressure_max_pa = {hi:.6g}",
            "phi_sigma = [" + ", ".join(f"{s:.3g}" for s in sigma) + "]",
        ]
    tmp = OUT + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(out) + "\n")
    os.replace(tmp, OUT)


if __name__ == "__main__":
    main()
