"""Scenario files for tests: written from keyword arguments instead of TOML copied between files,
and the scenarios several test files share.

:func:`scenario_text` turns Python values into a scenario file's TOML (top-level keys, tables
such as ``simulation`` and ``drives``, arrays of tables such as ``actions`` and ``phases``);
:func:`joint_phase` is the joint move most tests start with; :func:`write_scenario` writes the
file. The text is parsed by cellsim's own loader, so a test states only what it varies::

    text = scenario_text("lrmate200ic5l", [joint_phase(JOINTS)], cell="weld_table",
                         tool="mig_torch", payload_kg=2.0)
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any


def joint_phase(joints_deg: Sequence[Sequence[float]], *, name: str = "move",
                planner: str = "434", time_s: Sequence[float] | None = None,
                durations_s: Sequence[float] | None = None, **keys: Any) -> dict[str, Any]:
    """A joint phase through ``joints_deg`` (one row per knot): at ``time_s``, or after the
    previous phase over ``durations_s``; by default one second per segment from t = 0."""
    phase: dict[str, Any] = {"name": name, "planner": planner}
    if durations_s is not None:
        phase["durations_s"] = list(durations_s)
    else:
        phase["time_s"] = (list(time_s) if time_s is not None
                           else [float(k) for k in range(len(joints_deg))])
    phase["joints_deg"] = [list(row) for row in joints_deg]
    phase.update(keys)
    return phase


def scenario_text(robot: str, phases: Sequence[Mapping[str, Any]], *, name: str = "t",
                  description: str = "a test scenario", **keys: Any) -> str:
    """A scenario file's TOML: ``name``, ``description``, ``robot``, the other top-level keys
    in the order given (a mapping becomes a table, ``[simulation]``; a mapping of mappings,
    tables ``[drives.j2]``; a list of mappings, an array of tables ``[[actions]]``), then
    ``[[phases]]``."""
    doc: dict[str, Any] = {"name": name, "description": description, "robot": robot, **keys,
                           "phases": list(phases)}
    return _toml(doc)


def write_scenario(folder: Path, robot: str, phases: Sequence[Mapping[str, Any]], *,
                   filename: str = "s.toml", **keys: Any) -> Path:
    """:func:`scenario_text` written to ``folder / filename``; returns the path."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / filename
    path.write_text(scenario_text(robot, phases, **keys))
    return path


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ("nan" if math.isnan(v) else
                                                 ("inf" if v > 0 else "-inf"))
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, Sequence):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    raise TypeError(f"no TOML value for {v!r}")


def _is_table_array(v: Any) -> bool:
    return (isinstance(v, Sequence) and not isinstance(v, str) and bool(v)
            and all(isinstance(x, Mapping) for x in v))


def _toml(doc: Mapping[str, Any]) -> str:
    return "\n".join(_lines(doc)).strip("\n") + "\n"


def _lines(doc: Mapping[str, Any], prefix: str = "") -> list[str]:
    """``doc``'s keys: its values first, then its tables, then its arrays of tables (named
    below ``prefix``: ``phases.`` for a phase's ``[phases.weave]``)."""
    lines = [f"{k} = {_value(v)}" for k, v in doc.items()
             if not isinstance(v, Mapping) and not _is_table_array(v)]
    for k, v in doc.items():
        if isinstance(v, Mapping) and v:
            head = f"{prefix}{k}"
            if not all(isinstance(x, Mapping) for x in v.values()):  # [drives.j2] alone
                lines += ["", f"[{head}]"]
            lines += _lines(v, prefix=head + ".")
    for k, v in doc.items():
        if _is_table_array(v):
            for item in v:
                lines += ["", f"[[{prefix}{k}]]", *_lines(item, prefix=f"{prefix}{k}.")]
    return lines


#: A FANUC TP program run as a scenario: ``weld1.ls`` (copy :data:`support.DATA`'s beside the
#: file) on the LR Mate 200iC/5L with the MIG torch.
TP_SCENARIO = """
name = "tp_weld1"
description = "a TP program"
robot = "lrmate200ic5l"
tool = "mig_torch"
program = "weld1.ls"
"""


#: The hostile-input campaign's base scenario (tests/campaigns/test_campaign.py): every kind of
#: key of the format (tables, drives, actions, each kind of phase) on the weld table, each of
#: which the campaign replaces by hostile values.
CAMPAIGN_BASE = """name = "campaign"
description = "base scenario of the hostile-input campaign"
robot = "lrmate200ic5l"
cell = "weld_table"
tool = "mig_torch"
payload_kg = 0.5

[simulation]
timestep_s = 0.001
settle_s = 0.1
tracking_tolerance_deg = 0.1
clearance_mm = 5.0

[video]
width = 160
height = 120
fps = 10.0

[sizing]
life_h = 20000.0
dwell_s = 1.0

[drives.j2]
gear_ratio = 120.0
efficiency = 0.8

[[actions]]
action = "arc_on"
phase = "across"

[[actions]]
action = "arc_off"
time_s = 3.5

[[phases]]
name = "start"
planner = "434"
time_s = [0.0, 0.5, 1.0]
joints_deg = [[0.0, 0.0, 0.0, 0.0, -90.0, 0.0], [0.0, 5.0, -5.0, 0.0, -90.0, 0.0], [0.0, 10.0, -10.0, 0.0, -90.0, 0.0]]

[[phases]]
name = "above"
planner = "546"
durations_s = [1.0]
to_mm = [330.0, 120.0, -60.0]
euler_zyx_deg = [0.0, 0.0, 180.0]

[[phases]]
name = "across"
kind = "linear"
to_mm = [330.0, 180.0, -60.0]
speed_mm_s = 50.0
sample_period_s = 0.02

[[phases]]
name = "rest"
kind = "hold"
duration_s = 0.3
"""
