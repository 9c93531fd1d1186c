"""dustdem: molecular dynamics of porous dust agglomerates, from Python.

Compressions of RBD dust samples with the JKR / Dominik–Tielens contact model as in
Seizinger et al. (2012), run by the same library as the `dustdem` command line:

    import dustdem
    r = dustdem.run({"sample": {"monomers": 300}, "experiment": {"max_steps": 5000}},
                    out="runs/py_small")
    r.curve["phi"], r.curve["p_top_pa"]       # numpy arrays
    fit = dustdem.fit_eq13(r.curve["phi"], r.curve["p_top_pa"])

Functions: :func:`run`, :func:`resume`, :func:`read_run`, :func:`rbd_sample`,
:func:`fit_eq13`, :func:`eq13`, :func:`envelope`, :func:`sweep`, :func:`calibrate`, :func:`check_config`,
:func:`read_table`, :func:`to_toml`. The measured reference laws (φ₁, φ₂, p_m [Pa], Δ of
Eq. 13): GUETTLER_2009_OMNI and BLUM_SCHRAEPLER_2004_UNI.
"""

from ._dustdem import (
    BLUM_SCHRAEPLER_2004_UNI,
    DEFAULT_CONFIG,
    GUETTLER_2009_OMNI,
    RESUMABLE_EXIT,
    VERSION,
    ConfigError,
    RunError,
)
from ._config import check_config, to_toml
from ._run import Run, read_run, resume, run
from ._tables import State, read_dump, read_table, read_vtu
from ._tools import (
    CalibrationResult,
    Eq13Fit,
    Sample,
    SweepResult,
    calibrate,
    envelope,
    eq13,
    find_cli,
    fit_eq13,
    rbd_sample,
    sweep,
)

__version__ = VERSION

__all__ = [
    "GUETTLER_2009_OMNI", "BLUM_SCHRAEPLER_2004_UNI", "DEFAULT_CONFIG", "RESUMABLE_EXIT", "ConfigError", "RunError", "Run", "State", "Sample",
    "Eq13Fit", "SweepResult", "CalibrationResult", "run", "resume", "read_run", "rbd_sample",
    "fit_eq13", "eq13", "envelope", "sweep", "calibrate", "check_config", "read_table", "read_vtu",
    "read_dump", "to_toml", "find_cli", "__version__",
]
