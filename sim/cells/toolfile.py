"""Tools as data: a TOML file describing an end-of-arm tool (format: ``docs/cell-format.md``).

A tool file gives the tool centre point in the *tool frame* (origin on the flange face, ``+z``
out of the flange along the approach axis, as for the shipped tools of
:mod:`sim.cells.tools`), the mass, centre of mass and inertia, collision shapes and an optional
visual mesh::

    name = "bent_torch"
    kind = "torch"                      # "torch", or "gripper" (picks with a [suction] table)
    mass_kg = 1.3
    tcp_mm = [0, 0, 320]                # the wire tip at the nominal stick-out
    tcp_euler_zyx_deg = [0, 0, 0]       # tcp axes in the tool frame; the torch axis is the tcp +z
    stickout_mm = 15                    # torch: the wire (the tool's work geom), back from the tcp
    touch_depth_mm = 0.5                # torch: the wire tip may press this far into the work
    [[shapes]]
    shape = "cylinder"
    from_mm = [0, 0, 0]
    to_mm = [0, 0, 60]
    radius_mm = 30

A tool whose tcp is on the flange axis and not turned is *straight*: the robots' closed forms
take its length as a link length (:func:`sim.cells.compose.RobotRig.kinematics`). Any other tcp
becomes the kinematic model's constant tcp offset, which six-axis arms take and the 5-axis
family refuses unless the tcp lies on its J5 axis (the error says so).

Mass: a ``mass_kg`` on every shape (and ``lip_mass_kg`` for a cup's lip), adding up to the
tool's ``mass_kg``; or ``mass_kg`` with ``com_mm`` and ``inertia_kg_m2`` (principal moments about
the centre of mass, tool axes); or ``mass_kg`` alone, the shapes taken as one uniform solid of
that mass (MuJoCo computes the centre of mass and inertia from their volumes).

Suction: a gripper's ``[suction]`` table makes the cup its own body (``cup``) with a ring of
sphere lips around the tcp that touch parts, and a MuJoCo ``adhesion`` actuator (``suction``)
that pulls a part at the lip's contacts (:mod:`sim.cells.toolspec` names them).

Lengths: a value in mm is read as the metre value it names (``v / 1000``, correctly rounded), so
a file in mm gives the same model as a builder writing metres. A cylinder or capsule along the
tool axis (``from_mm`` and ``to_mm`` on it, ``to_mm`` further out) is written as MuJoCo's
``pos`` and ``size``: the solid MuJoCo makes of its ``fromto``, in the tool's frame (MuJoCo's
``fromto`` turns the geom half a turn about x).

The shipped tools are tool files too (``models/tools``, :mod:`sim.cells.tools`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Literal

import numpy as np
from pydantic import Field

from sim.cells.toolspec import (
    CONTACT_CUP,
    CUP_BODY,
    GRAVITY,
    SUCTION_ACTUATOR,
    SUCTION_SAFETY,
    TIP_SITE,
    ToolSpec,
)
from sim.core.rotations import euler_zyx_to_matrix
from sim.core.text import PlainText
from sim.core.tomlschema import Quantity, Real, Strict, load_toml
from sim.errors import CellError

if TYPE_CHECKING:  # dm_control is imported where a tool model is built
    from dm_control import mjcf

#: A length or coordinate in mm, bounded (10 m: a tool is not bigger).
Mm = Annotated[float, Field(ge=-1e4, le=1e4)]
_NAME = r"^[A-Za-z0-9_-][A-Za-z0-9_.-]*$"

#: The quantities of the per-shape masses and the ``[suction]`` table.
SHAPE_MASS_KG = Quantity("a shape's mass", "kg", 1e-7, 100.0)
ADHESION_N = Quantity("an adhesion force", "N", 1e-3, 1e5)
LIP_RADIUS_MM = Quantity("a lip sphere's radius", "mm", 0.01, 1e3)
RING_RADIUS_MM = Quantity("the radius of the lip ring", "mm", 0.01, 1e3)
GAP_MM = Quantity("a contact gap", "mm", 0.0, 100.0)
SLIDING_FRICTION = Quantity("a sliding friction coefficient", "", 1e-6, 5.0)
SPIN_FRICTION = Quantity("a torsional or rolling friction coefficient", "", 0.0, 1.0)
TIMECONST_S = Quantity("a contact time constant", "s", 1e-4, 10.0)
DAMPRATIO = Quantity("a contact damping ratio", "", 1e-2, 10.0)
IMPEDANCE = Quantity("a contact impedance", "", 1e-4, 0.9999)
WIDTH_M = Quantity("a contact impedance width", "m", 1e-6, 1.0)
MIDPOINT = Quantity("a contact impedance midpoint", "", 1e-4, 0.9999)
POWER = Quantity("a contact impedance power", "", 1.0, 100.0)
ShapeMass = SHAPE_MASS_KG.type
Adhesion = ADHESION_N.type
LipRadius = LIP_RADIUS_MM.type
RingRadius = RING_RADIUS_MM.type
Gap = GAP_MM.type


def _m(mm: float) -> float:
    """mm to m, correctly rounded (``12 mm -> 0.012`` exactly as the literal)."""
    return mm / 1000.0


class ShapeSpec(Strict):
    """A shape of the tool, in the tool frame (mm, deg)."""

    name: str | None = Field(None, pattern=_NAME)
    shape: Literal["box", "cylinder", "capsule", "sphere"]
    size_mm: list[Mm] | None = Field(None, min_length=3, max_length=3)
    radius_mm: float | None = Field(None, gt=0, le=1e4)
    from_mm: list[Mm] | None = Field(None, min_length=3, max_length=3)
    to_mm: list[Mm] | None = Field(None, min_length=3, max_length=3)
    pos_mm: list[Mm] = Field([0.0, 0.0, 0.0], min_length=3, max_length=3)
    euler_zyx_deg: list[float] = Field([0.0, 0.0, 0.0], min_length=3, max_length=3)
    color: list[float] | None = Field(None, min_length=3, max_length=4)
    mass_kg: ShapeMass | None = None
    group: int | None = Field(None, ge=0, le=5)


class SuctionSpec(Strict):
    """A gripper's suction cup: its body's shapes, the ring of lip spheres, the adhesion."""

    gain_n: Adhesion
    lip_count: int = Field(8, ge=3, le=64)
    lip_radius_mm: LipRadius = 3.0
    lip_ring_radius_mm: RingRadius = 17.0
    lip_mass_kg: ShapeMass | None = None
    lip_color: list[float] = Field([0.1, 0.1, 0.1], min_length=3, max_length=4)
    gap_mm: Gap = 3.0
    friction: list[Real] = Field([1.0, 0.005, 0.0001], min_length=3, max_length=3)
    solref: list[Real] = Field([0.002, 1.0], min_length=2, max_length=2)
    solimp: list[Real] = Field([0.95, 0.99, 0.001, 0.5, 2.0], min_length=5, max_length=5)
    shapes: list[ShapeSpec] = []


class ToolFileSpec(Strict):
    """Top level of a tool file."""

    name: str = Field(pattern=_NAME)
    description: PlainText = ""
    kind: Literal["torch", "gripper"] = "torch"
    body: str = Field("tool", pattern=_NAME)
    mass_kg: float = Field(gt=0, le=100)
    max_payload_kg: float | None = Field(None, gt=0, le=10_000)
    com_mm: list[Mm] | None = Field(None, min_length=3, max_length=3)
    inertia_kg_m2: list[Annotated[float, Field(gt=0, le=1e3)]] | None = Field(
        None, min_length=3, max_length=3)
    tcp_mm: list[Mm] = Field(min_length=3, max_length=3)
    tcp_euler_zyx_deg: list[float] = Field([0.0, 0.0, 0.0], min_length=3, max_length=3)
    stickout_mm: float = Field(15.0, gt=0, le=100)
    wire_diameter_mm: float = Field(1.2, gt=0, le=5)
    touch_depth_mm: float = Field(0.5, ge=0, le=5)
    mesh: str | None = None
    mesh_unit: Literal["mm", "m"] = "mm"
    shapes: list[ShapeSpec] = Field(min_length=1)
    suction: SuctionSpec | None = None


#: The keys each shape takes (besides name, shape, color, mass_kg, group).
_SHAPE_KEYS = {"cylinder": ("radius_mm", "from_mm", "to_mm"),
               "capsule": ("radius_mm", "from_mm", "to_mm"),
               "box": ("size_mm", "pos_mm", "euler_zyx_deg"), "sphere": ("radius_mm", "pos_mm")}


def _geom_kwargs(key: str, default_name: str, s: ShapeSpec) -> dict:
    unused = [k for k in ("size_mm", "radius_mm", "from_mm", "to_mm", "pos_mm", "euler_zyx_deg")
              if k in s.model_fields_set and k not in _SHAPE_KEYS[s.shape]]
    if unused:
        raise CellError(f"{key}.{unused[0]}: not used with shape = {s.shape!r} (it takes "
                        f"{', '.join(_SHAPE_KEYS[s.shape])})")
    kw: dict = {"name": s.name or default_name}
    if s.shape in ("cylinder", "capsule"):
        if s.radius_mm is None or s.from_mm is None or s.to_mm is None:
            missing = [k for k in ("radius_mm", "from_mm", "to_mm") if getattr(s, k) is None]
            raise CellError(f"{key}.{missing[0]}: required for a {s.shape}")
        a = np.array([_m(v) for v in s.from_mm])
        b = np.array([_m(v) for v in s.to_mm])
        if np.linalg.norm(b - a) < 1e-6:
            raise CellError(f"{key}.to_mm: from_mm and to_mm coincide")
        if not (a[:2].any() or b[:2].any()) and b[2] > a[2]:  # along the tool axis, outwards
            kw.update(type=s.shape, size=[_m(s.radius_mm), (b[2] - a[2]) / 2],
                      pos=[0.0, 0.0, (a[2] + b[2]) / 2])
        else:
            kw.update(type=s.shape, fromto=[*a, *b], size=[_m(s.radius_mm)])
    elif s.shape == "box":
        if s.size_mm is None or min(s.size_mm) <= 0:
            raise CellError(f"{key}.size_mm: a box needs three positive full extents (mm)")
        kw.update(type="box", size=[v / 2000.0 for v in s.size_mm],
                  pos=[_m(v) for v in s.pos_mm])
        if any(s.euler_zyx_deg):
            R = euler_zyx_to_matrix(*np.deg2rad(s.euler_zyx_deg))
            kw["xyaxes"] = [*R[:, 0], *R[:, 1]]
    else:
        if s.radius_mm is None:
            raise CellError(f"{key}.radius_mm: required for a sphere")
        kw.update(type="sphere", size=[_m(s.radius_mm)], pos=[_m(v) for v in s.pos_mm])
    if s.color is not None:
        kw["rgba"] = [*s.color, 1.0][:4]
    if s.mass_kg is not None:
        kw["mass"] = s.mass_kg
    if s.group is not None:
        kw["group"] = s.group
    return kw


class ToolBuilder:
    """Builds a tool file's MJCF (a class, not a closure, so tools travel to sweep workers).

    Args:
        spec: The file's contents.
        mesh_path: Its visual mesh, or None.
        X: The tcp pose in the tool frame, (4, 4), m.
        wire_from: Where a torch's wire starts (its end is the tcp), m; used when the file
            names no ``wire`` shape.
        geoms: The geoms of the tool body, then of the cup body (``dm_control`` attributes).
        cup_geoms: How many of ``geoms``, at the end, belong to the cup body.
    """

    def __init__(self, spec: ToolFileSpec, mesh_path: Path | None, X: np.ndarray,
                 wire_from: np.ndarray, geoms: list[dict], cup_geoms: int = 0) -> None:
        self.spec, self.mesh_path, self.X, self.wire_from, self.geoms = (
            spec, mesh_path, X, wire_from, geoms)
        self.cup_geoms = cup_geoms

    def __call__(self) -> mjcf.RootElement:
        from dm_control import mjcf

        spec, mesh_path, X = self.spec, self.mesh_path, self.X
        where = str(mesh_path)
        model = mjcf.RootElement(model=spec.name)
        body = model.worldbody.add("body", name=spec.body)
        explicit = spec.com_mm is not None
        massed = any("mass" in kw for kw in self.geoms)
        if explicit:
            body.add("inertial", pos=np.asarray(spec.com_mm) / 1000.0, mass=spec.mass_kg,
                     diaginertia=spec.inertia_kg_m2)
        group = 1 if spec.mesh is None else 3
        split = len(self.geoms) - self.cup_geoms
        cup = None
        for i, kw in enumerate(self.geoms):
            if i == split:
                cup = body.add("body", name=CUP_BODY, pos=[0.0, 0.0, 0.0])
            kw = dict(kw)
            g = kw.pop("group", group)
            if g:
                kw["group"] = g
            if not massed:
                kw["density"] = 0.0 if explicit else 1000.0
            (body if cup is None else cup).add("geom", contype=0, conaffinity=0, **kw)
        if spec.suction is not None and cup is None:
            cup = body.add("body", name=CUP_BODY, pos=[0.0, 0.0, 0.0])
        if spec.kind == "torch" and not any(kw["name"] == "wire" for kw in self.geoms):
            body.add("geom", name="wire", type="cylinder", fromto=[*self.wire_from, *X[:3, 3]],
                     size=[spec.wire_diameter_mm / 2000.0], density=0.0, contype=0,
                     conaffinity=0, rgba=(0.75, 0.75, 0.78, 1.0))
        if mesh_path is not None:
            from sim.cells.meshes import read_mesh

            verts, faces = read_mesh(mesh_path, spec.mesh_unit, where=f"{where}: mesh")
            model.asset.add("mesh", name="tool_mesh", vertex=verts.ravel(), face=faces.ravel())
            body.add("geom", name="mesh", type="mesh", mesh="tool_mesh", contype=0,
                     conaffinity=0, group=1, density=0.0, rgba=(0.3, 0.32, 0.35, 1.0))
        if cup is not None:
            self._lips(cup, massed, explicit)
        tip = {} if np.array_equal(X[:3, :3], np.eye(3)) else {"xyaxes": [*X[:3, 0], *X[:3, 1]]}
        (body if cup is None else cup).add("site", name=TIP_SITE, pos=X[:3, 3], size=[0.002],
                                           rgba=(1.0, 0.2, 0.1, 1.0), **tip)
        if cup is not None:
            model.actuator.add("adhesion", name=SUCTION_ACTUATOR, body=cup, ctrlrange=[0.0, 1.0],
                               gain=spec.suction.gain_n)  # type: ignore[union-attr]
        if not explicit and not massed:
            # uniform solid of the given mass: scale the density so the shapes weigh mass_kg
            import mujoco

            m = mujoco.MjModel.from_xml_string(model.to_xml_string(), model.get_assets())
            total = float(m.body_subtreemass[1])
            for g in body.find_all("geom"):
                if g.density:
                    g.density = 1000.0 * spec.mass_kg / total
        return model

    def _lips(self, cup: mjcf.Element, massed: bool, explicit: bool) -> None:
        """The cup's lip: spheres on a ring around the tcp, their bottoms in the tcp plane."""
        s = self.spec.suction
        assert s is not None
        X = self.X
        r_ball, r_ring, n = _m(s.lip_radius_mm), _m(s.lip_ring_radius_mm), s.lip_count
        mass = ({"mass": s.lip_mass_kg} if massed else
                {"density": 0.0 if explicit else 1000.0})
        for k in range(n):
            phi = 2.0 * np.pi * k / n
            local = np.array([r_ring * np.cos(phi), r_ring * np.sin(phi), -r_ball])
            cup.add("geom", name=f"lip{k}", type="sphere", size=[r_ball],
                    pos=X[:3, 3] + X[:3, :3] @ local, rgba=[*s.lip_color, 1.0][:4],
                    contype=CONTACT_CUP, conaffinity=CONTACT_CUP, condim=4,
                    friction=s.friction, solref=s.solref, solimp=s.solimp, margin=0.0,
                    gap=_m(s.gap_mm), priority=1, **mass)


#: The quantity of each entry of the ``[suction]`` table's contact parameters.
_CONTACT_PARAMS = {"friction": (SLIDING_FRICTION, SPIN_FRICTION, SPIN_FRICTION),
                   "solref": (TIMECONST_S, DAMPRATIO),
                   "solimp": (IMPEDANCE, IMPEDANCE, WIDTH_M, MIDPOINT, POWER)}


def _check_suction(s: SuctionSpec, where: str) -> None:
    for key, quantities in _CONTACT_PARAMS.items():
        for i, (q, v) in enumerate(zip(quantities, getattr(s, key), strict=True)):
            q.read(v, f"{where}: suction.{key}[{i}]", CellError)
    if s.solimp[0] > s.solimp[1]:
        raise CellError(f"{where}: suction.solimp[0]: the impedance at zero depth must not "
                        "exceed the one at full width (solimp[1])")
    if s.lip_ring_radius_mm <= s.lip_radius_mm:
        raise CellError(f"{where}: suction.lip_ring_radius_mm: must exceed lip_radius_mm "
                        "(the lip spheres would overlap at the cup's axis)")


def _check_masses(spec: ToolFileSpec, where: str) -> None:
    shapes = [*spec.shapes, *(spec.suction.shapes if spec.suction else [])]
    given = [s.mass_kg for s in shapes]
    if spec.suction is not None:
        given.append(spec.suction.lip_mass_kg)
    if all(m is None for m in given):
        return
    if any(m is None for m in given):
        key = ("suction.lip_mass_kg" if given[-1] is None and spec.suction is not None
               else "mass_kg")
        raise CellError(f"{where}: {key}: give a mass on every shape (and the lip's "
                        "suction.lip_mass_kg) or on none")
    if spec.com_mm is not None:
        raise CellError(f"{where}: com_mm: not used when every shape has its mass_kg")
    total = math.fsum(m for m in given[:len(shapes)] if m is not None)
    if spec.suction is not None:
        total += spec.suction.lip_count * (spec.suction.lip_mass_kg or 0.0)
    if abs(total - spec.mass_kg) > 0.01 * spec.mass_kg:
        raise CellError(f"{where}: mass_kg: the shapes' masses add up to {total:.6g} kg, more "
                        f"than 1 % off the tool's {spec.mass_kg:g} kg")


def load_tool_file(path: str | Path, *, shipped: bool = False) -> ToolSpec:
    """Read a tool file into a :class:`ToolSpec` whose builder makes its MJCF.

    Args:
        path: The tool file.
        shipped: A tool cellsim ships (``models/tools``), not a user's own.

    Raises:
        CellError: Unreadable file, unknown key, bad value, missing mesh; one line naming the
            file and the key.
    """
    path = Path(path)
    spec, _ = load_toml(path, ToolFileSpec, CellError)
    where = str(path)
    geoms = [_geom_kwargs(f"{where}: shapes[{i}]", f"shape{i}", s)
             for i, s in enumerate(spec.shapes)]
    suction = spec.suction
    if suction is not None:
        n = len(geoms)
        geoms += [_geom_kwargs(f"{where}: suction.shapes[{i}]", f"shape{n + i}", s)
                  for i, s in enumerate(suction.shapes)]
        if spec.kind != "gripper":
            raise CellError(f"{where}: suction: only a gripper has a suction cup "
                            f"(kind = {spec.kind!r})")
        _check_suction(suction, where)
    names = [g["name"] for g in geoms]
    reserved = {"mesh"} | ({"wire"} if spec.kind != "torch" else set())
    if suction is not None:
        reserved |= {f"lip{k}" for k in range(suction.lip_count)}
    dup = {n for n in names if names.count(n) > 1} | (reserved & set(names))
    if dup:
        raise CellError(f"{where}: shapes: the name {sorted(dup)[0]!r} is used twice (or is "
                        "reserved: 'wire' is a gripper's, 'mesh' the visual mesh, 'lipN' the "
                        "cup's lip)")
    if spec.kind != "torch" and "touch_depth_mm" in spec.model_fields_set:
        raise CellError(f"{where}: touch_depth_mm: only a torch's wire touches the work "
                        f"(kind = {spec.kind!r})")
    if (spec.com_mm is None) != (spec.inertia_kg_m2 is None):
        raise CellError(f"{where}: com_mm and inertia_kg_m2 go together (give both or neither)")
    if spec.inertia_kg_m2 is not None:
        Ia, Ib, Ic = sorted(spec.inertia_kg_m2)
        if Ia <= 0 or Ia + Ib < Ic:
            raise CellError(f"{where}: inertia_kg_m2: principal moments must be positive and "
                            "satisfy the triangle inequality")
    _check_masses(spec, where)
    mesh_path = None
    if spec.mesh is not None:
        from sim.cells.meshes import read_mesh

        mesh_path = (path.parent / spec.mesh).resolve()
        read_mesh(mesh_path, spec.mesh_unit, where=f"{where}: mesh")  # checked now, not later
    X = np.eye(4)
    X[:3, :3] = euler_zyx_to_matrix(*np.deg2rad(spec.tcp_euler_zyx_deg))
    X[:3, 3] = [_m(v) for v in spec.tcp_mm]
    straight = bool(np.hypot(X[0, 3], X[1, 3]) < 1e-12 and np.allclose(X[:3, :3], np.eye(3)))
    if straight and X[2, 3] <= 0:
        raise CellError(f"{where}: tcp_mm: the tool centre point must lie beyond the flange face")
    wire_from = X[:3, 3] - _m(spec.stickout_mm) * X[:3, 2]
    payload: float | None
    if suction is not None:
        work: tuple[str, ...] = tuple(f"lip{k}" for k in range(suction.lip_count))
        payload = spec.max_payload_kg or suction.gain_n / (GRAVITY * SUCTION_SAFETY)
    else:
        work, payload = ("wire",) if spec.kind == "torch" else (), spec.max_payload_kg
    return ToolSpec(
        name=spec.name, description=spec.description or f"tool file {path.name}",
        mass_kg=spec.mass_kg,
        length_m=float(X[2, 3]) if straight else float(np.linalg.norm(X[:3, 3])),
        kind=spec.kind, suction_gain_n=0.0 if suction is None else suction.gain_n,
        max_payload_kg=payload, work_geoms=work,
        tcp_in_tool=None if straight else tuple(tuple(float(v) for v in row) for row in X),
        stickout_m=_m(spec.stickout_mm), touch_depth_m=_m(spec.touch_depth_mm),
        source=path.resolve(), shipped=shipped,
        builder=ToolBuilder(spec, mesh_path, X, wire_from, geoms,
                            len(suction.shapes) if suction else 0))


__all__ = ["ShapeSpec", "SuctionSpec", "ToolBuilder", "ToolFileSpec", "load_tool_file"]
