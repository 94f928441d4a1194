"""One TOML value writer for the tests that write input files from generated numbers (cell,
scenario and mechanism files): booleans, integers, floats (``nan``, ``inf`` spelled as TOML
does; finite ones by ``repr``, which round-trips exactly), strings (escaped), arrays and inline
tables. The files' block structure (``[table]``, ``[[array]]``) is each writer's own."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any


def toml_value(v: Any) -> str:
    """``v`` as a TOML value (an inline table for a mapping)."""
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
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    if isinstance(v, Mapping):
        return "{" + ", ".join(f"{k} = {toml_value(x)}" for k, x in v.items()) + "}"
    if isinstance(v, Sequence):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    raise TypeError(f"no TOML value for {v!r}")
