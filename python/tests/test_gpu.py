"""The GPU backend from Python: the command line's GPU results (lavapipe where no GPU)."""

from __future__ import annotations

import os
import subprocess

import numpy as np
import pytest

import dustdem
from conftest import tiny_config


def test_gpu_run_matches_cli(tmp_path, cli):
    config = tmp_path / "c.toml"
    config.write_text(dustdem.to_toml(tiny_config(max_steps=1000)))
    notes = []
    try:
        run = dustdem.run(config, out=tmp_path / "py", backend="gpu",
                          progress=lambda e: isinstance(e, str) and notes.append(e))
    except dustdem.RunError as e:
        if os.environ.get("CI"):
            raise
        pytest.skip(f"no GPU adapter with f64: {e}")
    assert notes[0].startswith("backend: gpu")
    subprocess.run([str(cli), "run", str(config), "--out", str(tmp_path / "cli"), "--backend",
                    "gpu", "--quiet"], check=True, capture_output=True)
    assert (run.out / "curve.csv").read_bytes() == (tmp_path / "cli" / "curve.csv").read_bytes()
    cpu = dustdem.run(config, out=tmp_path / "cpu", backend="cpu")
    np.testing.assert_allclose(run.phi, cpu.phi, rtol=1e-9)


def test_gpu_precision_is_chosen_and_checked(tmp_path):
    config = tmp_path / "c.toml"
    config.write_text(dustdem.to_toml(tiny_config(max_steps=200)))
    with pytest.raises(ValueError, match="precision `half`: expected exact, mixed or auto"):
        dustdem.run(config, out=tmp_path / "bad", backend="gpu", precision="half")
    notes = []
    try:
        run = dustdem.run(config, out=tmp_path / "mixed", backend="gpu", precision="mixed",
                          progress=lambda e: isinstance(e, str) and notes.append(e))
    except dustdem.RunError as e:
        if os.environ.get("CI"):
            raise
        pytest.skip(f"no GPU adapter: {e}")
    assert "mixed precision" in notes[0], notes
    assert len(run.phi) > 1
