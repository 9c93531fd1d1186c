"""Reading what a run writes: CSV tables (through the library's reader) and snapshots."""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, Optional

import numpy as np

from . import _dustdem


def read_table(path: "str | os.PathLike[str]") -> Dict[str, np.ndarray]:
    """A dustdem CSV table (curve.csv, profiles.csv, ...) as a dict of float64 columns.

    Comment lines are skipped and `NaN` cells kept, as the command-line tools read them.
    """
    header, data, rows = _dustdem.read_csv(os.fspath(path))
    table = np.frombuffer(data, dtype=np.float64).reshape(rows, len(header)).copy()
    return {name: table[:, i] for i, name in enumerate(header)}


@dataclass
class State:
    """A snapshot of the monomers: positions in µm (N × 3), ordered by monomer id."""

    step: int
    time_s: float
    positions: np.ndarray
    ids: np.ndarray
    arrays: Dict[str, np.ndarray] = field(default_factory=dict)
    source: Optional[Path] = None


def _numbers(element: ET.Element, dtype: type) -> np.ndarray:
    return np.array((element.text or "").split(), dtype=dtype)


def read_vtu(path: "str | os.PathLike[str]") -> State:
    """Reads a snapshot written as `snap_<step>.vtu` (ASCII VTK unstructured grid)."""
    root = ET.parse(os.fspath(path)).getroot()
    field_data = {a.get("Name"): a for a in root.iter("DataArray")}
    step = int(_numbers(field_data["step"], np.float64)[0])
    time_s = float(_numbers(field_data["TimeValue"], np.float64)[0])
    piece = root.find("UnstructuredGrid/Piece")
    if piece is None:
        raise ValueError(f"{path}: no Piece in the VTU file")
    n = int(piece.get("NumberOfPoints", "0"))
    points = piece.find("Points/DataArray")
    if points is None or points.get("format") != "ascii":
        raise ValueError(f"{path}: positions are not stored as ASCII (a failed state?)")
    positions = _numbers(points, np.float64).reshape(n, 3)
    arrays: Dict[str, np.ndarray] = {}
    point_data = piece.find("PointData")
    for a in point_data if point_data is not None else []:
        if a.get("format") != "ascii":
            continue
        k = int(a.get("NumberOfComponents", "1"))
        values = _numbers(a, np.float64)
        arrays[a.get("Name", "")] = values.reshape(n, k) if k > 1 else values
    ids = arrays.pop("id", np.arange(1, n + 1)).astype(np.int64)
    order = np.argsort(ids, kind="stable")
    arrays = {k: v[order] for k, v in arrays.items()}
    return State(step, time_s, positions[order], ids[order], arrays, Path(path))


def read_dump(path: "str | os.PathLike[str]") -> State:
    """Reads a snapshot written as `snap_<step>.dump` (LAMMPS text dump, µm)."""
    lines = Path(path).read_text().splitlines()
    step = int(lines[lines.index("ITEM: TIMESTEP") + 1])
    start = next(i for i, l in enumerate(lines) if l.startswith("ITEM: ATOMS"))
    columns = lines[start].split()[2:]
    table = np.array([l.split() for l in lines[start + 1 :] if l.strip()], dtype=np.float64)
    table = table.reshape(-1, len(columns))
    col = {name: table[:, i] for i, name in enumerate(columns)}
    ids = col.pop("id").astype(np.int64)
    order = np.argsort(ids, kind="stable")
    positions = np.column_stack([col.pop(c) for c in ("x", "y", "z")])[order]
    arrays = {k: v[order] for k, v in col.items()}
    return State(step, float("nan"), positions, ids[order], arrays, Path(path))


def last_snapshot(out: Path) -> Optional[State]:
    """The snapshot of the highest step in `out/snapshots` (VTU preferred), or None."""
    snaps = out / "snapshots"
    if not snaps.is_dir():
        return None
    found = sorted(
        p for p in snaps.iterdir()
        if p.name.startswith("snap_") and p.suffix in (".vtu", ".dump")
        and p.stem[5:].isdigit()
    )
    if not found:
        return None
    last_step = max(int(p.stem[5:]) for p in found)
    best = [p for p in found if int(p.stem[5:]) == last_step]
    vtu = [p for p in best if p.suffix == ".vtu"]
    return read_vtu(vtu[0]) if vtu else read_dump(best[0])
