"""A calibration plan run from Python through the library's calibration."""

from __future__ import annotations

from pathlib import Path

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


def test_revisit_from_the_committed_run_cache(tmp_path, monkeypatch):
    """The committed three-sample damping + side walls calibration, made by the command with
    `--screen-monomers 60 --revisit`, rebuilt through Python from its run cache alone: the
    keyword options must reach the search (without `revisit` the report has no Revisits
    section; with another `screen_monomers` the cache lacks the runs). The report names
    the files as given, so they are given as the command was: relative to the repository."""
    monkeypatch.chdir(REPO)
    hidden = Path("docs") / "calibration" / "hidden_pair"
    dustdem.calibrate(
        hidden / "measured_damping_side_walls.toml", Path("configs") / "calibrate_quick.toml",
        out=tmp_path / "cal", seeds=[1, 2, 3], threads=2, cache=hidden / "run_cache",
        screen_monomers=60, revisit=True, cache_only=True,
    )
    report = (tmp_path / "cal" / "report.md").read_text()
    assert report == (hidden / "damping_side_walls" / "report.md").read_text()
    assert "Revisits" in report


def test_cache_only_refuses_to_simulate(tmp_path):
    hidden = REPO / "docs" / "calibration" / "hidden_pair"
    with pytest.raises(dustdem.RunError, match="not in the run cache"):
        dustdem.calibrate(
            hidden / "measured_damping_side_walls.toml", REPO / "configs" / "calibrate_quick.toml",
            out=tmp_path / "cal", seeds=[1, 2, 3], threads=2, cache=hidden / "run_cache",
            screen_monomers=40, cache_only=True,
        )
