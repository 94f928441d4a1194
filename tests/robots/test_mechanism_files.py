"""Mechanism files (turntables, positioners, tracks; docs/mechanism-format.md): what a file
says is what :func:`read_mechanism` gives, in SI units; every bad value is one line naming the
file, the key and the value; the shipped mechanisms read, and the MotoPos D500 carries
ROS-Industrial's numbers.

Oracles are written from first principles (``tests/support/mechanisms.py``: mm -> m is
``/ 1000``, deg -> rad is ``* pi / 180``, an axis is normalised by its Euclidean length,
``Rz Ry Rx`` from the explicit matrices; here: inertias about an axis by the parallel-axis
theorem).
"""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support.mechanisms import DEG, floats, mechanism_docs, mismatches, rodrigues, write, zyx

from sim.errors import CellsimError, InternalError, MechanismError, UnknownNameError
from sim.robots.mechanisms import (
    MECHANISMS,
    MechanismSpec,
    mechanism_from_ref,
    read_mechanism,
)

ROOT = Path(__file__).resolve().parents[2]
G = 9.81


# ------------------------------------------------------------------------------- round trip
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                   HealthCheck.function_scoped_fixture])
@given(doc=mechanism_docs())
def test_a_generated_file_reads_as_its_own_numbers_in_si_units(doc, tmp_path):
    """Every field of the spec is the file's number, converted by the oracle's own rules."""
    spec = read_mechanism(write(tmp_path, doc))
    assert mismatches(spec, doc, "mech") == []


@pytest.mark.slow
@settings(max_examples=1000, deadline=None, suppress_health_check=[
    HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(doc=mechanism_docs())
def test_a_larger_generated_share_reads_as_its_own_numbers(doc, tmp_path):
    spec = read_mechanism(write(tmp_path, doc))
    assert mismatches(spec, doc, "mech") == []


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                   HealthCheck.function_scoped_fixture])
@given(doc=mechanism_docs(), scale=st.sampled_from([1 + 1e-9, 1 - 1e-9, 1000.0, DEG]))
def test_the_round_trip_oracle_catches_a_perturbed_or_unconverted_value(doc, scale, tmp_path):
    """Planted fault: one axis's range off by one part in 1e9, or left in mm or unconverted to
    rad, is reported by the oracle."""
    spec = read_mechanism(write(tmp_path, doc))
    ax = spec.axes[0]
    lo, hi = ax.range
    wrong = (lo, hi * scale) if hi != 0 else (lo * scale, hi)  # lower < upper: not both 0
    bad = dataclasses.replace(spec, axes=(dataclasses.replace(ax, range=wrong),
                                          *spec.axes[1:]))
    found = mismatches(bad, doc, "mech")
    assert found and found[0].startswith("axes[0].range")


def test_the_rotation_oracle_is_rz_ry_rx():
    """The oracle's matrices: Rz(90) maps x to y, Ry(90) maps z to x, Rx(90) maps y to z, and
    the product applies Rx first."""
    np.testing.assert_allclose(zyx([90, 0, 0]) @ [1, 0, 0], [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(zyx([0, 90, 0]) @ [0, 0, 1], [1, 0, 0], atol=1e-15)
    np.testing.assert_allclose(zyx([0, 0, 90]) @ [0, 1, 0], [0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(zyx([90, 0, 90]) @ [0, 1, 0], [0, 0, 1], atol=1e-15)


# ---------------------------------------------------------------------------------- hostile
def _base_doc() -> dict[str, Any]:
    """A valid two-axis positioner (the hostile cases change one thing)."""
    def axis(name: str, axis: list[float]) -> dict[str, Any]:
        return {"name": name, "kind": "revolute", "axis": axis, "range_deg": [-90.0, 90.0],
                "max_speed_deg_s": 90.0, "max_accel_deg_s2": 300.0,
                "drive": {"gear_ratio": 100.0, "efficiency": 0.8, "rotor_inertia_kg_m2": 1e-4,
                          "rated_torque_nm": 1.0, "peak_torque_nm": 3.0, "max_speed_rpm": 3000.0},
                "link": {"mass_kg": 50.0, "com_mm": [0.0, 0.0, 10.0],
                         "inertia_kg_m2": [1.0, 1.0, 1.5],
                         "shapes": [{"kind": "box", "size_mm": [100.0, 100.0, 10.0]}]}}
    return {"name": "hostile", "kind": "positioner", "payload_kg": 100.0,
            "axes": [axis("tilt", [0.0, 1.0, 0.0]), axis("rotate", [0.0, 0.0, 1.0])],
            "mount": {"pos_mm": [0.0, 0.0, 100.0]}}


def _set(doc: dict[str, Any], path: str, value: Any) -> None:
    parts = re.findall(r"[^.\[\]]+|\[\d+\]", path)
    node: Any = doc
    for p in parts[:-1]:
        node = node[int(p[1:-1])] if p.startswith("[") else node[p]
    last = parts[-1]
    if value is _DELETE:
        del node[last]
    elif last.startswith("["):
        node[int(last[1:-1])] = value
    else:
        node[last] = value


_DELETE = object()

#: (what is set, to what, the key path and a piece of the message the line must hold)
HOSTILE = [
    ("axes[0].link.mass_kg", float("nan"), "axes[0].link.mass_kg", "NaN"),
    ("axes[1].max_speed_deg_s", float("inf"), "axes[1].max_speed_deg_s", "inf"),
    ("axes[0].link.mass_kg", 1e308, "axes[0].link.mass_kg", "1e+308"),
    ("axes[0].link.mass_kg", -5.0, "axes[0].link.mass_kg", "-5.0"),
    ("axes[0].drive.gear_ratio", 10**400, "axes[0].drive.gear_ratio", "401 digits"),
    ("payload_kg", True, "payload_kg", "boolean"),
    ("axes[0].link.com_mm", ["1", 0.0, 0.0], "axes[0].link.com_mm[0]", "'1'"),
    ("axes[0].axis", [0.0, 0.0, 0.0], "axes[0].axis", "[0.0, 0.0, 0.0]"),
    ("axes[1].range_deg", [10.0, -10.0], "axes[1].range_deg",
     "lower 10.0 must be below upper -10.0"),
    ("axes[1].range_deg", [5.0, 5.0], "axes[1].range_deg", "lower 5.0 must be below upper 5.0"),
    ("axes[1].range_deg", [5.0, 5.0005], "axes[1].range_deg", "at least 0.001 deg wide"),
    ("axes[1].range_deg", [-2000.0, 5.0], "axes[1].range_deg[0]", "-2000.0"),
    ("axes[0].frobnicate", 1.0, "axes[0].frobnicate", "unknown key"),
    ("axes[0].max_speed_rad_s", 1.0, "axes[0].max_speed_rad_s", "did you mean"),
    ("axes[0].range_mm", [0.0, 100.0], "axes[0].range_mm", "takes range_deg"),
    ("axes[0].friction_n", 3.0, "axes[0].friction_n", "takes friction_nm"),
    ("axes[0].max_accel_deg_s2", _DELETE, "axes[0].max_accel_deg_s2", "required"),
    ("axes[0].link.inertia_kg_m2", [1.0, 1.0, 3.0], "axes[0].link.inertia_kg_m2",
     "[1.0, 1.0, 3.0]"),
    ("axes[0].link.inertia_kg_m2", [0.0, 1.0, 1.0], "axes[0].link.inertia_kg_m2[0]", "0.0"),
    ("axes[1].name", "tilt", "axes[1].name", "'tilt' names two axes"),
    ("axes[0].drive.peak_torque_nm", 0.5, "axes[0].drive.peak_torque_nm", "0.5"),
    ("axes[0].drive.rated_torque_nm", _DELETE, "axes[0].drive.rated_torque_nm", "missing"),
    ("axes[0].link.shapes[0].size_mm", _DELETE, "axes[0].link.shapes[0].size_mm", "required"),
    ("axes[0].link.shapes[0].radius_mm", 5.0, "axes[0].link.shapes[0].radius_mm", "5.0"),
    ("axes[0].link.shapes[0].rgba", [1.5, 0.0, 0.0, 1.0], "axes[0].link.shapes[0].rgba[0]",
     "1.5"),
    ("kind", "turntable", "axes", "got 2"),
    ("axes[0].kind", "prismatic", "axes[0].kind", "'prismatic'"),
    ("mount.euler_zyx_deg", [0.0, 0.0, 1e4], "mount.euler_zyx_deg[2]", "10000.0"),
]


@pytest.mark.parametrize("path,value,key,piece", HOSTILE,
                         ids=[f"{p}={'<deleted>' if v is _DELETE else repr(v)}"[:60]
                              for p, v, _, _ in HOSTILE])
def test_a_bad_value_is_one_line_naming_the_file_the_key_and_the_value(
        tmp_path, path, value, key, piece):
    doc = _base_doc()
    assert read_mechanism(write(tmp_path, doc, "ok.toml")).name == "hostile"
    _set(doc, path, value)
    file = write(tmp_path, doc, "d500.toml")
    with pytest.raises(MechanismError) as err:
        read_mechanism(file)
    text = str(err.value)
    assert "\n" not in text
    assert text.startswith(f"{file}: {key}:"), text
    assert piece in text, text
    # the command line's exit 2: a CellsimError that is not an internal fault
    assert isinstance(err.value, CellsimError) and not isinstance(err.value, InternalError)


def _numbers(node: Any, loc: tuple[Any, ...] = ()) -> list[tuple[tuple[Any, ...], float]]:
    """Every number of a parsed TOML table with its location."""
    if isinstance(node, dict):
        return [x for k, v in node.items() for x in _numbers(v, (*loc, k))]
    if isinstance(node, list):
        return [x for i, v in enumerate(node) for x in _numbers(v, (*loc, i))]
    if isinstance(node, (int, float)) and not isinstance(node, bool):
        return [(loc, float(node))]
    return []


def test_every_number_of_a_shipped_file_is_refused_just_outside_its_range(tmp_path):
    """Each numeric key of every shipped file, set just below and just above the range its
    quantity declares (``docs/mechanism-format.md``, Numbers), is one line naming that key."""
    import tomllib

    from sim.core.tomlschema import format_loc, quantity_at
    from sim.robots.mechanisms.schema import MechanismFile

    checked = 0
    for spec in MECHANISMS.values():
        raw = tomllib.loads(Path(spec.source).read_text(encoding="utf-8"))
        for loc, _ in _numbers(raw):
            q = quantity_at(MechanismFile, loc)
            assert q is not None, f"{spec.name}: {format_loc(loc)} has no declared range"
            for bad in (q.lo - max(1.0, abs(q.lo)), q.hi + max(1.0, abs(q.hi))):
                doc = tomllib.loads(Path(spec.source).read_text(encoding="utf-8"))
                node: Any = doc
                for part in loc[:-1]:
                    node = node[part]
                node[loc[-1]] = bad
                file = write(tmp_path, doc, "edge.toml")
                with pytest.raises(MechanismError) as err:
                    read_mechanism(file)
                assert str(err.value).startswith(f"{file}: {format_loc(loc)}: must be between")
                assert repr(bad) in str(err.value)
                checked += 1
    assert checked > 100


def test_a_prismatic_axis_refuses_the_revolute_keys(tmp_path):
    doc = _base_doc()
    doc["kind"] = "track"
    doc["axes"] = [doc["axes"][0]]
    ax = doc["axes"][0]
    ax["kind"] = "prismatic"
    with pytest.raises(MechanismError, match=r"axes\[0\]\.range_deg: a prismatic axis takes "
                                             r"range_mm, not range_deg \(got \[-90\.0, 90\.0\]\)"):
        read_mechanism(write(tmp_path, doc))


def test_a_file_that_is_no_toml_or_not_there_is_one_line(tmp_path):
    bad = tmp_path / "x.toml"
    bad.write_text("name = [\n", encoding="utf-8")
    with pytest.raises(MechanismError, match="invalid TOML"):
        read_mechanism(bad)
    with pytest.raises(MechanismError, match="no mechanism file"):
        mechanism_from_ref("nowhere.toml", tmp_path)


# ---------------------------------------------------------------------------------- shipped
def test_every_shipped_mechanism_reads_and_is_registered_under_its_folder_name():
    folders = sorted(p.parent for kind in ("positioners", "turntables", "tracks")
                     for p in (ROOT / "models" / kind).glob("*/mechanism.toml"))
    assert {f.name for f in folders} == set(MECHANISMS.names())
    assert {"motopos_d500", "floor_track_4m", "turntable_500"} <= set(MECHANISMS.names())
    for folder in folders:
        spec = read_mechanism(folder / "mechanism.toml")
        assert spec.name == folder.name
        assert (folder / "README.md").is_file()
        assert mechanism_from_ref(spec.name).name == spec.name
        assert mechanism_from_ref(str(folder)).name == spec.name
        assert mechanism_from_ref(folder.name + "/mechanism.toml", folder.parent).name == spec.name


def test_an_unknown_mechanism_name_lists_the_shipped_ones():
    with pytest.raises(UnknownNameError, match="motopos_d500"):
        mechanism_from_ref("motopos_d50")


@pytest.mark.parametrize("name", ["motopos_d500", "floor_track_4m", "turntable_500"])
def test_a_shipped_mechanisms_drives_reach_its_limits(name):
    """Each axis: the motor's top speed reaches the axis's speed limit through the ratio
    (rad/s or m/s = rpm 2 pi / 60 / ratio); peak torque at least the rated; the mount's z is
    up at zero (the last link frame is not turned at zero)."""
    spec = MECHANISMS[name]
    for a in spec.axes:
        assert a.drive.max_speed_rpm * 2 * math.pi / 60 / a.drive.gear_ratio >= a.max_speed
        assert a.drive.peak_torque >= a.drive.rated_torque
    np.testing.assert_allclose(spec.mount[:3, 2], [0, 0, 1], atol=1e-12)


def _inertia_about(u: np.ndarray, origin: np.ndarray, mass: float, com: np.ndarray,
                   principal: np.ndarray) -> float:
    """A body's inertia about the line through ``origin`` along unit ``u``: its own (principal
    moments along the frame's axes) plus the parallel-axis term."""
    r = com - origin
    perp = r - (r @ u) * u
    return float(u @ np.diag(principal) @ u + mass * perp @ perp)


def _accel_oracle(spec: MechanismSpec, i: int, payload_inertia: float) -> float:
    """The acceleration limit the READMEs derive for axis ``i``: ``(peak N eta - gravity -
    friction) / (J + J_r N^2 eta)``, with the links past it and the rated payload at the mount
    (its own inertia ``payload_inertia`` about the axis), all axes at zero; the gravity term is
    the largest over the axis's turn, ``g |m r_perp| sqrt(1 - u_z^2)`` (none about a vertical
    axis). The shipped links' centres of mass lie on the later axes, so turning those changes
    neither ``J`` nor the gravity term."""
    a, d = spec.axes[i], spec.axes[i].drive
    origins = np.cumsum([ax.pos for ax in spec.axes], axis=0)  # link frames at zero
    if a.kind == "prismatic":
        load = sum(ax.link.mass for ax in spec.axes[i:]) + spec.payload_kg
        return (d.peak_torque * d.gear_ratio * d.efficiency - a.friction) / (
            load + d.rotor_inertia * d.gear_ratio**2 * d.efficiency)
    u, o = a.axis, origins[i]
    J, moment = payload_inertia, np.zeros(3)
    bodies = [(ax.link.mass, origins[j] + ax.link.com, ax.link.inertia)
              for j, ax in enumerate(spec.axes) if j >= i]
    bodies.append((spec.payload_kg, origins[-1] + spec.mount[:3, 3], np.zeros(3)))
    for mass, com, principal in bodies:
        J += _inertia_about(u, o, mass, com, principal)
        moment += mass * (com - o)
    perp = moment - (moment @ u) * u
    gravity = G * float(np.linalg.norm(perp)) * math.sqrt(max(0.0, 1.0 - u[2] ** 2))
    return (d.peak_torque * d.gear_ratio * d.efficiency - gravity - a.friction) / (
        J + d.rotor_inertia * d.gear_ratio**2 * d.efficiency)


def _accel_cases() -> list[tuple[MechanismSpec, int, float]]:
    """(mechanism, axis, the rated payload's own inertia about the axis) as the READMEs take
    it: the D500's a body of 100 mm radius of gyration at the faceplate; the turntable's a
    uniform disc over its table; the track's a mass on the carriage."""
    d500 = MECHANISMS["motopos_d500"]
    k = 0.1
    table = MECHANISMS["turntable_500"]
    radius = next(s for s in table.axes[0].link.shapes if s.name == "table").size[0]
    return [(d500, 0, d500.payload_kg * k * k), (d500, 1, d500.payload_kg * k * k),
            (table, 0, 0.5 * table.payload_kg * radius**2),
            (MECHANISMS["floor_track_4m"], 0, 0.0)]


def _accel_problem(spec: MechanismSpec, i: int, own: float) -> str:
    """Why axis ``i``'s limit is not the drive's rounded down to two significant digits (at
    most 10 % below it), or ""."""
    want = _accel_oracle(spec, i, own)
    got = spec.axes[i].max_accel
    return "" if 0.9 * want <= got <= want else f"{spec.name} axis {i}: {got} vs {want}"


def test_the_shipped_acceleration_limits_are_what_the_drives_give_rounded_down():
    assert [p for case in _accel_cases() if (p := _accel_problem(*case))] == []


@pytest.mark.parametrize("factor", [1.02, 0.85])
def test_the_acceleration_check_catches_a_limit_above_the_drive_or_far_below(factor):
    """Planted fault: each shipped limit 2 % above what its drive gives, or 15 % below."""
    for spec, i, own in _accel_cases():
        axes = list(spec.axes)
        axes[i] = dataclasses.replace(axes[i], max_accel=_accel_oracle(spec, i, own) * factor)
        assert _accel_problem(dataclasses.replace(spec, axes=tuple(axes)), i, own)


# ------------------------------------------------------------- MotoPos D500 against ROS-I
#: ROS-Industrial motoman, commit 433be15f6a27cb9a5715cc3887b1cd15ff33a8cb,
#: motoman_motopos_d500_support/urdf/motopos_d500_macro.xacro (the independent reference).
ROSI_D500 = {
    "joint_1": {"origin": (0.0, 0.0, 0.380), "axis": (0.0, -1.0, 0.0), "lower": -2.3561,
                "upper": 2.3561, "effort": 1274.0, "velocity": 1.3962},
    "joint_2": {"origin": (0.0, 0.0, 0.0), "axis": (0.0, 0.0, -1.0), "lower": -3.4906,
                "upper": 3.4906, "effort": 392.0, "velocity": 2.7925},
    "tool0": (0.0, 0.0, 0.150),
}


def test_the_d500_carries_the_ros_industrial_numbers():
    spec = MECHANISMS["motopos_d500"]
    assert spec.kind == "positioner" and spec.payload_kg == 500.0
    assert spec.axis_names == ("tilt", "rotate")
    for ax, ref in zip(spec.axes, (ROSI_D500["joint_1"], ROSI_D500["joint_2"]), strict=True):
        np.testing.assert_allclose(ax.pos, ref["origin"], atol=1e-12)
        np.testing.assert_allclose(ax.axis, ref["axis"], atol=1e-12)
        # ROS-I rounds to 4 decimals: 135 deg = 2.35619.., 200 deg = 3.49066..
        assert abs(ax.range[0] - ref["lower"]) < 1e-4 and abs(ax.range[1] - ref["upper"]) < 1e-4
        assert abs(ax.max_speed - ref["velocity"]) < 1e-4
        d = ax.drive
        # the effort is Yaskawa's allowable moment: the drive's continuous torque at the joint
        joint_rated = d.rated_torque * d.gear_ratio * d.efficiency
        assert ref["effort"] <= joint_rated <= 1.01 * ref["effort"]
        assert d.max_speed_rpm * 2 * math.pi / 60 / d.gear_ratio >= ref["velocity"]
    np.testing.assert_allclose(spec.mount[:3, 3], ROSI_D500["tool0"], atol=1e-12)
    np.testing.assert_allclose(spec.mount[:3, :3], np.eye(3), atol=1e-12)


@settings(max_examples=50, deadline=None)
@given(q1=floats(-2.3561, 2.3561), q2=floats(-3.4906, 3.4906))
def test_the_d500_chain_puts_the_faceplate_where_the_urdf_does(q1, q2):
    """The documented chain (translate by pos, turn about axis) of the file's numbers gives
    the URDF's tool0 pose: origin, Rodrigues(axis, q), origin, Rodrigues(axis, q), tool0."""
    spec = MECHANISMS["motopos_d500"]

    def urdf() -> np.ndarray:
        T = np.eye(4)
        for name, q in (("joint_1", q1), ("joint_2", q2)):
            j = ROSI_D500[name]
            step = np.eye(4)
            step[:3, 3] = j["origin"]
            step[:3, :3] = rodrigues(np.array(j["axis"]), q)
            T = T @ step
        tool = np.eye(4)
        tool[:3, 3] = ROSI_D500["tool0"]
        return T @ tool

    T = np.eye(4)
    for ax, q in zip(spec.axes, (q1, q2), strict=True):
        step = np.eye(4)
        step[:3, 3] = ax.pos
        step[:3, :3] = rodrigues(ax.axis, q)
        T = T @ step
    np.testing.assert_allclose(T @ spec.mount, urdf(), atol=1e-12)


# ------------------------------------------------------------------------------------ docs
def test_the_format_reference_documents_every_key():
    """docs/mechanism-format.md and the declared schema name the same keys, and a drive's
    keys are the robot file's ``[[drives]]`` (those of a scenario's ``[drives.jN]``)."""
    from sim.robots.drives import DRIVE_KEYS
    from sim.robots.mechanisms.schema import (
        AxisBlock,
        LinkBlock,
        MechanismFile,
        MountBlock,
        ShapeBlock,
    )
    from sim.robots.schema import DriveBlock

    doc = (ROOT / "docs" / "mechanism-format.md").read_text(encoding="utf-8")
    table_keys = set(re.findall(r"^\| `([a-z][a-z0-9_]*)`", doc, flags=re.M))
    table_keys -= {"motopos_d500", "turntable_500", "floor_track_4m"}  # the shipped list
    declared = set()
    for model in (MechanismFile, AxisBlock, DriveBlock, LinkBlock, ShapeBlock, MountBlock):
        for key in model.model_fields:
            assert key in table_keys, f"{model.__name__}.{key} is not documented"
            declared.add(key)
    assert table_keys <= declared, f"documented but not accepted: {table_keys - declared}"
    assert set(DriveBlock.model_fields) == set(DRIVE_KEYS)
    for name in MECHANISMS.names():
        assert f"`{name}`" in doc, f"{name} is not in the list of shipped mechanisms"


def test_the_format_reference_example_reads(tmp_path):
    doc = (ROOT / "docs" / "mechanism-format.md").read_text(encoding="utf-8")
    example = re.search(r"```toml\n(.*?)```", doc, flags=re.S)
    assert example is not None
    path = tmp_path / "table.toml"
    path.write_text(example.group(1), encoding="utf-8")
    spec = read_mechanism(path)
    assert spec.name == "my_table" and spec.kind == "turntable"
    assert spec.axes[0].range == pytest.approx((-370 * DEG, 370 * DEG))
    assert spec.base_shapes[0].name == "base0" and spec.axes[0].link.shapes[0].name == "rotate0"
