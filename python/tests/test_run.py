"""Runs through the Python API give the command line's results, read back as numpy arrays."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest

import dustdem
from conftest import tiny_config


def test_curve_identical_to_cli(tmp_path, tiny, cli):
    config = tmp_path / "tiny.toml"
    config.write_text(dustdem.to_toml(tiny))
    subprocess.run(
        [str(cli), "run", str(config), "--out", str(tmp_path / "cli"), "--backend", "cpu",
         "--quiet"],
        check=True, capture_output=True,
    )
    run = dustdem.run(config, out=tmp_path / "py", backend="cpu")
    for name in ("curve.csv", "profiles.csv", "config.toml"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes()
    cli_run = dustdem.read_run(tmp_path / "cli")
    for column, values in run.curve.items():
        np.testing.assert_array_equal(values, cli_run.curve[column])
    np.testing.assert_array_equal(run.final_state.positions, cli_run.final_state.positions)


def test_dict_toml_string_and_path_agree(tmp_path, tiny):
    text = dustdem.to_toml(tiny)
    (tmp_path / "c.toml").write_text(text)
    runs = [
        dustdem.run(tiny, out=tmp_path / "dict"),
        dustdem.run(text, out=tmp_path / "text"),
        dustdem.run(str(tmp_path / "c.toml"), out=tmp_path / "path"),
    ]
    first = (tmp_path / "dict" / "curve.csv").read_bytes()
    for r in runs[1:]:
        assert (r.out / "curve.csv").read_bytes() == first


def test_run_object(tmp_path, tiny):
    rows, notes = [], []
    run = dustdem.run(tiny, out=tmp_path / "r", threads=1,
                      progress=lambda e: (notes if isinstance(e, str) else rows).append(e))
    assert run.out == tmp_path / "r"
    assert len(rows) == len(run.curve["step"]) - 1 or len(rows) == len(run.curve["step"])
    assert rows[-1]["step"] == run.curve["step"][-1] == 4000
    assert 0 < rows[-1]["fraction"] <= 1
    assert any(n.startswith("backend: cpu") for n in notes)
    assert run.curve["phi"][-1] > run.curve["phi"][0]
    assert set(run.energy) >= {"e_kinetic_erg", "d_rolling_erg", "energy_balance_erg"}
    assert all(k.startswith(("e_", "d_", "wall_", "energy_")) for k in run.energy)
    state = run.final_state
    assert state.positions.shape == (200, 3) and state.step == 4000
    assert list(state.ids) == list(range(1, 201))
    assert set(run.profiles) == {"step", "time_s", "phi_mean", "z_um", "phi"}
    assert run.checkpoint is not None
    assert "monomers = 200" in run.config
    assert run.lines[0].startswith("stopped at step 4000")
    again = dustdem.read_run(run.out)
    np.testing.assert_array_equal(again.phi, run.phi)
    np.testing.assert_array_equal(again.pressure, run.pressure)


def test_existing_run_refused_unless_forced(tmp_path, tiny):
    dustdem.run(tiny, out=tmp_path / "r")
    with pytest.raises(dustdem.RunError):
        dustdem.run(tiny, out=tmp_path / "r")
    dustdem.run(tiny, out=tmp_path / "r", force=True)


def test_dataframe(tmp_path):
    pd = pytest.importorskip("pandas")
    run = dustdem.run(tiny_config(max_steps=1000), out=tmp_path / "r")
    frame = run.to_dataframe()
    assert isinstance(frame, pd.DataFrame)
    assert list(frame.columns)[:5] == ["step", "time_s", "wall_gap_um", "area_um2", "phi"]
    assert len(run.to_dataframe("profiles")) == len(run.profiles["z_um"])


def test_lammps_snapshot(tmp_path):
    config = tiny_config(max_steps=1000)
    vtu = dustdem.run(config, out=tmp_path / "vtu").final_state
    config["output"]["snapshot_format"] = "lammps"
    dump = dustdem.run(config, out=tmp_path / "dump").final_state
    assert dump.step == vtu.step == 1000
    np.testing.assert_allclose(dump.positions, vtu.positions, rtol=1e-9, atol=1e-9)


def test_collision(tmp_path):
    run = dustdem.run({"experiment": {"kind": "collision"}}, out=tmp_path / "c")
    assert run.curve == {} and run.lines
    assert (tmp_path / "c" / "config.toml").is_file()


def test_envelope(tmp_path, tiny):
    run = dustdem.run(tiny, out=tmp_path / "r")
    phi, p = run.envelope()
    assert len(phi) == len(p) > 10
    assert np.all(np.diff(p) >= 0) and np.all(p > 0)
    np.testing.assert_array_equal(phi, run.phi[-len(phi):])
