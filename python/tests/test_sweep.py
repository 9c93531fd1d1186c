"""A sweep run from Python: cases run by the command-line program, table collected."""

from __future__ import annotations

import dustdem
from conftest import tiny_config


def test_tiny_sweep(tmp_path, cli):
    base = tmp_path / "base.toml"
    base.write_text(dustdem.to_toml(tiny_config(monomers=100, max_steps=1000)))
    spec = {
        "base": str(base),
        "axes": {"wall_speed_m_s": [5.0], "seed": [1, 2], "monomers": [100]},
    }
    lines = []
    result = dustdem.sweep(spec, out=tmp_path / "sweep", jobs=2, threads=1, exe=cli,
                           progress=lines.append)
    assert result.done == 2 and result.failed == [] and result.not_started == 0
    assert result.table == tmp_path / "sweep" / "sweep.csv"
    assert [r["status"] for r in result.rows] == ["done", "done"]
    assert any(line.startswith("sweep: 2 cases") for line in lines)
    runs = [dustdem.read_run(result.out_dir / r["case"]) for r in result.rows]
    assert all(r.curve["step"][-1] == 1000 for r in runs)
    again = dustdem.sweep(tmp_path / "sweep" / "sweep.toml", out=tmp_path / "sweep", exe=cli)
    assert again.done == 0 and again.skipped == 2
