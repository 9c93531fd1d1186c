"""Configs given as a path, a TOML string or a dict: what the library is handed."""

from __future__ import annotations

import json
import math
import os
import re
from pathlib import Path
from typing import Any, Mapping, Optional, Tuple, Union

from . import _dustdem

ConfigLike = Union[str, "os.PathLike[str]", Mapping[str, Any], None]

_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")


def _key(k: str) -> str:
    return k if _BARE_KEY.match(k) else json.dumps(k)


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, (str, os.PathLike)):
        # JSON string escapes are TOML basic-string escapes.
        return json.dumps(os.fspath(v))
    if isinstance(v, Mapping):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if hasattr(v, "item"):  # numpy scalars
        return _value(v.item())
    raise TypeError(f"cannot write {type(v).__name__} {v!r} as a TOML value")


def to_toml(config: Mapping[str, Any]) -> str:
    """Writes a nested dict as TOML: plain values first, then one table per nested dict.

    Enough for dustdem configs and sweep files (tables, numbers, strings, booleans, lists and
    inline tables); `{"sample": {"monomers": 200}}` becomes `[sample]` / `monomers = 200`.
    """
    lines: list = []
    _table(config, [], lines)
    return "\n".join(lines).strip() + "\n"


def _table(table: Mapping[str, Any], path: list, lines: list) -> None:
    plain = [(k, v) for k, v in table.items() if not isinstance(v, Mapping)]
    nested = [(k, v) for k, v in table.items() if isinstance(v, Mapping)]
    if path and (plain or not nested):
        lines.append("")
        lines.append("[" + ".".join(_key(p) for p in path) + "]")
    for k, v in plain:
        lines.append(f"{_key(str(k))} = {_value(v)}")
    for k, v in nested:
        _table(v, path + [str(k)], lines)


def _looks_like_toml(text: str) -> bool:
    return "\n" in text or "=" in text or text.lstrip().startswith("[")


def config_source(config: ConfigLike) -> Tuple[Optional[str], Optional[str], str]:
    """(TOML text, file path, name for messages) of a config given any supported way.

    None is the built-in quick run; a dict is written as TOML; a `str` is a path when a file
    of that name exists or it does not look like TOML, else TOML text.
    """
    if config is None:
        return _dustdem.DEFAULT_CONFIG, None, "built-in omni_quick"
    if isinstance(config, Mapping):
        return to_toml(config), None, "<dict config>"
    if isinstance(config, os.PathLike):
        return None, os.fspath(config), os.fspath(config)
    if isinstance(config, str):
        if Path(config).is_file() or not _looks_like_toml(config):
            return None, config, config
        return config, None, "<TOML string>"
    raise TypeError(
        f"config must be a path, a TOML string or a dict, not {type(config).__name__}"
    )


def check_config(config: ConfigLike) -> str:
    """Validates a config as `dustdem run` would; raises ConfigError on a problem.

    Returns the output directory the config names (`[output] dir`).
    """
    text, path, name = config_source(config)
    return _dustdem.check_config(text=text, path=path, name=name)
