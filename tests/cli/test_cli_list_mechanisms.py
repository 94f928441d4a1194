"""`cellsim list` shows the shipped mechanisms (issue 28): every mechanism file under
``models/positioners|turntables|tracks/*/mechanism.toml`` appears once with its kind, axis
count, rated payload and description, and one line of its axes with their ranges and speeds,
each number as the FILE gives it (read here with tomllib, never through cellsim's reader);
``cellsim list --cell`` names the cell's mechanisms, their axes and what they carry."""

from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sim.cli import main

ROOT = Path(__file__).resolve().parents[2]
FOLDERS = ("positioners", "turntables", "tracks")
#: The listing prints 6 significant digits.
REL = 6e-6

_AXIS = re.compile(r"^(?P<name>\S+) (?P<kind>revolute|prismatic) (?P<lo>\S+)\.\.(?P<hi>\S+) "
                   r"(?P<unit>deg|mm), (?P<speed>\S+) (?P=unit)/s$")


def _files() -> list[Path]:
    return [p for f in FOLDERS for p in sorted((ROOT / "models" / f).glob("*/mechanism.toml"))]


def _expected(path: Path) -> dict:
    """What the listing must say of a mechanism, from its file's own keys (the name defaults
    to the folder's, the payload to 0: docs/mechanism-format.md)."""
    doc = tomllib.loads(path.read_text())
    axes = []
    for a in doc["axes"]:
        unit = "deg" if a["kind"] == "revolute" else "mm"
        lo, hi = a[f"range_{unit}"]
        axes.append({"name": a["name"], "kind": a["kind"], "unit": unit, "lo": float(lo),
                     "hi": float(hi), "speed": float(a[f"max_speed_{unit}_s"])})
    return {"name": doc.get("name", path.parent.name), "kind": doc["kind"],
            "payload": float(doc.get("payload_kg", 0.0)),
            "description": doc.get("description", ""), "axes": axes}


def _block(out: str) -> str:
    return out.split("mechanisms:\n", 1)[1].split("cells:\n", 1)[0]


def _parse(block: str) -> dict[str, dict]:
    """The listing's mechanisms block, parsed: name -> head fields and axes."""
    lines = block.splitlines()
    out: dict[str, dict] = {}
    for head, axes in zip(lines[::2], lines[1::2], strict=True):
        m = re.match(r"^  (\S+) +(\S+) +(\d+) ax[ie]s, payload (\S+) kg  (.*)$", head)
        assert m, head
        assert axes.startswith("      axes: "), axes
        parsed = [_AXIS.match(a) for a in axes.removeprefix("      axes: ").split("; ")]
        assert all(parsed), axes
        out[m[1]] = {"kind": m[2], "n": int(m[3]), "payload": float(m[4]),
                     "description": m[5],
                     "axes": [{"name": a["name"], "kind": a["kind"], "unit": a["unit"],
                               "lo": float(a["lo"]), "hi": float(a["hi"]),
                               "speed": float(a["speed"])} for a in parsed if a]}
    return out


def _close(a: float, b: float) -> bool:
    return math.isclose(a, b, rel_tol=REL, abs_tol=1e-9)


def _mismatches(shown: dict, want: dict) -> list[str]:
    """The oracle: every number and word of the listing against the file's."""
    bad = [k for k in ("kind", "description") if shown[k] != want[k]]
    if shown["n"] != len(want["axes"]):
        bad.append("n")
    if not _close(shown["payload"], want["payload"]):
        bad.append("payload")
    if len(shown["axes"]) != len(want["axes"]):
        return bad + ["axes"]
    for s, w in zip(shown["axes"], want["axes"], strict=True):
        bad += [f"{w['name']}.{k}" for k in ("name", "kind", "unit") if s[k] != w[k]]
        bad += [f"{w['name']}.{k}" for k in ("lo", "hi", "speed") if not _close(s[k], w[k])]
    return bad


def test_every_shipped_mechanism_is_listed_with_its_files_numbers(capsys):
    files = _files()
    assert len(files) >= 3  # the positioner, the turntable, the track
    assert main(["list"]) == 0
    shown = _parse(_block(capsys.readouterr().out))
    wanted = {w["name"]: w for w in map(_expected, files)}
    assert set(shown) == set(wanted)
    for name, want in wanted.items():
        assert _mismatches(shown[name], want) == [], name
    # a track's axis is in mm, never deg
    tracks = [w for w in wanted.values() if w["kind"] == "track"]
    assert tracks and all(shown[w["name"]]["axes"][0]["unit"] == "mm" for w in tracks)


def test_the_oracle_catches_a_planted_fault(capsys):
    """A file whose range, speed or payload is 0.1 % off fails the comparison."""
    assert main(["list"]) == 0
    shown = _parse(_block(capsys.readouterr().out))
    want = _expected(_files()[0])
    for key in ("lo", "hi", "speed"):
        bad = {**want, "axes": [dict(want["axes"][0], **{key: want["axes"][0][key] * 1.001
                                                       + 1e-3})] + want["axes"][1:]}
        assert _mismatches(shown[want["name"]], bad) != []
    assert _mismatches(shown[want["name"]], {**want, "payload": want["payload"] + 1}) != []


_CELL = """
name = "gen_cell"
tool = "mig_torch"
[robot]
model = "lrmate200ic5l"
{robot_on}
[[mechanisms]]
name = "{mech}"
model = "{model}"
pos_mm = [{x}, {y}, 0]
{objects}
"""

_OBJECT = """
[[objects]]
name = "{name}"
shape = "box"
size_mm = [100, 100, 20]
pos_mm = [0, 0, 10]
role = "workpiece"
on = "{mech}"
"""


@settings(max_examples=8, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(model=st.sampled_from(["motopos_d500", "turntable_500", "floor_track_4m"]),
       mech=st.from_regex(r"m[a-z]{1,6}", fullmatch=True),
       n_objects=st.integers(0, 2), x=st.floats(1500, 3000), y=st.floats(-500, 500))
def test_list_cell_names_its_mechanisms_axes_and_load(tmp_path_factory, capsys, model, mech,
                                                      n_objects, x, y):
    """A generated cell with a shipped mechanism: the listing names it, its model, its axes
    as ``<mechanism>_<axis>`` (the axes of the model's file) and what it carries."""
    tmp = tmp_path_factory.mktemp("cell")
    path = next(p for p in _files() if _expected(p)["name"] == model)
    want = _expected(path)
    track = want["kind"] == "track"
    objects = [] if track else [f"part{k}" for k in range(n_objects)]
    cell = tmp / "cell.toml"
    cell.write_text(_CELL.format(
        robot_on=f'on = "{mech}"' if track else "", mech=mech, model=model, x=x, y=y,
        objects="".join(_OBJECT.format(name=o, mech=mech) for o in objects)))
    capsys.readouterr()
    assert main(["list", "--cell", str(cell)]) == 0
    out = capsys.readouterr().out
    line = next(ln.strip() for ln in out.splitlines() if ln.strip().startswith("mechanisms:"))
    axes = ", ".join(f"{mech}_{a['name']}" for a in want["axes"])
    carries = ["robot"] if track else objects
    tail = f"; carries {', '.join(carries)}" if carries else ""
    assert line == f"mechanisms: {mech} ({model}: {axes}{tail})"
    objects_line = next(ln.strip() for ln in out.splitlines() if "objects:" in ln)
    # the mechanism's own solids are not the cell's objects
    assert objects_line == f"objects: {', '.join(objects)}".rstrip()
