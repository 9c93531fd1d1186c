"""Ctrl-C stops a run at the next row with a checkpoint written; resume finishes it exactly."""

from __future__ import annotations

import shutil
import signal
import subprocess
import sys
import textwrap

import pytest

import dustdem
from conftest import tiny_config

CHILD = textwrap.dedent(
    """
    import sys
    import dustdem

    def progress(event):
        if isinstance(event, dict) and event["step"] == 100:
            print("row", flush=True)

    try:
        dustdem.run(sys.argv[1], out=sys.argv[2], progress=progress)
        print("finished", flush=True)
    except KeyboardInterrupt as e:
        print("interrupted", e.checkpoint, flush=True)
        sys.exit(dustdem.RESUMABLE_EXIT)
    """
)


def test_sigint_checkpoints_and_resume_continues(tmp_path, cli):
    config = tmp_path / "c.toml"
    # checkpoint_every_rows = 0 and minutes = 0 would never checkpoint: the one found after
    # the signal is the interrupt's own.
    cfg = tiny_config(max_steps=20_000)
    cfg["experiment"]["wall_speed_m_s"] = 0.5
    cfg["output"] = {"checkpoint_every_rows": 0, "checkpoint_minutes": 0.0}
    config.write_text(dustdem.to_toml(cfg))
    out = tmp_path / "interrupted"
    child = subprocess.Popen([sys.executable, "-c", CHILD, str(config), str(out)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "row"
    child.send_signal(signal.SIGINT)
    stdout, stderr = child.communicate(timeout=120)
    assert child.returncode == dustdem.RESUMABLE_EXIT, stderr
    checkpoint = out / "checkpoint.bin"
    assert stdout.strip() == f"interrupted {checkpoint}"
    assert checkpoint.is_file()
    stopped = dustdem.read_run(out)
    assert 100 <= stopped.curve["step"][-1] < 20_000
    assert not (out / ".dustdem.lock").exists()

    shutil.copytree(out, tmp_path / "copy")
    resumed = dustdem.resume(checkpoint)
    assert resumed.curve["step"][-1] == 20_000
    assert resumed.lines[0].endswith("max_steps reached")
    whole = dustdem.run(config, out=tmp_path / "whole")
    expected = (whole.out / "curve.csv").read_bytes()
    assert (out / "curve.csv").read_bytes() == expected
    assert (out / "profiles.csv").read_bytes() == (whole.out / "profiles.csv").read_bytes()

    subprocess.run([str(cli), "resume", str(tmp_path / "copy" / "checkpoint.bin"), "--quiet"],
                   check=True, capture_output=True)
    assert (tmp_path / "copy" / "curve.csv").read_bytes() == expected


def test_exception_in_progress_stops_at_a_checkpoint(tmp_path):
    class Stop(Exception):
        pass

    def progress(event):
        if isinstance(event, dict) and event["step"] >= 500:
            raise Stop("enough")

    with pytest.raises(Stop) as info:
        dustdem.run(tiny_config(), out=tmp_path / "r", progress=progress)
    assert info.value.checkpoint == str(tmp_path / "r" / "checkpoint.bin")
    assert dustdem.read_run(tmp_path / "r").curve["step"][-1] == 500
    finished = dustdem.read_run(tmp_path / "r").resume()
    assert finished.curve["step"][-1] == 4000
