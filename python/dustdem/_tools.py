"""RBD samples, the Eq. 13 fit, sweeps and calibrations."""

from __future__ import annotations

import csv
import os
import shutil
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Union

import numpy as np

from . import _dustdem
from ._config import ConfigLike, config_source, to_toml

PathLike = Union[str, "os.PathLike[str]"]


@dataclass
class Sample:
    """A sample built by random ballistic deposition; lengths in µm."""

    positions: np.ndarray
    radius_um: float
    footprint: str
    size_um: float
    height_um: float
    seed: int
    filling_factor_bulk: float
    interior_filling_factor: float


def rbd_sample(monomers: int, seed: int = 1, footprint: str = "box", top: str = "rough",
               size_um: float = 0.0, config: ConfigLike = None) -> Sample:
    """A random-ballistic-deposition sample exactly as a run with these `[sample]` settings
    builds it (contacts at the equilibrium distance; the same seed gives the same bits).

    `footprint` is "box" or "cylinder", `top` "rough" (as deposited) or "cut" (cut flat at a
    height equal to the width, Seizinger et al. 2012, Sect. 5.2). `size_um` is the box side or
    cylinder radius (0: sized for a cube-shaped sample). `config` supplies the material (the
    monomer radius); its `[sample]` section is overridden. Positions are monomer centres in µm,
    shape (monomers, 3), in deposition order. Bad values raise ConfigError.
    """
    text = None
    if config is not None:
        text, path, _ = config_source(config)
        if text is None:
            text = Path(path).read_text()  # type: ignore[arg-type]
    d = _dustdem.rbd_sample(monomers, seed, footprint, top, float(size_um), text)
    positions = np.frombuffer(d["positions_um"], dtype=np.float64).reshape(-1, 3).copy()
    return Sample(positions, d["radius_um"], d["footprint"], d["size_um"], d["height_um"],
                  d["seed"], d["filling_factor_bulk"], d["interior_filling_factor"])


def eq13(pressure: Any, phi1: float, phi2: float, p_m: float, delta: float) -> np.ndarray:
    """Eq. 13 of Seizinger et al. (2012), the law of Güttler et al. (2009): φ(P) for
    pressures in Pa (the library's own implementation)."""
    p = np.asarray(pressure, dtype=np.float64)
    values = _dustdem.eq13_phi(phi1, phi2, p_m, delta, p.ravel().tolist())
    return np.asarray(values).reshape(p.shape)


def envelope(phi: Any, pressure: Any) -> "tuple[np.ndarray, np.ndarray]":
    """φ(P) of a compression as the sweep analysis and the calibration read it: each row's φ
    with the running maximum of the log-pressure smoothed by a running median over 9 rows, so
    each pressure is reached once. Returns (phi, P [Pa]) of the rows that had held a pressure.
    """
    phi = np.asarray(phi, dtype=np.float64)
    p = np.asarray(pressure, dtype=np.float64)
    log_p = np.asarray(_dustdem.envelope_log10_p(phi.tolist(), p.tolist()))
    held = log_p > -10.0
    return phi[held], 10.0 ** log_p[held]


@dataclass
class Eq13Fit:
    """Parameters of Eq. 13 with their one-sigma errors and the fit's statistics."""

    phi1: float
    phi2: float
    p_m: float
    delta: float
    std_err: Dict[str, float]
    std_err_log10_p_m: float
    correlation: List[List[float]]
    free: List[str]
    rss: float
    chi2_per_dof: float
    dof: int
    iterations: int
    converged: bool
    points: int = 0

    def __call__(self, pressure: Any) -> np.ndarray:
        """φ of the fitted law at `pressure` [Pa]."""
        return eq13(pressure, self.phi1, self.phi2, self.p_m, self.delta)


def fit_eq13(phi: Any, pressure: Any, sigma: Any = None, *, fix_phi1: Optional[float] = None,
             fix_phi2: Optional[float] = None, p_min: float = 0.0,
             max_iterations: int = 200) -> Eq13Fit:
    """Fits Eq. 13 of Seizinger et al. (2012) to filling factors `phi` at pressures
    `pressure` [Pa], as `dustdem fit` does (Levenberg–Marquardt, grid start).

    Points with a pressure that is not finite and positive, or below `p_min`, are left out
    (the first rows of a curve have none). `sigma` weights φ by its one-sigma errors; without
    it the errors are scaled by the scatter. φ₁ or φ₂ can be held fixed.
    """
    phi = np.asarray(phi, dtype=np.float64)
    p = np.asarray(pressure, dtype=np.float64)
    if phi.shape != p.shape:
        raise ValueError(f"phi has shape {phi.shape}, pressure {p.shape}")
    keep = np.isfinite(p) & (p > 0) & (p >= p_min)
    s = None if sigma is None else np.asarray(sigma, dtype=np.float64)[keep].tolist()
    r = _dustdem.fit_eq13(p[keep].tolist(), phi[keep].tolist(), s, fix_phi1, fix_phi2,
                          max_iterations)
    return Eq13Fit(points=int(keep.sum()), **r)


def find_cli() -> Path:
    """The `dustdem` command-line program that sweeps run their cases with: $DUSTDEM_EXE,
    else `dustdem` on the PATH, else the repository's target/release/dustdem."""
    exe = os.environ.get("DUSTDEM_EXE") or shutil.which("dustdem")
    if exe:
        return Path(exe)
    repo = Path(__file__).resolve().parents[2] / "target" / "release" / "dustdem"
    if repo.is_file():
        return repo
    raise FileNotFoundError(
        "no dustdem program found: build it (cargo build --release) and set DUSTDEM_EXE or "
        "put it on the PATH"
    )


@dataclass
class SweepResult:
    """What a sweep came to: its directory, its table (sweep.csv) and the case counts."""

    out_dir: Path
    table: Path
    done: int
    skipped: int
    failed: List[tuple]
    interrupted: List[str]
    not_started: int
    rows: List[Dict[str, str]] = field(default_factory=list)


def sweep(path: Union[PathLike, Mapping[str, Any]], out: Optional[PathLike] = None,
          jobs: int = 1, threads: Optional[int] = None, backend: str = "cpu",
          exe: Optional[PathLike] = None,
          progress: Optional[Callable[[str], Any]] = None,
          precision: str = "auto") -> SweepResult:
    """Runs a sweep as `dustdem sweep FILE` does: every case (finished ones skipped, stopped
    ones resumed) as a run of the command-line program (`exe`, default :func:`find_cli`),
    `jobs` at once, then collects sweep.csv. A dict is written to `out/sweep.toml` first
    (its `base` path is then relative to that directory: give it absolute). `progress`
    receives the sweep's lines; `backend` and `precision` are each case's (as for
    :func:`run`). Ctrl-C stops the running cases at a checkpoint, then raises
    KeyboardInterrupt; calling again continues.
    """
    if isinstance(path, Mapping):
        if out is None:
            raise ValueError("a sweep given as a dict needs `out`")
        Path(out).mkdir(parents=True, exist_ok=True)
        file = Path(out) / "sweep.toml"
        file.write_text(to_toml(path))
        path = file
    r = _dustdem.sweep(
        os.fspath(path), os.fspath(exe or find_cli()),
        out=None if out is None else os.fspath(out),
        jobs=jobs, threads=threads, backend=backend, progress=progress,
        precision=precision,
    )
    with open(r["table"], newline="") as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    return SweepResult(Path(r["out_dir"]), Path(r["table"]), r["done"], r["skipped"],
                       r["failed"], r["interrupted"], r["not_started"], rows)


@dataclass
class CalibrationResult:
    """The summary lines of a calibration and the files of its report."""

    out: Path
    lines: List[str]
    files: List[Path]


def calibrate(measured: Union[PathLike, Sequence[PathLike]], config: ConfigLike,
              out: PathLike = "runs/calibration", seeds: Sequence[int] = (1, 2, 3),
              rounds: int = 2, threads: Optional[int] = None, plan: bool = False,
              cache: Optional[PathLike] = None,
              progress: Optional[Callable[[str], Any]] = None, *, screen_seeds: int = 1,
              screen_monomers: int = 0, prune: bool = True, screen_both_ends: bool = True,
              revisit: bool = False, cache_only: bool = False) -> CalibrationResult:
    """Calibrates the config's model against measured curves, as `dustdem calibrate` does
    (with `plan`, only the detection limits: plan.md). `measured` is one file or several
    (fitted jointly, see configs/measured/). A config given as text or a dict is written to
    `out/base_config.toml`. Finished runs are kept in `cache` (default: out/run_cache), so a
    repeated calibration does not repeat them. Returns the summary lines and report files.

    The keyword-only options are those of the command: `screen_seeds` and `screen_monomers`
    (seeds and sample size of the screen and the 1-D fits; 0: all seeds, the config's size),
    `prune=False` (``--no-prune``), `screen_both_ends`, `revisit` (search again for each
    applied effect with the others in, one backfitting pass) and `cache_only` (read finished
    runs from `cache` and simulate nothing: a run missing from it is an error).
    """
    items = [measured] if isinstance(measured, (str, os.PathLike)) else list(measured)
    text, path, _ = config_source(config)
    out = Path(out)
    if path is None:
        out.mkdir(parents=True, exist_ok=True)
        path = os.fspath(out / "base_config.toml")
        Path(path).write_text(text or "")
    lines, files = _dustdem.calibrate(
        [os.fspath(m) for m in items], path, os.fspath(out), list(seeds), rounds, threads,
        plan, None if cache is None else os.fspath(cache), progress, screen_seeds,
        screen_monomers, prune, screen_both_ends, revisit, cache_only,
    )
    return CalibrationResult(out, lines, [Path(f) for f in files])
