"""A calibration plan run from Python through the library's calibration."""

from __future__ import annotations

import pytest

import dustdem
from conftest import REPO

MEASURED = REPO / "configs" / "measured" / "guettler2009_omni.toml"


def test_plan(tmp_path):
    config = {
        "sample": {"monomers": 100, "seed": 1},
        "experiment": {"kind": "omni", "wall_speed_m_s": 2.0, "phi_stop": 0.5},
        "output": {"snapshot_format": "none"},
    }
    lines = []
    result = dustdem.calibrate(MEASURED, config, out=tmp_path / "cal", seeds=[1], plan=True,
                               threads=1, progress=lines.append)
    assert result.files == [tmp_path / "cal" / "plan.md"]
    assert result.files[0].is_file()
    assert any(line.startswith("rolling_stiffness:") for line in result.lines)
    assert lines[0].startswith("baseline:")
    assert any((tmp_path / "cal" / "run_cache").iterdir())
    assert (tmp_path / "cal" / "base_config.toml").is_file()


def test_missing_measured_file(tmp_path):
    with pytest.raises(dustdem.RunError):
        dustdem.calibrate(tmp_path / "none.toml", None, out=tmp_path / "cal", plan=True)
