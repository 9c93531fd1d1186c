"""examples/phi_p.py runs and draws its figure."""

from __future__ import annotations

import subprocess
import sys

import pytest

from conftest import REPO


def test_phi_p_example(tmp_path):
    pytest.importorskip("matplotlib")
    png = tmp_path / "phi_p.png"
    done = subprocess.run([sys.executable, str(REPO / "examples" / "phi_p.py"), "--out",
                           str(png)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert f"wrote {png}" in done.stdout
