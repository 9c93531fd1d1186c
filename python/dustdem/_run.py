"""Running, resuming and reading compressions."""

from __future__ import annotations

import os
from functools import cached_property
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, Union

import numpy as np

from . import _dustdem
from ._config import ConfigLike, config_source
from ._tables import State, last_snapshot, read_table

Progress = Callable[[Union[Dict[str, Any], str]], Any]
PathLike = Union[str, "os.PathLike[str]"]

#: The curve's energy channels [erg]: the energies held and the work dissipated per channel.
ENERGY_PREFIXES = ("e_", "d_", "wall_work", "energy_balance")


class Run:
    """The results of a run: a run directory read lazily.

    `curve` and `profiles` are dicts of numpy columns (as in curve.csv and profiles.csv),
    `energy` the energy channels of the curve, `final_state` the last snapshot's monomers.
    """

    def __init__(self, out: PathLike, lines: Optional[List[str]] = None,
                 files: Optional[List[str]] = None) -> None:
        self.out = Path(out)
        #: The summary lines `dustdem run` prints (empty for a run read back).
        self.lines: List[str] = list(lines or [])
        #: The files the run wrote (config, curve, profiles, plot).
        self.files: List[Path] = [Path(f) for f in files or []]
        if not any((self.out / f).is_file() for f in ("curve.csv", "config.toml")):
            raise FileNotFoundError(f"{self.out}: no curve.csv; not a dustdem run directory")

    def __repr__(self) -> str:
        return f"Run({str(self.out)!r}, rows={len(self.curve.get('step', ()))})"

    @cached_property
    def curve(self) -> Dict[str, np.ndarray]:
        """curve.csv: one row per `average_steps` steps (step, time_s, phi, p_top_pa, ...);
        empty for a collision, whose results are in `lines`."""
        path = self.out / "curve.csv"
        return read_table(path) if path.is_file() else {}

    @cached_property
    def profiles(self) -> Dict[str, np.ndarray]:
        """profiles.csv: filling-factor profiles, one line per slab (step, z_um, phi, ...)."""
        path = self.out / "profiles.csv"
        return read_table(path) if path.is_file() else {}

    @property
    def energy(self) -> Dict[str, np.ndarray]:
        """The energy tally of the curve [erg]: energies held (e_*), work dissipated per
        channel (d_*), the walls' work and the balance, per row."""
        return {k: v for k, v in self.curve.items() if k.startswith(ENERGY_PREFIXES)}

    @cached_property
    def final_state(self) -> Optional[State]:
        """The last snapshot (positions in µm, N × 3, by monomer id); None without snapshots."""
        return last_snapshot(self.out)

    @property
    def phi(self) -> np.ndarray:
        """Filling factor per row."""
        return self.curve["phi"]

    @property
    def pressure(self) -> np.ndarray:
        """Top-wall pressure per row [Pa]."""
        return self.curve["p_top_pa"]

    def envelope(self) -> "tuple[np.ndarray, np.ndarray]":
        """(φ, P [Pa]) as the sweep analysis reads the curve (see :func:`dustdem.envelope`)."""
        from ._tools import envelope

        return envelope(self.phi, self.pressure)

    @property
    def config(self) -> str:
        """The effective config the run used (config.toml in its directory)."""
        return (self.out / "config.toml").read_text()

    @property
    def checkpoint(self) -> Optional[Path]:
        """checkpoint.bin if the run wrote one (`resume` continues from it)."""
        path = self.out / "checkpoint.bin"
        return path if path.is_file() else None

    def to_dataframe(self, table: str = "curve") -> Any:
        """The curve (or `table="profiles"`) as a pandas DataFrame; pandas is imported here."""
        import pandas as pd  # optional dependency

        if table not in ("curve", "profiles"):
            raise ValueError(f"table {table!r}: expected 'curve' or 'profiles'")
        return pd.DataFrame(getattr(self, table))

    def resume(self, backend: str = "cpu", threads: Optional[int] = None,
               progress: Optional[Progress] = None, precision: str = "auto") -> "Run":
        """Continues this run from its checkpoint (see :func:`resume`)."""
        if self.checkpoint is None:
            raise FileNotFoundError(f"{self.out}: no checkpoint.bin to resume from")
        return resume(self.checkpoint, backend=backend, threads=threads, progress=progress,
                      precision=precision)


def run(config: ConfigLike = None, out: Optional[PathLike] = None, backend: str = "cpu",
        threads: Optional[int] = None, progress: Optional[Progress] = None,
        force: bool = False, precision: str = "auto") -> Run:
    """Runs a compression (or collision) as `dustdem run` does and returns its results.

    `config` is a path, a TOML string, a dict of sections or None (the built-in quick run).
    `out` defaults to the config's `[output] dir`; an existing run there is refused unless
    `force`. `backend` is "cpu", "gpu" or "auto"; `threads` sizes the CPU engine's pool;
    `precision` is the GPU engine's arithmetic: "exact" (f64), "mixed" (f32 with split
    centres, for adapters without f64) or "auto" (exact where the adapter has f64).
    `progress` is called once per row with a dict (step, time_s, phi, p_top_pa, p_bottom_pa,
    contacts, wall_contacts, fraction, steps_per_second) and with a string for each notice
    (backend chosen, checkpoints written).

    Ctrl-C (or an exception from `progress`) stops the run at the next row after writing
    checkpoint.bin; the exception (KeyboardInterrupt) is raised with its `checkpoint`
    attribute naming the file, which :func:`resume` continues from. A bad config raises
    ConfigError naming the field, its value and what is allowed.
    """
    text, path, name = config_source(config)
    summary = _dustdem.run_config(
        text=text, path=path, name=name,
        out=None if out is None else os.fspath(out),
        backend=backend, threads=threads, force=force, progress=progress,
        precision=precision,
    )
    return Run(summary["out_dir"], summary["lines"], summary["files"])


def resume(checkpoint: PathLike, backend: str = "cpu", threads: Optional[int] = None,
           progress: Optional[Progress] = None, precision: str = "auto") -> Run:
    """Continues the run that wrote `checkpoint` (its checkpoint.bin) in its own directory, as
    `dustdem resume` does: on the same backend the result is bit for bit the uninterrupted
    run's. A run directory may be given instead of the file. Progress, Ctrl-C and
    `precision` as in :func:`run`."""
    path = Path(checkpoint)
    if path.is_dir():
        path = path / "checkpoint.bin"
    summary = _dustdem.resume_checkpoint(
        os.fspath(path), backend=backend, threads=threads, progress=progress,
        precision=precision,
    )
    return Run(summary["out_dir"], summary["lines"], summary["files"])


def read_run(path: PathLike) -> Run:
    """Reads an existing run directory (curve.csv, profiles.csv, snapshots) as a :class:`Run`."""
    return Run(path)
