"""A hostile-input campaign (issue 18): every key of the scenario format and the arguments of
every command, given NaN, inf, huge, tiny, negative, empty, wrong types and unknown keys.

Specification: whatever the input, cellsim answers with exit 0, 1 or 2 and at most one line
on standard error for a refusal: never a traceback, never more than 20 s, never more memory
than the campaign's address-space limit (the test lowers it while it runs).
"""

from __future__ import annotations

import math
import resource
import signal
import tomllib
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sim.cli import main

BASE = """name = "campaign"
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

#: Wall-clock limit of one command, s, and the address-space limit of the campaign, bytes.
LIMIT_S = 20
EXTRA_MEMORY = 6 * 1024**3


def _leaves(node: Any, path: tuple = ()) -> list[tuple]:
    """Key paths of every leaf value (and every list item) of a TOML document."""
    out = []
    if isinstance(node, dict):
        for k, v in node.items():
            out += _leaves(v, (*path, k))
    elif isinstance(node, list) and node and all(isinstance(x, dict) for x in node):
        for i, v in enumerate(node):
            out += _leaves(v, (*path, i))
    else:
        out.append(path)
    return out


def _set(doc: Any, path: tuple, value: Any) -> None:
    for p in path[:-1]:
        doc = doc[p]
    doc[path[-1]] = value


def _toml_value(v: Any) -> str:
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
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(v)


def dump_toml(doc: dict) -> str:
    """A TOML writer for the scenario format's shape (tables, arrays of tables, values)."""
    lines: list[str] = []
    scalars = {k: v for k, v in doc.items()
               if not isinstance(v, dict) and not (isinstance(v, list) and v
                                                   and all(isinstance(x, dict) for x in v))}
    for k, v in scalars.items():
        lines.append(f"{k} = {_toml_value(v)}")
    for k, v in doc.items():
        if k in scalars:
            continue
        if isinstance(v, dict):
            nested = {kk: vv for kk, vv in v.items() if isinstance(vv, dict)}
            lines.append(f"\n[{k}]")
            lines += [f"{kk} = {_toml_value(vv)}" for kk, vv in v.items() if kk not in nested]
            for kk, vv in nested.items():
                lines.append(f"\n[{k}.{kk}]")
                lines += [f"{a} = {_toml_value(b)}" for a, b in vv.items()]
        else:
            for item in v:
                lines.append(f"\n[[{k}]]")
                lines += [f"{a} = {_toml_value(b)}" for a, b in item.items()]
    return "\n".join(lines) + "\n"


HOSTILE = st.one_of(
    st.sampled_from([math.nan, math.inf, -math.inf, 1e300, -1e300, 1e-300, 0.0, -1.0, 1e9,
                     1e-9, 0, -1, 10**12, "", "x" * 500, "..", ".", "/", "nan", True, [], [[]],
                     [math.nan], [1e300] * 6, [0.0] * 6, {}]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(10**15), max_value=10**15),
    st.text(max_size=20),
    st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=8),
)
LEAVES = _leaves(tomllib.loads(BASE))


@contextmanager
def bounded(seconds: int = LIMIT_S, extra: int = EXTRA_MEMORY):
    """Fail after ``seconds`` of wall time; cap the address space at the current use plus
    ``extra`` (restored afterwards)."""
    def alarm(*_: Any) -> None:
        raise TimeoutError(f"took more than {seconds} s")

    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    with open("/proc/self/statm") as f:
        used = int(f.read().split()[0]) * resource.getpagesize()
    cap = used + extra if hard == resource.RLIM_INFINITY else min(hard, used + extra)
    old = signal.signal(signal.SIGALRM, alarm)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


def _answer(argv: list[str], capsys) -> int:
    """Run a command; its exit code (argparse's own refusals included)."""
    try:
        rc = main(argv)
    except SystemExit as exc:  # argparse: usage error
        rc = int(exc.code or 0)
    err = capsys.readouterr().err
    assert "Traceback" not in err, err
    assert rc in (0, 1, 2), (argv, rc, err)
    if rc == 2:
        assert err.strip(), argv
    return rc


@pytest.mark.slow
@settings(max_examples=60, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(path=st.sampled_from(LEAVES), value=HOSTILE, unknown=st.booleans())
def test_every_scenario_key_with_hostile_values(tmp_path, capsys, monkeypatch, path, value,
                                                unknown):
    monkeypatch.chdir(tmp_path)
    doc = tomllib.loads(BASE)
    _set(doc, path, value)
    if unknown:  # a misspelt key beside it
        _set(doc, (*path[:-1], f"{path[-1]}_typo"), 1.0)
    scenario = tmp_path / "s.toml"
    try:
        scenario.write_text(dump_toml(doc))
    except TypeError:
        return
    with bounded():
        _answer(["check", str(scenario)], capsys)


def _argv(draw_command: str, values: list[str], base: Path, out: Path) -> list[str]:
    options = {
        "list": [],
        "plan": [str(base), "--json"],
        "ik": ["lrmate100ib", "660", "0", "5", "--euler-zyx-deg", "0", "30", "0"],
        "workspace": ["lrmate100ib", "--out", str(out / "w.png")],
        "check": [str(base)],
        "run": [str(base), "--out", str(out / "run"), "--no-video", "--no-plots", "--quiet"],
        "size": [str(base), "--out", str(out / "sweep"), "--workers", "1", "--quiet"],
        "render": [str(out / "missing-run")],
    }[draw_command]
    return [draw_command, *options, *values]


FLAGS = ["--payload", "--speed-scale", "--workers", "--fps", "--width", "--height", "--camera",
         "--out", "--catalog", "--life-h", "--dwell-s", "--rank", "--inertia-ratio-max",
         "--euler-zyx-deg", "--gl", "--select", "--strict", "--json", "--engine", "--address",
         "--backend", "--keep-runs", "--plots"]
VALUES = st.sampled_from(["nan", "inf", "-inf", "1e308", "-1", "0", "1e-300", "", "x" * 300,
                          "..", ".", "/", "0:1e308:1e-300", "1,2,,3", "-0", "999999999",
                          "egl", "osmesa", "mass", "overview", "/dev/null", "1:0:1", "ray",
                          "127.0.0.1:1", "auto"])


@pytest.mark.slow
@settings(max_examples=60, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(command=st.sampled_from(["list", "plan", "ik", "workspace", "check", "run", "size",
                                "render"]),
       extra=st.lists(st.tuples(st.sampled_from(FLAGS), VALUES), max_size=3))
def test_every_command_with_hostile_arguments(tmp_path, capsys, monkeypatch, command, extra):
    monkeypatch.chdir(tmp_path)  # relative --out values land here, never in the checkout
    base = tmp_path / "s.toml"
    base.write_text(BASE)
    values = [x for flag, value in extra for x in ((flag,) if flag in (
        "--select", "--strict", "--json", "--keep-runs", "--plots") else (flag, value))]
    with bounded():
        _answer(_argv(command, values, base, tmp_path), capsys)


def test_the_campaign_starts_from_a_valid_scenario(tmp_path, capsys):
    """The base passes `cellsim check` and runs: hostile values are the only reason a mutant
    is refused."""
    base = tmp_path / "s.toml"
    base.write_text(BASE)
    assert _answer(["check", str(base)], capsys) == 0
    assert _answer(["run", str(base), "--out", str(tmp_path / "r"), "--no-video", "--no-plots",
                    "--quiet"], capsys) == 0
