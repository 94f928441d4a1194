"""Reading a mechanism file (``mechanism.toml``: a turntable, a positioner, a track) into a
:class:`~sim.robots.mechanisms.spec.MechanismSpec`: :func:`read_mechanism`.

The file's keys carry their units (mm, deg, deg/s, mm/s, kg, kg m^2; the schema is
:mod:`sim.robots.mechanisms.schema`, every key in ``docs/mechanism-format.md``); the spec is
SI (m, rad, rad/s, m/s). A sketch::

    name = "motopos_d500"
    kind = "positioner"                 # "turntable", "positioner" or "track"
    payload_kg = 500
    [[axes]]                            # base first
    name = "tilt"
    kind = "revolute"                   # or "prismatic" (the _mm keys and friction_n)
    pos_mm = [0, 0, 380]                # origin in the parent frame at zero
    axis = [0, -1, 0]                   # normalised on reading
    range_deg = [-135, 135]
    max_speed_deg_s = 80
    max_accel_deg_s2 = 450
    [axes.drive]                        # the robot file's [[drives]] keys
    gear_ratio = 337                    # prismatic: motor rad per metre
    ...
    [axes.link]
    mass_kg = 62
    com_mm = [0, 0, -90]
    inertia_kg_m2 = [1.9, 1.2, 2.0]     # principal moments at the centre of mass
    [[axes.link.shapes]]
    kind = "box"
    size_mm = [330, 450, 60]
    [mount]
    pos_mm = [0, 0, 150]

Every problem is one line, :class:`sim.errors.MechanismError` (exit 2), naming the file, the
key's path and the value (``d500.toml: axes[1].range_deg: lower 10.0 must be below upper -10.0``).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from sim.core.rotations import euler_zyx_to_matrix
from sim.core.tomlschema import MIN_PRINCIPAL_INERTIA_KG_M2, load_toml
from sim.errors import MechanismError
from sim.robots.drive import Drive
from sim.robots.mechanisms.schema import (
    AXIS_UNIT_KEYS,
    AxisBlock,
    LinkBlock,
    MechanismFile,
    ShapeBlock,
)
from sim.robots.mechanisms.spec import AxisSpec, LinkSpec, MechanismSpec, Shape

#: The file name of a mechanism folder (``models/positioners/<name>/mechanism.toml``).
MECHANISM_FILE = "mechanism.toml"

#: The narrowest range an axis may have, deg or mm (a narrower one is a typo; in SI units it
#: could vanish altogether).
MIN_RANGE = 1e-3

#: Axes a mechanism of each kind has: ``(kind of every axis, fewest, most)``.
KIND_AXES: dict[str, tuple[str, int, int]] = {
    "turntable": ("revolute", 1, 1),
    "positioner": ("revolute", 1, 3),
    "track": ("prismatic", 1, 1),
}


def _fail(where: str, key: str, why: str) -> MechanismError:
    return MechanismError(f"{where}: {key}: {why}")


def read_mechanism(path: str | Path) -> MechanismSpec:
    """The :class:`MechanismSpec` of a mechanism file (or of a folder holding a
    ``mechanism.toml``).

    Its ``name`` is the file's ``name``, else the folder's name for a ``mechanism.toml``, else
    the file's stem; ``title`` defaults to the name.

    Raises:
        MechanismError: One line naming the file, the key's path and the value.
    """
    path = Path(path)
    if path.is_dir():
        path = path / MECHANISM_FILE
    spec, _ = load_toml(path, MechanismFile, MechanismError)
    where = str(path)
    name = spec.name or (path.parent.name if path.name == MECHANISM_FILE else path.stem)
    want, fewest, most = KIND_AXES[spec.kind]
    if not fewest <= len(spec.axes) <= most:
        count = f"{fewest}" if fewest == most else f"{fewest} to {most}"
        raise _fail(where, "axes", f"a {spec.kind} has {count} axes, got {len(spec.axes)}")
    names: set[str] = set()
    shape_names: set[str] = set()
    axes = []
    for i, block in enumerate(spec.axes):
        key = f"axes[{i}]"
        if block.kind != want:
            raise _fail(where, f"{key}.kind", f"the axes of a {spec.kind} are {want}, got "
                        f"{block.kind!r}")
        if block.name in names:
            raise _fail(where, f"{key}.name", f"{block.name!r} names two axes")
        names.add(block.name)
        axes.append(_axis(block, where, key, shape_names))
    base_shapes = _shapes(spec.base_shapes, where, "base_shapes", "base", shape_names)
    mount = np.eye(4)
    mount[:3, :3] = _rotation(spec.mount.euler_zyx_deg)
    mount[:3, 3] = np.asarray(spec.mount.pos_mm, dtype=float) / 1000.0
    return MechanismSpec(
        name=name, title=spec.title or name, kind=spec.kind, axes=tuple(axes),
        base_shapes=base_shapes, mount=mount, payload_kg=float(spec.payload_kg),
        description=spec.description, source=path)


def _axis(block: AxisBlock, where: str, key: str, shape_names: set[str]) -> AxisSpec:
    """One ``[[axes]]`` table in SI units, its unit keys matching its kind."""
    units = AXIS_UNIT_KEYS[block.kind]
    other = AXIS_UNIT_KEYS["prismatic" if block.kind == "revolute" else "revolute"]
    for quantity, wrong in other.items():
        if getattr(block, wrong) is not None:
            raise _fail(where, f"{key}.{wrong}", f"a {block.kind} axis takes {units[quantity]}, "
                        f"not {wrong} (got {getattr(block, wrong)!r})")
    for quantity in ("range", "max_speed", "max_accel"):
        if getattr(block, units[quantity]) is None:
            raise _fail(where, f"{key}.{units[quantity]}",
                        f"required for a {block.kind} axis")
    scale = math.pi / 180.0 if block.kind == "revolute" else 1e-3
    lower, upper = getattr(block, units["range"])
    unit = "deg" if block.kind == "revolute" else "mm"
    if not lower < upper:
        raise _fail(where, f"{key}.{units['range']}",
                    f"lower {lower!r} must be below upper {upper!r}")
    if upper - lower < MIN_RANGE * (1 - 1e-6):  # rounding: 1.001 - 1.0 is 0.000999...
        raise _fail(where, f"{key}.{units['range']}", f"[{lower!r}, {upper!r}]: the range must "
                    f"be at least {MIN_RANGE:g} {unit} wide (the axis could not move)")
    friction = getattr(block, units["friction"])
    d = block.drive
    if d.peak_torque_nm < d.rated_torque_nm:
        raise _fail(where, f"{key}.drive.peak_torque_nm", f"{d.peak_torque_nm!r} N m is below "
                    f"rated_torque_nm {d.rated_torque_nm!r} N m")
    drive = Drive(d.gear_ratio, d.efficiency, d.rotor_inertia_kg_m2, d.rated_torque_nm,
                  d.peak_torque_nm, d.max_speed_rpm)
    return AxisSpec(
        name=block.name, kind=block.kind,
        pos=np.asarray(block.pos_mm, dtype=float) / 1000.0,
        axis=_unit(block.axis, where, f"{key}.axis"),
        range=(lower * scale, upper * scale),
        max_speed=getattr(block, units["max_speed"]) * scale,
        max_accel=getattr(block, units["max_accel"]) * scale,
        drive=drive,
        link=_link(block.link, where, f"{key}.link", block.name, shape_names),
        friction=0.0 if friction is None else float(friction),
        damping=float(block.damping))


def _unit(v: list[float], where: str, key: str) -> NDArray[np.float64]:
    """``v`` normalised (scaled by its largest component first: no overflow, no underflow)."""
    a = np.asarray(v, dtype=float)
    big = float(np.abs(a).max())
    if big == 0.0:
        raise _fail(where, key, f"must not be zero (a direction), got {list(v)!r}")
    a = a / big
    return a / float(np.linalg.norm(a))


def _link(block: LinkBlock, where: str, key: str, axis_name: str,
          shape_names: set[str]) -> LinkSpec:
    inertia = np.asarray(block.inertia_kg_m2, dtype=float)
    a, b, c = np.sort(inertia)
    if a < MIN_PRINCIPAL_INERTIA_KG_M2 or a + b < c * (1 - 1e-9):
        raise _fail(where, f"{key}.inertia_kg_m2", "principal moments must satisfy the triangle "
                    f"inequality (none larger than the sum of the other two), got "
                    f"{list(block.inertia_kg_m2)!r}")
    return LinkSpec(mass=float(block.mass_kg), com=np.asarray(block.com_mm, dtype=float) / 1000.0,
                    inertia=inertia,
                    shapes=_shapes(block.shapes, where, f"{key}.shapes", axis_name, shape_names))


def _shapes(blocks: list[ShapeBlock], where: str, key: str, prefix: str,
            names: set[str]) -> tuple[Shape, ...]:
    """Shapes in SI units; a shape without a name is ``<prefix><i>``; names are unique within
    the mechanism (``names`` collects them)."""
    out = []
    for i, s in enumerate(blocks):
        k = f"{key}[{i}]"
        if s.kind == "box":
            if s.size_mm is None:
                raise _fail(where, f"{k}.size_mm", "required for a box (its full extents)")
            extra = "radius_mm" if s.radius_mm is not None else \
                "length_mm" if s.length_mm is not None else None
            if extra:
                raise _fail(where, f"{k}.{extra}", "a box takes size_mm only, got "
                            f"{getattr(s, extra)!r}")
            size = np.asarray(s.size_mm, dtype=float) / 2000.0
        else:
            if s.size_mm is not None:
                raise _fail(where, f"{k}.size_mm", "a cylinder takes radius_mm and length_mm, "
                            f"not size_mm (got {list(s.size_mm)!r})")
            radius, length = s.radius_mm, s.length_mm
            if radius is None:
                raise _fail(where, f"{k}.radius_mm", "required for a cylinder")
            if length is None:
                raise _fail(where, f"{k}.length_mm", "required for a cylinder")
            size = np.array([radius / 1000.0, length / 2000.0, 0.0])
        name = s.name or f"{prefix}{i}"
        if name in names:
            raise _fail(where, f"{k}.name", f"{name!r} names two shapes of the mechanism")
        names.add(name)
        out.append(Shape(kind=s.kind, size=size, pos=np.asarray(s.pos_mm, dtype=float) / 1000.0,
                         rot=_rotation(s.euler_zyx_deg),
                         rgba=(float(s.rgba[0]), float(s.rgba[1]), float(s.rgba[2]),
                               float(s.rgba[3])),
                         name=name))
    return tuple(out)


def _rotation(euler_zyx_deg: list[float]) -> NDArray[np.float64]:
    """``Rz(a) Ry(b) Rx(c)`` of ``[a, b, c]`` in degrees."""
    a, b, c = np.deg2rad(np.asarray(euler_zyx_deg, dtype=float))
    return np.asarray(euler_zyx_to_matrix(a, b, c), dtype=float)


__all__ = ["KIND_AXES", "MECHANISM_FILE", "MIN_RANGE", "read_mechanism"]
