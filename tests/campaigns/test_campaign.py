"""A hostile-input campaign (issue 18): every key of the scenario format and the arguments of
every command, given NaN, inf, huge, tiny, negative, empty, wrong types and unknown keys.

Specification: whatever the input, cellsim answers with exit 0, 1 or 2 and at most one line
on standard error for a refusal: never a traceback, never more than a minute of CPU, never
more memory than the campaign's address-space limit (the test lowers it while it runs).
Issue 31 extends it to the inputs of the second milestone: cell files, robot folders (DH and
URDF), URDFs, TP programs and catalogues, each generated from a valid one by hostile values
at every key (or line) and run through ``cellsim check`` (``run --select`` for catalogues).
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
from support import DATA, ROOT
from support.cell_files import CELL, make_cell
from support.robots import DH_ROBOT, DH_SCENARIO
from support.scenarios import CAMPAIGN_BASE, TP_SCENARIO
from support.toml_values import toml_value

from sim.cli import main

#: CPU-time limit of one command, s, and the address-space limit of the campaign, bytes.
LIMIT_S = 60
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


_toml_value = toml_value  # the shared writer (tests/support/toml_values.py)


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
LEAVES = _leaves(tomllib.loads(CAMPAIGN_BASE))


@contextmanager
def bounded(seconds: int = LIMIT_S, extra: int = EXTRA_MEMORY):
    """Fail after ``seconds`` of this process's CPU time (not wall time: a loaded machine
    must not fail the campaign); cap the address space at the current use plus ``extra``
    (both restored afterwards)."""
    def over(*_: Any) -> None:
        raise TimeoutError(f"took more than {seconds} s of CPU")

    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    with open("/proc/self/statm") as f:
        used = int(f.read().split()[0]) * resource.getpagesize()
    cap = used + extra if hard == resource.RLIM_INFINITY else min(hard, used + extra)
    old = signal.signal(signal.SIGPROF, over)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
    signal.setitimer(signal.ITIMER_PROF, float(seconds))
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0.0)
        signal.signal(signal.SIGPROF, old)
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
    doc = tomllib.loads(CAMPAIGN_BASE)
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
    base.write_text(CAMPAIGN_BASE)
    values = [x for flag, value in extra for x in ((flag,) if flag in (
        "--select", "--strict", "--json", "--keep-runs", "--plots") else (flag, value))]
    with bounded():
        _answer(_argv(command, values, base, tmp_path), capsys)


def test_the_campaign_starts_from_a_valid_scenario(tmp_path, capsys):
    """The base passes `cellsim check` and runs: hostile values are the only reason a mutant
    is refused."""
    base = tmp_path / "s.toml"
    base.write_text(CAMPAIGN_BASE)
    assert _answer(["check", str(base)], capsys) == 0
    assert _answer(["run", str(base), "--out", str(tmp_path / "r"), "--no-video", "--no-plots",
                    "--quiet"], capsys) == 0


# ------------------------------------------------------------------ the second milestone's
# inputs (issue 31): every key of a valid file, or every line of a program, made hostile

def _mutated_toml(text: str, path: tuple, value: Any, unknown: bool) -> str | None:
    """``text`` (a TOML document) with the leaf at ``path`` set to ``value`` (and a misspelt
    key beside it), or None where TOML cannot hold the value."""
    doc = tomllib.loads(text)
    _set(doc, path, value)
    if unknown:
        _set(doc, (*path[:-1], f"{path[-1]}_typo"), 1.0)
    try:
        return dump_toml(doc)
    except TypeError:
        return None


@pytest.fixture(scope="module")
def cell_root(tmp_path_factory):
    """The user cell of test_cell_files (concave bracket from an STL, decomposed once)."""
    root = tmp_path_factory.mktemp("campaign_cell")
    make_cell(root)
    return root


@pytest.fixture(scope="module")
def robot_root(tmp_path_factory):
    """A DH robot folder and a URDF robot folder (a copy of the shipped KR 6 R900-2), each
    with a scenario that moves it."""
    import shutil

    root = tmp_path_factory.mktemp("campaign_robots")
    (root / "robots" / "dh_arm").mkdir(parents=True)
    (root / "robots" / "dh_arm" / "robot.toml").write_text(DH_ROBOT)
    (root / "dh.toml").write_text(DH_SCENARIO)
    src = ROOT / "models" / "kuka_kr6r900_2"
    shutil.copytree(src, root / "robots" / "kr6", ignore=shutil.ignore_patterns("*.py"))
    toml = root / "robots" / "kr6" / "robot.toml"  # a user's robot takes a name of its own
    toml.write_text(toml.read_text().replace('name = "kr6r900_2"\n', 'name = "my_kr6"\n', 1))
    (root / "urdf.toml").write_text(DH_SCENARIO.replace("robots/dh_arm", "robots/kr6").replace(
        "[[0, 0, 0, 0, 30, 0], [20, 10, -20, 10, 40, 20], [30, 20, -30, 0, 60, 0]]",
        "[[0, -90, 90, 0, 30, 0], [10, -80, 80, 10, 40, 20], [20, -70, 70, 0, 60, 0]]").replace(
        "to_mm = [450, 150, 300]", "to_mm = [500, 100, 400]"))
    return root


def _cell_case(root: Path, data: st.DataObject) -> list[str] | None:
    path = data.draw(st.sampled_from(_leaves(tomllib.loads(CELL))), label="cell key")
    text = _mutated_toml(CELL, path, data.draw(HOSTILE, label="value"),
                         data.draw(st.booleans(), label="typo"))
    if text is None:
        return None
    (root / "cells" / "user_cell.toml").write_text(text)
    return ["check", str(root / "user_weld.toml")]


def _robot_case(root: Path, data: st.DataObject) -> list[str] | None:
    which = data.draw(st.sampled_from(["dh_arm", "kr6"]), label="robot folder")
    folder = root / "robots" / which
    original = folder / "robot.toml.orig"
    if not original.exists():
        original.write_text((folder / "robot.toml").read_text())
    base = original.read_text()
    path = data.draw(st.sampled_from(_leaves(tomllib.loads(base))), label="robot key")
    text = _mutated_toml(base, path, data.draw(HOSTILE, label="value"),
                         data.draw(st.booleans(), label="typo"))
    if text is None:
        return None
    (folder / "robot.toml").write_text(text)
    return ["check", str(root / ("dh.toml" if which == "dh_arm" else "urdf.toml"))]


_NUMBER = r"-?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?"


def _urdf_case(root: Path, data: st.DataObject) -> list[str] | None:
    """A number in the URDF (origins, axes, limits, masses, inertias) made hostile."""
    import re

    folder = root / "robots" / "kr6"
    original = folder / "kr6r900_2.urdf.orig"
    if not original.exists():
        original.write_text((folder / "kr6r900_2.urdf").read_text())
    text = original.read_text()
    spots = [m.span() for m in re.finditer(_NUMBER, text)]
    a, b = data.draw(st.sampled_from(spots), label="number")
    value = data.draw(st.sampled_from(["nan", "inf", "-inf", "1e308", "-1e308", "1e-308", "0",
                                       "-0", "-1", "1e9", "", "x", "1 2", "0x10"]),
                      label="value")
    (folder / "kr6r900_2.urdf").write_text(text[:a] + value + text[b:])
    return ["check", str(root / "urdf.toml")]


def _program_case(root: Path, data: st.DataObject) -> list[str] | None:
    """weld1.ls with a line deleted, doubled or replaced, or a number made hostile."""
    import re

    lines = (DATA / "weld1.ls").read_text().splitlines()
    k = data.draw(st.integers(0, len(lines) - 1), label="line")
    how = data.draw(st.sampled_from(["delete", "double", "garbage", "number"]), label="edit")
    if how == "delete":
        del lines[k]
    elif how == "double":
        lines.insert(k, lines[k])
    elif how == "garbage":
        lines[k] = data.draw(st.text(max_size=40), label="text")
    else:
        spots = [m.span() for m in re.finditer(_NUMBER, lines[k])]
        if not spots:
            return None
        a, b = data.draw(st.sampled_from(spots), label="number")
        value = data.draw(st.sampled_from(["nan", "1e308", "-1e308", "1e-300", "0", "-1",
                                           "99999999999999999999", "1e300"]), label="value")
        lines[k] = lines[k][:a] + value + lines[k][b:]
    (root / "weld1.ls").write_text("\n".join(lines) + "\n")
    (root / "tp.toml").write_text(TP_SCENARIO)
    return ["check", str(root / "tp.toml")]


def _small_catalog() -> str:
    """The starter catalogue's first two motors and two reducers, as TOML."""
    doc = tomllib.loads((ROOT / "models" / "catalog" /
                         "starter.toml").read_text())
    doc = {"catalog": doc["catalog"], "motors": doc["motors"][:2],
           "reducers": doc["reducers"][:2]}
    for entry in doc["motors"] + doc["reducers"]:
        entry["source"] = "campaign"
    return dump_toml(doc)


def _catalog_case(root: Path, data: st.DataObject) -> list[str] | None:
    base = _small_catalog()
    path = data.draw(st.sampled_from(_leaves(tomllib.loads(base))), label="catalogue key")
    text = _mutated_toml(base, path, data.draw(HOSTILE, label="value"),
                         data.draw(st.booleans(), label="typo"))
    if text is None:
        return None
    (root / "cat.toml").write_text(text)
    (root / "s.toml").write_text(CAMPAIGN_BASE)
    return ["run", str(root / "s.toml"), "--out", str(root / "run"), "--no-video", "--no-plots",
            "--quiet", "--select", "--catalog", str(root / "cat.toml")]


CASES = {"cell": _cell_case, "robot": _robot_case, "urdf": _urdf_case,
         "program": _program_case, "catalog": _catalog_case}


def _input_campaign(kind: str, data: st.DataObject, cell_root: Path, robot_root: Path,
                    tmp: Path, capsys) -> None:
    root = {"cell": cell_root, "robot": robot_root, "urdf": robot_root}.get(kind, tmp)
    try:
        argv = CASES[kind](root, data)
        if argv is None:
            return
        with bounded():
            _answer(argv, capsys)
    finally:  # the shared folders back as they were for the next mutant
        (cell_root / "cells" / "user_cell.toml").write_text(CELL)
        for orig in robot_root.glob("robots/*/*.orig"):
            orig.with_suffix("").write_text(orig.read_text())


@pytest.mark.parametrize("kind", sorted(CASES))
@settings(max_examples=2, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(data=st.data())
def test_every_new_input_with_hostile_values(kind, data, cell_root, robot_root, tmp_path,
                                             capsys, monkeypatch):
    """The fast share: two generated mutants of each kind of input."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("XDG_CACHE_HOME", str(robot_root / "cache"))
    _input_campaign(kind, data, cell_root, robot_root, tmp_path, capsys)


@pytest.mark.slow
@pytest.mark.parametrize("kind", sorted(CASES))
@settings(max_examples=40, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(data=st.data())
def test_every_new_input_with_hostile_values_many(kind, data, cell_root, robot_root, tmp_path,
                                                  capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("XDG_CACHE_HOME", str(robot_root / "cache"))
    _input_campaign(kind, data, cell_root, robot_root, tmp_path, capsys)


def test_the_new_inputs_start_valid(cell_root, robot_root, tmp_path, capsys, monkeypatch):
    """Each base passes: hostile values are the only reason a mutant is refused."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(robot_root / "cache"))
    assert _answer(["check", str(cell_root / "user_weld.toml")], capsys) == 0
    assert _answer(["check", str(robot_root / "dh.toml")], capsys) == 0
    assert _answer(["check", str(robot_root / "urdf.toml")], capsys) == 0
    (tmp_path / "weld1.ls").write_text((DATA / "weld1.ls").read_text())
    (tmp_path / "tp.toml").write_text(TP_SCENARIO)
    assert _answer(["check", str(tmp_path / "tp.toml")], capsys) == 0
    (tmp_path / "cat.toml").write_text(_small_catalog())
    (tmp_path / "s.toml").write_text(CAMPAIGN_BASE)
    assert _answer(["run", str(tmp_path / "s.toml"), "--out", str(tmp_path / "run"),
                    "--no-video", "--no-plots", "--quiet", "--select", "--catalog",
                    str(tmp_path / "cat.toml")], capsys) in (0, 1)
