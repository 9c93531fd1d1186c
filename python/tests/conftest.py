"""Shared fixtures: a tiny compression config and the command-line program to compare with."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

import dustdem

REPO = Path(__file__).resolve().parents[2]


def tiny_config(monomers: int = 200, max_steps: int = 4000, seed: int = 3) -> dict:
    """An omnidirectional compression of a few hundred monomers: well under a second."""
    return {
        "sample": {"monomers": monomers, "seed": seed},
        "experiment": {
            "kind": "omni",
            "wall_speed_m_s": 5.0,
            "max_steps": max_steps,
            "average_steps": 100,
            "profile_every_rows": 10,
        },
        "output": {"checkpoint_every_rows": 10},
    }


@pytest.fixture
def tiny() -> dict:
    return tiny_config()


@pytest.fixture(scope="session")
def cli() -> Path:
    """The dustdem program built from this tree (CI builds it before the tests)."""
    try:
        exe = dustdem.find_cli()
    except FileNotFoundError:
        if os.environ.get("CI"):
            raise
        pytest.skip("no dustdem program built (cargo build --release)")
    return exe
