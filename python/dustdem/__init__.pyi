"""Type stubs of the dustdem package (the Python interface of the dustdem simulator)."""

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

_PathLike = Union[str, "os.PathLike[str]"]
_ConfigLike = Union[str, "os.PathLike[str]", Mapping[str, Any], None]
_Progress = Callable[[Union[Dict[str, Any], str]], Any]
_Law = Tuple[float, float, float, float]

__version__: str
DEFAULT_CONFIG: str
"""The built-in quick run (configs/omni_quick.toml)."""
RESUMABLE_EXIT: int
"""Exit status of the command line when a signal stopped it after a checkpoint."""
GUETTLER_2009_OMNI: _Law
"""(φ₁, φ₂, p_m [Pa], Δ) of Eq. 13 for the omnidirectional measurements (Güttler et al. 2009)."""
BLUM_SCHRAEPLER_2004_UNI: _Law
"""(φ₁, φ₂, p_m [Pa], Δ) of Eq. 13 for the unidirectional measurements (Blum & Schräpler 2004)."""

class ConfigError(ValueError):
    """A config problem, with the command line's message (file, field, value, what is allowed)."""

    file: str
    field: str
    value: str
    allowed: str

class RunError(RuntimeError):
    """A run that could not be set up, continued or written."""

@dataclass
class State:
    """A snapshot of the monomers: positions in µm (N × 3), ordered by monomer id."""

    step: int
    time_s: float
    positions: np.ndarray
    ids: np.ndarray
    arrays: Dict[str, np.ndarray]
    source: Optional[Path]

class Run:
    """The results of a run: a run directory read lazily."""

    out: Path
    lines: List[str]
    files: List[Path]
    def __init__(
        self, out: _PathLike, lines: Optional[List[str]] = ..., files: Optional[List[str]] = ...
    ) -> None: ...
    @property
    def curve(self) -> Dict[str, np.ndarray]:
        """curve.csv as numpy columns (step, time_s, phi, p_top_pa, ...)."""
    @property
    def profiles(self) -> Dict[str, np.ndarray]:
        """profiles.csv as numpy columns (step, time_s, phi_mean, z_um, phi)."""
    @property
    def energy(self) -> Dict[str, np.ndarray]:
        """The energy channels of the curve [erg] (e_*, d_*, wall_work_erg, energy_balance_erg)."""
    @property
    def final_state(self) -> Optional[State]:
        """The last snapshot's monomers; None without snapshots."""
    @property
    def phi(self) -> np.ndarray:
        """Filling factor per row."""
    @property
    def pressure(self) -> np.ndarray:
        """Top-wall pressure per row [Pa]."""
    @property
    def config(self) -> str:
        """The effective config (config.toml)."""
    @property
    def checkpoint(self) -> Optional[Path]:
        """checkpoint.bin, if written."""
    def envelope(self) -> Tuple[np.ndarray, np.ndarray]:
        """(φ, P [Pa]) as the sweep analysis reads the curve."""
    def to_dataframe(self, table: str = ...) -> Any:
        """The curve (or "profiles") as a pandas DataFrame."""
    def resume(
        self,
        backend: str = ...,
        threads: Optional[int] = ...,
        progress: Optional[_Progress] = ...,
        precision: str = ...,
    ) -> Run:
        """Continues this run from its checkpoint."""

def run(
    config: _ConfigLike = ...,
    out: Optional[_PathLike] = ...,
    backend: str = ...,
    threads: Optional[int] = ...,
    progress: Optional[_Progress] = ...,
    force: bool = ...,
    precision: str = ...,
) -> Run:
    """Runs a compression as `dustdem run` does; Ctrl-C stops it at a checkpoint."""

def resume(
    checkpoint: _PathLike,
    backend: str = ...,
    threads: Optional[int] = ...,
    progress: Optional[_Progress] = ...,
    precision: str = ...,
) -> Run:
    """Continues the run that wrote `checkpoint` (or a run directory), as `dustdem resume`."""

def read_run(path: _PathLike) -> Run:
    """Reads an existing run directory."""

def check_config(config: _ConfigLike) -> str:
    """Validates a config; raises ConfigError; returns its output directory."""

def to_toml(config: Mapping[str, Any]) -> str:
    """Writes a nested dict as TOML."""

def read_table(path: _PathLike) -> Dict[str, np.ndarray]:
    """A dustdem CSV table as numpy columns."""

def read_vtu(path: _PathLike) -> State:
    """Reads a VTU snapshot."""

def read_dump(path: _PathLike) -> State:
    """Reads a LAMMPS dump snapshot."""

@dataclass
class Sample:
    """An RBD sample; lengths in µm."""

    positions: np.ndarray
    radius_um: float
    footprint: str
    size_um: float
    height_um: float
    seed: int
    filling_factor_bulk: float
    interior_filling_factor: float

def rbd_sample(
    monomers: int,
    seed: int = ...,
    footprint: str = ...,
    top: str = ...,
    size_um: float = ...,
    config: _ConfigLike = ...,
) -> Sample:
    """A random-ballistic-deposition sample exactly as a run builds it."""

def eq13(pressure: Any, phi1: float, phi2: float, p_m: float, delta: float) -> np.ndarray:
    """Eq. 13 of Seizinger et al. (2012): φ(P)."""

def envelope(phi: Any, pressure: Any) -> Tuple[np.ndarray, np.ndarray]:
    """(φ, P [Pa]) with the running maximum of the median-smoothed pressure."""

@dataclass
class Eq13Fit:
    """Parameters of Eq. 13 with their errors and the fit's statistics."""

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
    points: int
    def __call__(self, pressure: Any) -> np.ndarray:
        """φ of the fitted law at `pressure` [Pa]."""

def fit_eq13(
    phi: Any,
    pressure: Any,
    sigma: Any = ...,
    *,
    fix_phi1: Optional[float] = ...,
    fix_phi2: Optional[float] = ...,
    p_min: float = ...,
    max_iterations: int = ...,
) -> Eq13Fit:
    """Fits Eq. 13 of Seizinger et al. (2012) to φ at pressures [Pa], as `dustdem fit`."""

def find_cli() -> Path:
    """The dustdem command-line program sweeps run their cases with."""

@dataclass
class SweepResult:
    """A sweep's directory, table and case counts."""

    out_dir: Path
    table: Path
    done: int
    skipped: int
    failed: List[Tuple[str, str]]
    interrupted: List[str]
    not_started: int
    rows: List[Dict[str, str]]

def sweep(
    path: Union[_PathLike, Mapping[str, Any]],
    out: Optional[_PathLike] = ...,
    jobs: int = ...,
    threads: Optional[int] = ...,
    backend: str = ...,
    exe: Optional[_PathLike] = ...,
    progress: Optional[Callable[[str], Any]] = ...,
    precision: str = ...,
) -> SweepResult:
    """Runs a sweep as `dustdem sweep FILE` and collects sweep.csv."""

@dataclass
class CalibrationResult:
    """A calibration's summary lines and report files."""

    out: Path
    lines: List[str]
    files: List[Path]

def calibrate(
    measured: Union[_PathLike, Sequence[_PathLike]],
    config: _ConfigLike,
    out: _PathLike = ...,
    seeds: Sequence[int] = ...,
    rounds: int = ...,
    threads: Optional[int] = ...,
    plan: bool = ...,
    cache: Optional[_PathLike] = ...,
    progress: Optional[Callable[[str], Any]] = ...,
    *,
    screen_seeds: int = ...,
    screen_monomers: int = ...,
    prune: bool = ...,
    screen_both_ends: bool = ...,
    revisit: bool = ...,
    cache_only: bool = ...,
) -> CalibrationResult:
    """Calibrates the config's model against measured curves, as `dustdem calibrate`."""
