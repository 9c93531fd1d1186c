"""The Eq. 13 fit of Seizinger et al. (2012) recovers a known law."""

from __future__ import annotations

import numpy as np
import pytest

import dustdem

LAW = dict(phi1=0.15, phi2=0.58, p_m=16_667.0, delta=0.562)


def guettler(p, phi1, phi2, p_m, delta):
    """Eq. 13 written out: φ₂ − (φ₂ − φ₁) / (exp((log₁₀P − log₁₀p_m)/Δ) + 1)."""
    return phi2 - (phi2 - phi1) / (np.exp((np.log10(p) - np.log10(p_m)) / delta) + 1.0)


def test_eq13_is_the_law():
    p = np.logspace(0, 8, 50)
    np.testing.assert_allclose(dustdem.eq13(p, **LAW), guettler(p, **LAW), rtol=1e-12)


def test_exact_data_give_the_parameters():
    p = np.logspace(1, 7, 60)
    fit = dustdem.fit_eq13(guettler(p, **LAW), p)
    assert fit.converged and fit.points == 60
    for name, value in LAW.items():
        assert getattr(fit, name) == pytest.approx(value, rel=1e-6)
    assert fit.free == ["phi1", "phi2", "log10_p_m", "delta"]


def test_noisy_data_within_errors():
    rng = np.random.default_rng(12)
    p = np.logspace(1, 7, 200)
    phi = guettler(p, **LAW) + rng.normal(0, 0.005, p.size)
    fit = dustdem.fit_eq13(phi, p)
    for name, value in LAW.items():
        assert abs(getattr(fit, name) - value) < 4 * fit.std_err[name], name
    np.testing.assert_allclose(fit(p), guettler(p, fit.phi1, fit.phi2, fit.p_m, fit.delta))


def test_fixed_phi1_and_filtered_points():
    p = np.logspace(1, 7, 40)
    phi = guettler(p, **LAW)
    p_with_gaps = np.concatenate([[np.nan, 0.0, -5.0], p])
    phi_with_gaps = np.concatenate([[0.1, 0.1, 0.1], phi])
    fit = dustdem.fit_eq13(phi_with_gaps, p_with_gaps, fix_phi1=0.15)
    assert fit.points == 40 and fit.phi1 == 0.15 and fit.std_err["phi1"] == 0
    assert fit.p_m == pytest.approx(LAW["p_m"], rel=1e-6)
    assert dustdem.fit_eq13(phi, p, p_min=1e3).points == np.count_nonzero(p >= 1e3)


def test_too_few_points():
    with pytest.raises(ValueError):
        dustdem.fit_eq13([0.2, 0.3], [1e3, 1e4])
    with pytest.raises(ValueError, match="shape"):
        dustdem.fit_eq13([0.2, 0.3], [1e3])
