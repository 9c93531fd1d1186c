"""Config problems arrive as dustdem.ConfigError with the command line's message."""

from __future__ import annotations

import subprocess

import pytest

import dustdem


def test_bad_value_names_the_field(tmp_path):
    with pytest.raises(dustdem.ConfigError) as info:
        dustdem.run({"experiment": {"wall_speed_m_s": -1.0}}, out=tmp_path / "r")
    e = info.value
    assert isinstance(e, ValueError)
    assert e.field == "[experiment] wall_speed_m_s"
    assert e.value == "-1"
    assert "wall_speed_m_s = -1 is not allowed" in str(e)
    assert not (tmp_path / "r").exists()


def test_unknown_key(tmp_path):
    with pytest.raises(dustdem.ConfigError, match="unknown field `monomer`"):
        dustdem.run({"sample": {"monomer": 10}}, out=tmp_path / "r")


def test_same_message_as_cli(tmp_path, cli):
    config = tmp_path / "bad.toml"
    config.write_text(dustdem.to_toml({"sample": {"monomers": 0}}))
    cli_run = subprocess.run([str(cli), "run", str(config), "--out", str(tmp_path / "o")],
                             capture_output=True, text=True)
    assert cli_run.returncode == 2
    with pytest.raises(dustdem.ConfigError) as info:
        dustdem.run(config, out=tmp_path / "o")
    assert cli_run.stderr.strip() == f"error: {info.value}"
    assert info.value.field == "[sample] monomers"


def test_check_config():
    assert dustdem.check_config(None) == "runs/omni_quick"
    with pytest.raises(dustdem.ConfigError):
        dustdem.check_config("[integration]\ndt_ns = 0\n")


def test_bad_backend_and_threads(tmp_path):
    with pytest.raises(ValueError, match="backend"):
        dustdem.run(None, out=tmp_path / "r", backend="tpu")
    with pytest.raises(ValueError, match="threads"):
        dustdem.run(None, out=tmp_path / "r", threads=0)


def test_missing_file():
    with pytest.raises(dustdem.ConfigError, match="cannot read the config file"):
        dustdem.run("/nonexistent/config.toml")


def test_toml_writer_round_trip():
    tomllib = pytest.importorskip("tomllib")
    config = {
        "model": {"damping": {"kind": "viscous", "kappa": 1e-6}, "rolling_modifier": 8},
        "walls": {"side": {"rolling": 1e-3}},
        "sample": {"file": "a \"quoted\" path.txt", "seed": 2},
        "integration": {"space_filling_order": False},
        "list": [1.5, float("inf")],
    }
    assert tomllib.loads(dustdem.to_toml(config)) == config
