"""RBD samples: deterministic, and the very sample a run starts from."""

from __future__ import annotations

import numpy as np
import pytest

import dustdem
from conftest import tiny_config


def test_same_seed_same_bits():
    a = dustdem.rbd_sample(300, seed=7)
    b = dustdem.rbd_sample(300, seed=7)
    c = dustdem.rbd_sample(300, seed=8)
    assert a.positions.shape == (300, 3)
    assert a.positions.tobytes() == b.positions.tobytes()
    assert not np.array_equal(a.positions, c.positions)


def test_geometry():
    s = dustdem.rbd_sample(300, seed=1)
    assert s.footprint == "box" and s.radius_um == pytest.approx(0.6)
    half = s.size_um / 2
    assert np.all(np.abs(s.positions[:, :2]) <= half - s.radius_um + 1e-9)
    assert np.all(s.positions[:, 2] >= s.radius_um - 1e-9)
    assert s.height_um == pytest.approx(s.positions[:, 2].max() + s.radius_um)
    assert 0.05 < s.filling_factor_bulk < 0.3
    cyl = dustdem.rbd_sample(300, seed=1, footprint="cylinder", size_um=5.0)
    assert cyl.footprint == "cylinder" and cyl.size_um == pytest.approx(5.0)
    assert np.all(np.hypot(cyl.positions[:, 0], cyl.positions[:, 1]) <= 5.0 - 0.6 + 1e-9)
    cut = dustdem.rbd_sample(300, seed=1, top="cut")
    assert cut.height_um <= cut.size_um + 1e-9


def test_matches_the_runs_first_snapshot(tmp_path):
    run = dustdem.run(tiny_config(max_steps=100), out=tmp_path / "r")
    first = dustdem.read_vtu(tmp_path / "r" / "snapshots" / "snap_0000000000.vtu")
    sample = dustdem.rbd_sample(200, seed=3)
    np.testing.assert_array_equal(first.positions, sample.positions)
    assert run.final_state.step == 100


def test_bad_values():
    with pytest.raises(dustdem.ConfigError, match=r"\[sample\] footprint"):
        dustdem.rbd_sample(100, footprint="sphere")
    with pytest.raises(dustdem.ConfigError) as info:
        dustdem.rbd_sample(0)
    assert info.value.field == "[sample] monomers"


def test_material_from_config():
    s = dustdem.rbd_sample(100, seed=2, config={"material": {"radius_um": 1.0}})
    assert s.radius_um == pytest.approx(1.0)
    assert s.positions[:, 2].min() == pytest.approx(1.0, rel=1e-3)
