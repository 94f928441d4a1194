"""Hostile numbers in a user's data files (issue 31, "nothing lost on hostile inputs").

A specification of the one rule every data reader applies to a number
(:class:`sim.core.tomlschema.Quantity`), checked on every numeric key of four kinds of file:
a robot folder (``robot.toml``: a DH table, a seeds' family, a URDF with ``[[links]]``), a bare
URDF (origins, axes, limits, inertials), a motor and reducer catalogue, and a cell file's
solids. The keys are taken from a valid file (so a key added to it is covered), each key's
range from its reader (:func:`sim.core.tomlschema.quantity_at` for the TOML files,
:data:`sim.robots.kinematics.chain.URDF_QUANTITIES` for URDFs): a number without a declared range fails
:func:`test_every_numeric_key_of_the_valid_files_has_a_range`.

1. A value that is no number (a TOML boolean, a string), not finite (``nan``, ``inf``, an
   integer beyond the range of a float) or outside its key's physical range is refused:
   exit 2 and one line naming the file and the key (the entry, the joint or the link).
2. A value inside the range never makes cellsim fail inside (exit 3): the command takes it
   (exit 0, or 1 for a finding of ``cellsim check``) or refuses it for a reason of the domain
   in one line (a drive too weak to hold the arm, a robot base inside a fixture).
3. A catalogue of more motor x reducer pairs than the selection can check in bounded time
   and memory (:data:`sim.analysis.catalog.MAX_PAIRS`) is refused when it is read.

The commands run in this process (``sim.cli.main``): ``cellsim check`` on a small scenario
for robots and cells (it loads, generates and compiles the model), the catalogue's reader for
catalogue entries (``cellsim run --select`` loads the catalogue before anything runs: a
hostile entry is checked through it too). The fast share draws a few hostile values per kind
of file; the slow share (``-m slow``) draws many more, valid ones included. Work is bounded by
counts, not by time.
"""

from __future__ import annotations

import copy
import io
import json
import math
import shutil
import sys
import tomllib
import uuid
import xml.etree.ElementTree as ET
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sim.analysis.catalog import (
    MAX_PAIRS,
    MotorSpec,
    ReducerSpec,
    load_catalog,
    starter_catalog,
)
from sim.cells.cellfile import CellFileSpec, ObjectBlock, RobotBlock
from sim.cli import main
from sim.core.tomlschema import Quantity, format_loc, quantity_at
from sim.errors import CatalogError
from sim.robots.kinematics.chain import URDF_QUANTITIES, URDF_ZERO_IS_NONE
from sim.robots.robotfile import RobotFolderSpec

MODELS = Path(__file__).resolve().parents[2] / "models"

# ---------------------------------------------------------------------------- the valid files
#: A robot given by a DH table, with every key of robot.toml a DH robot takes but [[links]]
#: (the KUKA folder below has them): an LR Mate 200iC-like OPW arm.
DH_ROBOT = """name = "dh_arm"
description = "an OPW arm from its DH table"
[kinematics]
convention = "dh"
dh = [[75, -90, 330, 0], [300, 0, 0, -90], [75, -90, 0, 0], [0, 90, 320, 0], [0, -90, 0, 0],
      [0, 0, 80, 0]]
[joints]
range_deg = [[-170, 170], [-100, 140], [-150, 150], [-190, 190], [-120, 120], [-360, 360]]
home_deg = [0, 0, 0, 0, 30, 0]
max_speed_deg_s = [270, 270, 270, 450, 450, 720]
max_accel_deg_s2 = [1400, 2300, 5200, 40000, 43000, 210000]
[mass]
total_kg = 25
payload_kg = 2
[maker]
joints = ["J1", "J2", "J3", "J4", "J5", "J6"]
matrix = [[1, 0, 0, 0, 0, 0], [0, 1, 0, 0, 0, 0], [0, 1, 1, 0, 0, 0], [0, 0, 0, 1, 0, 0],
          [0, 0, 0, 0, 1, 0], [0, 0, 0, 0, 0, 1]]
""" + "".join(f"""
[[drives]]
gear_ratio = {r}
efficiency = 0.75
rotor_inertia_kg_m2 = {i}
rated_torque_nm = {t}
peak_torque_nm = {p}
max_speed_rpm = 6000
""" for r, i, t, p in [(120, 2e-5, 0.65, 2.4), (120, 4.5e-5, 1.3, 4.5), (120, 2e-5, 0.65, 2.4),
                       (75, 5e-6, 0.32, 1.0), (75, 5e-6, 0.32, 1.0), (48, 3e-6, 0.25, 0.8)])

#: A joint move near zero that every base robot makes (all inside their ranges).
MOVE = """
[[phases]]
name = "move"
planner = "434"
time_s = [0.0, 0.5]
joints_deg = [[0, {j2}, {j3}, 0, 30, 0], [5, {j2p}, {j3p}, 5, 35, 5]]
"""


def _scenario(robot: str, j2: float = 0.0, j3: float = 0.0) -> str:
    return (f'name = "dv"\ndescription = "hostile numbers"\nrobot = "{robot}"\n'
            + MOVE.format(j2=j2, j3=j3, j2p=j2 + 5, j3p=j3 - 5))


def _dh(root: Path) -> None:
    (root / "arm").mkdir()
    (root / "arm" / "robot.toml").write_text(DH_ROBOT)


def _family(root: Path) -> None:
    """The shipped LR Mate 200iC/5L folder (``[kinematics] family``, its own MJCF), under a
    name of its own (a shipped robot's name is refused for a user's folder)."""
    shutil.copytree(MODELS / "fanuc_lrmate200ic", root / "arm")
    _rename(root / "arm" / "robot.toml", "lrmate200ic5l")


def _kuka(root: Path) -> None:
    """The shipped KR 6 R900-2 folder (a URDF with [[links]] of mass, centre and inertia),
    its model generated (``mjcf`` left out) so the links' numbers reach MuJoCo."""
    shutil.copytree(MODELS / "kuka_kr6r900_2", root / "arm")
    toml = root / "arm" / "robot.toml"
    toml.write_text(toml.read_text().replace('mjcf = "kr6r900_2.xml"\n', ""))
    _rename(toml, "kr6r900_2")


def _rename(toml: Path, shipped: str) -> None:
    text = toml.read_text()
    assert text.count(f'name = "{shipped}"\n') == 1
    toml.write_text(text.replace(f'name = "{shipped}"\n', f'name = "my_{shipped}"\n'))


def _bare(root: Path) -> None:
    """A bare URDF with inertials, efforts and velocities (kroshu's KR 6 R900-2)."""
    shutil.copy(MODELS / "kuka_kr6r900_2" / "kr6_r900_2_kroshu.urdf", root / "arm.urdf")


#: The robot bases: name -> (writer of the case folder, the scenario's robot, the file whose
#: numbers are drawn, relative to the case folder, and J2 and J3 of the move's start, deg).
ROBOTS = {
    "dh": (_dh, "./arm", "arm/robot.toml", (0.0, 0.0)),
    "family": (_family, "./arm", "arm/robot.toml", (0.0, 0.0)),
    "urdf_folder": (_kuka, "./arm", "arm/robot.toml", (-90.0, 90.0)),
    "urdf_folder_urdf": (_kuka, "./arm", "arm/kr6r900_2.urdf", (-90.0, 90.0)),
    "bare_urdf": (_bare, "arm.urdf", "arm.urdf", (-90.0, 90.0)),
}

#: A cell with one solid of each shape, a ring and a part.
CELL = """name = "solids"
description = "one solid of each shape"
tool = "mig_torch"
[robot]
base_pos_mm = [0, 0, 0]
base_euler_zyx_deg = [0, 0, 0]
[[objects]]
name = "table"
shape = "box"
size_mm = [400, 400, 40]
pos_mm = [600, 0, 100]
euler_zyx_deg = [10, 0, 0]
friction = 0.8
color = [0.5, 0.5, 0.5]
[[objects]]
name = "drum"
shape = "cylinder"
radius_mm = 50
length_mm = 200
pos_mm = [0, 600, 200]
[[objects]]
name = "ball"
shape = "sphere"
radius_mm = 40
pos_mm = [0, -600, 200]
[[objects]]
name = "hoop"
shape = "ring"
radius_mm = 100
inner_radius_mm = 80
length_mm = 30
arc_deg = [0, 270]
segments = 24
pos_mm = [-600, 0, 200]
[[objects]]
name = "block"
shape = "box"
size_mm = [40, 40, 40]
pos_mm = [600, 0, 140]
role = "part"
mass_kg = 0.5
"""
CELL_SCENARIO = _scenario("lrmate200ic5l").replace('robot = "lrmate200ic5l"',
                                                   'robot = "lrmate200ic5l"\ncell = "cell.toml"')
#: Integer keys of a cell solid (counts, not quantities: their bounds are pydantic's).
COUNTS = {"segments"}

# ---------------------------------------------------------------------------- TOML as text


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) \
            else repr(v)
    if isinstance(v, (int, str)):
        return json.dumps(v) if isinstance(v, str) else str(v)
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return "{" + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()) + "}"


def dump_toml(doc: dict[str, Any], prefix: str = "") -> str:
    """A TOML document of plain tables, arrays of tables and values (what the bases hold)."""
    lines, tables, arrays = [], [], []
    for k, v in doc.items():
        if isinstance(v, dict) and prefix == "" or isinstance(v, dict) and v and all(
                isinstance(x, dict) for x in v.values()):
            tables.append((k, v))
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            arrays.append((k, v))
        else:
            lines.append(f"{k} = {_toml_value(v)}")
    for k, v in tables:
        lines += [f"[{prefix}{k}]", dump_toml(v, f"{prefix}{k}.")]
    for k, v in arrays:
        for x in v:
            lines += [f"[[{prefix}{k}]]", dump_toml(x, f"{prefix}{k}.")]
    return "\n".join(lines) + "\n"


def numeric_leaves(doc: Any, path: tuple = ()) -> list[tuple]:
    """The location of every number (not a boolean) in a parsed TOML document."""
    if isinstance(doc, dict):
        return [p for k, v in doc.items() for p in numeric_leaves(v, (*path, k))]
    if isinstance(doc, list):
        return [p for i, v in enumerate(doc) for p in numeric_leaves(v, (*path, i))]
    return [path] if isinstance(doc, (int, float)) and not isinstance(doc, bool) else []


def with_value(doc: dict[str, Any], path: tuple, value: Any) -> dict[str, Any]:
    out = copy.deepcopy(doc)
    node = out
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = value
    return out


# ---------------------------------------------------------------------------- the values
#: Values that are never a number cellsim takes, whatever the key.
NOT_NUMBERS = [True, False, "5", math.nan, math.inf, -math.inf, 10**400, -(10**400)]
#: Float limits, tried against every range.
LIMITS = [1e308, -1e308, 1e-308, 5e-324, -5e-324, -0.0, 0.0, -1.0, 1e300]


def hostile(q: Quantity | None) -> st.SearchStrategy[Any]:
    """Values the key must refuse: no number, not finite, or outside its range."""
    bad = st.sampled_from(NOT_NUMBERS)
    if q is None:
        return bad
    outside = [v for v in LIMITS if not q.lo <= v <= q.hi]
    return st.one_of(bad, st.sampled_from(outside),
                     st.floats(max_value=q.lo, exclude_max=True, allow_nan=False,
                               allow_infinity=False),
                     st.floats(min_value=q.hi, exclude_min=True, allow_nan=False,
                               allow_infinity=False))


def valid(q: Quantity, zero: bool = False) -> st.SearchStrategy[float]:
    """Values inside the range: its ends, numbers between, 0 where 0 means none."""
    ends = [q.lo, q.hi, *([0.0] if zero else [])]
    return st.one_of(st.sampled_from(ends), st.floats(q.lo, q.hi))


def is_hostile(q: Quantity | None, value: Any, zero: bool = False) -> bool:
    """Whether the specification says ``value`` must be refused for a key of quantity ``q``
    (None: a count, whose bounds are not drawn): computed here from the declared range, not
    by the reader's code (which the planted-fault test replaces)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return True
    if isinstance(value, float) and not math.isfinite(value) or abs(value) > sys.float_info.max:
        return True
    if q is None or zero and value == 0:
        return False
    return not q.lo <= float(value) <= q.hi


# ---------------------------------------------------------------------------- the oracle
def cli(argv: list[str]) -> tuple[int, list[str]]:
    """``cellsim ARGV`` in this process: its exit code and its stderr lines."""
    err = io.StringIO()
    with redirect_stderr(err), redirect_stdout(io.StringIO()):
        try:
            rc = main(argv)
        except SystemExit as exc:  # argparse's own refusals
            rc = int(exc.code or 0)
    return rc, [line for line in err.getvalue().splitlines() if line.strip()]


def assert_refused(rc: int, lines: list[str], file: str, *names: str) -> None:
    """Exit 2 and one line naming the file and every one of ``names`` (the key)."""
    assert rc == 2, (rc, lines)
    assert len(lines) == 1, lines
    assert file in lines[0], (file, lines[0])
    for name in names:
        assert name in lines[0], (name, lines[0])


def assert_taken(rc: int, lines: list[str]) -> None:
    """A valid value: taken (0, or 1 for findings), or refused for the domain in one line;
    never an internal fault."""
    assert rc in (0, 1, 2), (rc, lines)
    assert not any("Traceback" in line or "internal error" in line for line in lines), lines
    if rc == 2:
        assert len(lines) == 1, lines


@pytest.fixture(scope="module")
def scratch(tmp_path_factory, request):
    """A folder for the cases and cellsim's cache (generated models) for this module."""
    root = tmp_path_factory.mktemp("hostile")
    mp = pytest.MonkeyPatch()
    mp.setenv("XDG_CACHE_HOME", str(root / "cache"))
    request.addfinalizer(mp.undo)
    return root


def _case(scratch: Path) -> Path:
    folder = scratch / uuid.uuid4().hex[:12]
    folder.mkdir()
    return folder


# ---------------------------------------------------------------------------- robots
def _source(kind: str) -> Path | None:
    """The valid file whose numbers a robot case draws (None: :data:`DH_ROBOT`)."""
    kuka = MODELS / "kuka_kr6r900_2"
    return {"dh": None, "family": MODELS / "fanuc_lrmate200ic" / "robot.toml",
            "urdf_folder": kuka / "robot.toml", "urdf_folder_urdf": kuka / "kr6r900_2.urdf",
            "bare_urdf": kuka / "kr6_r900_2_kroshu.urdf"}[kind]


def _robot_leaves(kind: str) -> list[tuple]:
    source = _source(kind)
    if source is not None and source.suffix == ".urdf":
        return _urdf_leaves(source)
    return numeric_leaves(tomllib.loads(DH_ROBOT if source is None else source.read_text()))


def _urdf_leaves(path: Path) -> list[tuple]:
    """``(element index, attribute, value index)`` of every number the URDF reader takes:
    every joint's origin, a revolute joint's axis and limits, the inertial of every link a
    revolute joint moves."""
    root = ET.parse(path).getroot()
    elements = list(root.iter())
    moved = {j.find("child").get("link") for j in root.findall("joint")
             if j.get("type") == "revolute"}
    out = []
    for j in root.findall("joint"):
        parts = ["origin"] + (["axis", "limit"] if j.get("type") == "revolute" else [])
        for tag in parts:
            el = j.find(tag)
            if el is not None:
                out += _attr_leaves(elements, el, tag)
    for ln in root.findall("link"):
        inertial = ln.find("inertial")
        if ln.get("name") in moved and inertial is not None:
            for el in inertial:
                out += _attr_leaves(elements, el, el.tag)
    return out


def _attr_leaves(elements: list[ET.Element], el: ET.Element, tag: str) -> list[tuple]:
    return [(elements.index(el), attr, k) for attr, text in el.attrib.items()
            if (tag, attr) in URDF_QUANTITIES for k in range(len(text.split()))]


def _urdf_with(path: Path, leaf: tuple, value: Any) -> tuple[str, list[str]]:
    """The URDF text with one number replaced, and the names its message must hold."""
    root = ET.parse(path).getroot()
    elements = list(root.iter())
    index, attr, k = leaf
    el = elements[index]
    owner = next(e for e in root if el in list(e.iter()))
    vals = el.get(attr).split()
    vals[k] = _toml_value(value) if not isinstance(value, int) or isinstance(value, bool) \
        else str(value)
    el.set(attr, " ".join(vals))
    return ET.tostring(root, encoding="unicode"), [f"'{owner.get('name')}'", el.tag, attr]


def _urdf_quantity(path: Path, leaf: tuple) -> tuple[Quantity, bool]:
    el = list(ET.parse(path).getroot().iter())[leaf[0]]
    key = (el.tag, leaf[1])
    return URDF_QUANTITIES[key], key in URDF_ZERO_IS_NONE


def _robot_case(scratch: Path, kind: str, leaf: tuple, value: Any
                ) -> tuple[int, list[str], list[str], bool]:
    """Write the base robot with one number replaced and run ``cellsim check`` on it: the
    exit code, the stderr lines, the names the message must hold, whether the value is
    hostile."""
    write, robot, file, (j2, j3) = ROBOTS[kind]
    folder = _case(scratch)
    write(folder)
    target = folder / file
    if file.endswith(".urdf"):
        text, names = _urdf_with(target, leaf, value)
        q, zero = _urdf_quantity(target, leaf)
        target.write_text(text)
    else:
        doc = tomllib.loads(target.read_text())
        target.write_text(dump_toml(with_value(doc, leaf, value)))
        names, q, zero = [format_loc(leaf)], quantity_at(RobotFolderSpec, leaf), False
    (folder / "s.toml").write_text(_scenario(robot, j2, j3))
    rc, lines = cli(["check", str(folder / "s.toml")])
    return rc, lines, names, is_hostile(q, value, zero)


def _robot_quantity(kind: str, leaf: tuple) -> tuple[Quantity | None, bool]:
    """The quantity of a robot case's number, and whether 0 means none there."""
    source = _source(kind)
    if source is not None and source.suffix == ".urdf":
        return _urdf_quantity(source, leaf)
    return quantity_at(RobotFolderSpec, leaf), False


ROBOT_LEAVES = [(kind, leaf) for kind in ROBOTS for leaf in _robot_leaves(kind)]


@st.composite
def robot_hostile(draw):
    kind, leaf = draw(st.sampled_from(ROBOT_LEAVES))
    q, _ = _robot_quantity(kind, leaf)
    return kind, leaf, draw(hostile(q))


@st.composite
def robot_valid(draw):
    kind, leaf = draw(st.sampled_from(ROBOT_LEAVES))
    q, zero = _robot_quantity(kind, leaf)
    return kind, leaf, draw(valid(q, zero))


def check_robot(scratch: Path, kind: str, leaf: tuple, value: Any) -> None:
    """The specification (module docstring) for one number of a robot."""
    rc, lines, names, bad = _robot_case(scratch, kind, leaf, value)
    if bad:
        assert_refused(rc, lines, Path(ROBOTS[kind][2]).name, *names)
    else:
        assert_taken(rc, lines)


@settings(max_examples=12, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(case=robot_hostile())
def test_a_hostile_robot_number_is_one_line_naming_file_and_key(scratch, case):
    check_robot(scratch, *case)


@pytest.mark.slow
@settings(max_examples=150, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(case=st.one_of(robot_hostile(), robot_valid()))
def test_any_robot_number_is_taken_or_refused_in_one_line(scratch, case):
    check_robot(scratch, *case)


@pytest.mark.parametrize("kind", [pytest.param(k, marks=[] if k == "dh" else [pytest.mark.slow])
                                  for k in sorted(ROBOTS)])
def test_the_robot_bases_are_valid(scratch, kind):
    """Every base passes as it is: a hostile value is the only reason a case is refused."""
    write, robot, _, (j2, j3) = ROBOTS[kind]
    folder = _case(scratch)
    write(folder)
    (folder / "s.toml").write_text(_scenario(robot, j2, j3))
    assert cli(["check", str(folder / "s.toml")]) == (0, [])


#: The DH base's joint ranges.
RANGES = ("range_deg = [[-170, 170], [-100, 140], [-150, 150], [-190, 190], [-120, 120], "
          "[-360, 360]]")


@pytest.mark.parametrize("edit, needle", [
    # the campaign's cases, each by name
    (("[300, 0, 0, -90]", "[300, 0, 0, -90, 1]"), "kinematics.dh[1]: 5 values"),
    (("[0, 0, 80, 0]]", "[0, 0, 80, 0], [0, 0, 10, 0]]"), "kinematics.dh: 7 rows, while joints.range_deg"),
    (("[-170, 170], [-100", "[10, 10], [-100"), "joints.range_deg[0]: lower 10 = upper 10"),
    (("[-170, 170], [-100", "[20, 10], [-100"), "joints.range_deg[0]: lower 20 > upper 10"),
    (("max_speed_deg_s = [270,", "max_speed_deg_s = [-270,"), "joints.max_speed_deg_s[0]"),
    (("max_accel_deg_s2 = [1400,", "max_accel_deg_s2 = [-1400,"), "joints.max_accel_deg_s2[0]"),
    (("efficiency = 0.75", "efficiency = true"), "drives[0].efficiency: must be a number"),
    (("gear_ratio = 120", "gear_ratio = 1" + "0" * 400), "drives[0].gear_ratio"),
    (("total_kg = 25", "total_kg = 5e-324"), "mass.total_kg"),
    ((RANGES, "range_deg = " + str([[-1080, 1080]] * 6)), "whole-turn variants"),
])
def test_the_campaigns_robot_cases_are_one_line(scratch, edit, needle):
    folder = _case(scratch)
    _dh(folder)
    text = DH_ROBOT.replace(*edit, 1)
    assert text != DH_ROBOT
    (folder / "arm" / "robot.toml").write_text(text)
    (folder / "s.toml").write_text(_scenario("./arm"))
    rc, lines = cli(["check", str(folder / "s.toml")])
    assert_refused(rc, lines, "robot.toml", needle)


@pytest.mark.parametrize("edit, needle", [
    (("lower", "0.5", "upper", "0.5"), "limit lower 0.5 = upper 0.5"),
    (("lower", "1", "upper", "0.5"), "limit lower 1 > upper 0.5"),
    (("velocity", "-1"), "limit velocity: must be between"),
    (("effort", "-1"), "limit effort: must be between"),
])
def test_the_campaigns_urdf_limit_cases_are_one_line(scratch, edit, needle):
    folder = _case(scratch)
    _bare(folder)
    root = ET.parse(folder / "arm.urdf").getroot()
    limit = root.find("joint[@name='joint_2']/limit")
    for attr, value in zip(edit[::2], edit[1::2], strict=True):
        limit.set(attr, value)
    (folder / "arm.urdf").write_text(ET.tostring(root, encoding="unicode"))
    (folder / "s.toml").write_text(_scenario("arm.urdf", -90.0, 90.0))
    rc, lines = cli(["check", str(folder / "s.toml")])
    assert_refused(rc, lines, "arm.urdf", "'joint_2'", needle)


@pytest.mark.parametrize("inertia, needle", [
    ({"ixx": "0", "iyy": "0", "izz": "0", "ixy": "0", "ixz": "0", "iyz": "0"},
     "inertia is not physical (principal moments 0, 0, 0"),
    ({"ixx": "1", "iyy": "1", "izz": "1", "ixy": "0.9", "ixz": "0.9", "iyz": "0.9"},
     "inertia is not physical"),
])
def test_a_urdf_link_with_a_zero_or_unphysical_inertia_is_one_line(scratch, inertia, needle):
    folder = _case(scratch)
    _bare(folder)
    root = ET.parse(folder / "arm.urdf").getroot()
    el = root.find("link[@name='link_2']/inertial/inertia")
    for k, v in inertia.items():
        el.set(k, v)
    (folder / "arm.urdf").write_text(ET.tostring(root, encoding="unicode"))
    (folder / "s.toml").write_text(_scenario("arm.urdf", -90.0, 90.0))
    rc, lines = cli(["check", str(folder / "s.toml")])
    assert_refused(rc, lines, "arm.urdf", "'link_2'", needle)


# ---------------------------------------------------------------------------- catalogues
#: The shipped starter catalogue, its first motor with the optional keys no entry gives
#: (a thermal time constant, a torque-speed curve).
STARTER = tomllib.loads(starter_catalog().read_text())
STARTER["motors"][0].update(thermal_time_constant_s=600.0, torque_speed=[
    [0.0, STARTER["motors"][0]["peak_torque_nm"]],
    [STARTER["motors"][0]["max_speed_rpm"], STARTER["motors"][0]["rated_torque_nm"]]])
CATALOG_LEAVES = [leaf for leaf in numeric_leaves(STARTER) if leaf[0] in ("motors", "reducers")]
#: The reader of each kind of entry.
ENTRY = {"motors": MotorSpec, "reducers": ReducerSpec}


def _catalog_quantity(leaf: tuple) -> Quantity | None:
    return quantity_at(ENTRY[leaf[0]], leaf[2:])


def check_catalog(scratch: Path, leaf: tuple, value: Any) -> None:
    """The specification for one number of a catalogue entry, through its reader (the one
    ``cellsim run --select`` and ``cellsim size --select`` call before anything runs)."""
    path = _case(scratch) / "catalog.toml"
    path.write_text(dump_toml(with_value(STARTER, leaf, value)))
    kind, index, *key = leaf
    entry = f"{kind}[{index}] ({STARTER[kind][index]['id']})"
    try:
        load_catalog(path)
    except CatalogError as exc:
        lines = str(exc).splitlines()
        if is_hostile(_catalog_quantity(leaf), value):
            assert_refused(2, lines, str(path), entry, format_loc(tuple(key)))
        else:  # a consistency rule of the entry (rated torque above the peak, ...)
            assert_taken(2, lines)
        return
    assert not is_hostile(_catalog_quantity(leaf), value), (leaf, value)


@st.composite
def catalog_hostile(draw):
    leaf = draw(st.sampled_from(CATALOG_LEAVES))
    return leaf, draw(hostile(_catalog_quantity(leaf)))


@st.composite
def catalog_valid(draw):
    leaf = draw(st.sampled_from(CATALOG_LEAVES))
    return leaf, draw(valid(_catalog_quantity(leaf)))


@settings(max_examples=25, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(case=catalog_hostile())
def test_a_hostile_catalogue_number_is_one_line_naming_entry_and_key(scratch, case):
    check_catalog(scratch, *case)


@pytest.mark.slow
@settings(max_examples=300, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(case=st.one_of(catalog_hostile(), catalog_valid()))
def test_any_catalogue_number_is_taken_or_refused_in_one_line(scratch, case):
    check_catalog(scratch, *case)


def test_true_is_no_torque_and_the_command_line_says_so(scratch):
    """``true`` as a motor's torque (once read as 1 N m) stops ``cellsim run --select``
    before anything runs: exit 2, one line naming the file, the entry and the key."""
    path = _case(scratch) / "catalog.toml"
    path.write_text(dump_toml(with_value(STARTER, ("motors", 0, "rated_torque_nm"), True)))
    out = path.parent / "run"
    rc, lines = cli(["run", "lrmate200ic_pick_place", "--select", "--catalog", str(path),
                     "--out", str(out), "--no-video", "--no-plots", "--quiet"])
    assert_refused(rc, lines, "catalog.toml", "motors[0]", "rated_torque_nm",
                   "must be a number, got a boolean")
    assert not out.exists()


def test_a_catalogue_of_more_pairs_than_the_selection_takes_is_refused(scratch):
    """1000 motors x 1000 reducers would take the selection about 12 CPU minutes and 15 GB
    on a six-axis arm (measured: 474 s to an 8 GiB limit): refused when read, in one line,
    before a single entry is validated; at the limit it is read."""
    motor = {k: v for k, v in STARTER["motors"][0].items()}
    reducer = {k: v for k, v in STARTER["reducers"][0].items()}

    def catalogue(n_motors: int, n_reducers: int) -> Path:
        doc = {"motors": [{**motor, "id": f"m{i}"} for i in range(n_motors)],
               "reducers": [{**reducer, "id": f"r{i}"} for i in range(n_reducers)]}
        path = _case(scratch) / "big.toml"
        path.write_text(dump_toml(doc))
        return path

    with pytest.raises(CatalogError) as info:
        load_catalog(catalogue(1000, 1000))
    text = str(info.value)
    assert "\n" not in text and "big.toml" in text and "1,000,000 pairs" in text, text
    side = math.isqrt(MAX_PAIRS)
    cat = load_catalog(catalogue(side, MAX_PAIRS // side))
    assert len(cat.motors) * len(cat.reducers) <= MAX_PAIRS
    with pytest.raises(CatalogError, match="pairs, more than"):
        load_catalog(catalogue(side + 1, MAX_PAIRS // side))


# ---------------------------------------------------------------------------- cells
CELL_DOC = tomllib.loads(CELL)
CELL_LEAVES = [leaf for leaf in numeric_leaves(CELL_DOC) if leaf[0] in ("objects", "robot")]


def check_cell(scratch: Path, leaf: tuple, value: Any) -> None:
    """The specification for one number of a cell file's solids (and robot placement)."""
    folder = _case(scratch)
    (folder / "cell.toml").write_text(dump_toml(with_value(CELL_DOC, leaf, value)))
    (folder / "s.toml").write_text(CELL_SCENARIO)
    rc, lines = cli(["check", str(folder / "s.toml")])
    bad = is_hostile(quantity_at(CellFileSpec, leaf), value)  # None for a count
    if bad:
        assert_refused(rc, lines, "cell.toml", format_loc(leaf))
    else:
        assert_taken(rc, lines)


@st.composite
def cell_hostile(draw):
    leaf = draw(st.sampled_from(CELL_LEAVES))
    return leaf, draw(hostile(quantity_at(CellFileSpec, leaf)))


@st.composite
def cell_valid(draw):
    leaf = draw(st.sampled_from([lf for lf in CELL_LEAVES if lf[-1] not in COUNTS]))
    return leaf, draw(valid(quantity_at(CellFileSpec, leaf)))


@settings(max_examples=12, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(case=cell_hostile())
def test_a_hostile_cell_number_is_one_line_naming_file_and_key(scratch, case):
    check_cell(scratch, *case)


@pytest.mark.slow
@settings(max_examples=120, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(case=st.one_of(cell_hostile(), cell_valid()))
def test_any_cell_number_is_taken_or_refused_in_one_line(scratch, case):
    check_cell(scratch, *case)


@pytest.mark.parametrize("key", ["radius_mm", "length_mm"])
def test_an_absurdly_thin_cylinder_is_one_line(scratch, key):
    """A cylinder of radius 1e-300 mm was an internal fault (MuJoCo's compiler): now one
    line naming the solid's key and the range."""
    leaf = ("objects", 1, key)
    folder = _case(scratch)
    (folder / "cell.toml").write_text(dump_toml(with_value(CELL_DOC, leaf, 1e-300)))
    (folder / "s.toml").write_text(CELL_SCENARIO)
    rc, lines = cli(["check", str(folder / "s.toml")])
    assert_refused(rc, lines, "cell.toml", f"objects[1].{key}", "must be between 0.001 and")


def test_the_cell_base_is_valid(scratch):
    folder = _case(scratch)
    (folder / "cell.toml").write_text(CELL)
    (folder / "s.toml").write_text(CELL_SCENARIO)
    assert cli(["check", str(folder / "s.toml")]) == (0, [])


# ---------------------------------------------------------------------------- the oracle itself
def test_every_numeric_key_of_the_valid_files_has_a_range():
    """Every number the bases hold has a declared range (or is a count): a new numeric key
    without one fails here, so the campaign above always knows what is hostile."""
    missing = [(kind, leaf) for kind, leaf in ROBOT_LEAVES
               if _robot_quantity(kind, leaf)[0] is None]
    missing += [("catalogue", leaf) for leaf in CATALOG_LEAVES if _catalog_quantity(leaf) is None]
    missing += [("cell", leaf) for leaf in CELL_LEAVES
                if leaf[-1] not in COUNTS and quantity_at(CellFileSpec, leaf) is None]
    assert missing == []
    # the bases hold every key the readers give a range: the drives, links, solids ...
    leaves = [leaf for _, leaf in ROBOT_LEAVES] + CATALOG_LEAVES + CELL_LEAVES
    keys = {part for leaf in leaves for part in leaf if isinstance(part, str)}
    for model in (RobotFolderSpec, MotorSpec, ReducerSpec, ObjectBlock, RobotBlock):
        for name, sub in _ranged_fields(model):
            assert name in keys, f"{sub.__name__}.{name} is in no base file"
    elements = list(ET.parse(_source("bare_urdf")).getroot().iter())
    urdf_keys = {(elements[leaf[0]].tag, leaf[1]) for kind, leaf in ROBOT_LEAVES
                 if kind == "bare_urdf"}
    assert urdf_keys == set(URDF_QUANTITIES)


def _ranged_fields(model: Any, seen: set | None = None) -> list[tuple[str, Any]]:
    """``(field name, model)`` of every field of a model (and the models it nests) whose
    number has a :class:`Quantity`."""
    import typing

    from pydantic import BaseModel

    seen = set() if seen is None else seen
    if model in seen:
        return []
    seen.add(model)
    out = []
    for name, field in model.model_fields.items():
        if quantity_at(model, (name,)) is not None or quantity_at(model, (name, 0)) is not None \
                or quantity_at(model, (name, 0, 0)) is not None:
            out.append((name, model))
        stack = [field.annotation]
        while stack:
            ann = stack.pop()
            if isinstance(ann, type) and issubclass(ann, BaseModel):
                out += _ranged_fields(ann, seen)
            stack += list(typing.get_args(ann))
    return out


@pytest.mark.parametrize("kind, case", [
    ("robot", ("dh", ("drives", 0, "gear_ratio"), 1e308)),
    ("robot", ("bare_urdf", None, 1e308)),
    ("catalogue", (("motors", 0, "peak_torque_nm"), 1e300)),
    ("cell", (("objects", 1, "radius_mm"), 1e-300)),
])
def test_a_reader_that_takes_a_value_out_of_range_is_caught(scratch, monkeypatch, kind, case):
    """A planted fault: with the range check of :class:`Quantity` made a no-op (types still
    checked), the specification's check of a value out of range fails."""
    if kind == "robot" and case[1] is None:  # a URDF joint's velocity limit
        leaf = next(lf for k, lf in ROBOT_LEAVES if k == "bare_urdf" and lf[1] == "velocity")
        case = ("bare_urdf", leaf, case[2])
    check = {"robot": check_robot, "catalogue": check_catalog, "cell": check_cell}[kind]
    check(scratch, *case)  # refused as it should be
    from sim.core.tomlschema import number_problem

    monkeypatch.setattr(Quantity, "problem", lambda self, value: number_problem(value))
    with pytest.raises(AssertionError):
        check(scratch, *case)
