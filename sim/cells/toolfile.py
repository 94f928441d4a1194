"""Tools as data: a TOML file describing an end-of-arm tool (format: ``docs/cell-format.md``).

A tool file gives the tool centre point in the *tool frame* (origin on the flange face, ``+z``
out of the flange along the approach axis, as for the shipped tools of
:mod:`sim.cells.tools`), the mass, centre of mass and inertia, collision shapes and an optional
visual mesh::

    name = "bent_torch"
    kind = "torch"                      # "torch" (a gripper file picks nothing: no suction)
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

Mass: ``mass_kg`` with ``com_mm`` and ``inertia_kg_m2`` (principal moments about the centre of
mass, tool axes) when given; without them the shapes are taken as one uniform solid of that
mass (MuJoCo computes the centre of mass and inertia from their volumes).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Literal

import numpy as np
from pydantic import Field

from sim.cells.tools import TIP_SITE, ToolSpec
from sim.core.rotations import euler_zyx_to_matrix
from sim.core.text import PlainText
from sim.core.tomlschema import Strict, load_toml
from sim.errors import CellError

if TYPE_CHECKING:  # dm_control is imported where a tool model is built
    from dm_control import mjcf

#: A length or coordinate in mm, bounded (10 m: a tool is not bigger).
Mm = Annotated[float, Field(ge=-1e4, le=1e4)]
_NAME = r"^[A-Za-z0-9_-][A-Za-z0-9_.-]*$"


class ShapeSpec(Strict):
    """A collision shape of the tool, in the tool frame (mm, deg)."""

    name: str | None = Field(None, pattern=_NAME)
    shape: Literal["box", "cylinder", "capsule", "sphere"]
    size_mm: list[Mm] | None = Field(None, min_length=3, max_length=3)
    radius_mm: float | None = Field(None, gt=0, le=1e4)
    from_mm: list[Mm] | None = Field(None, min_length=3, max_length=3)
    to_mm: list[Mm] | None = Field(None, min_length=3, max_length=3)
    pos_mm: list[Mm] = Field([0.0, 0.0, 0.0], min_length=3, max_length=3)
    euler_zyx_deg: list[float] = Field([0.0, 0.0, 0.0], min_length=3, max_length=3)
    color: list[float] | None = Field(None, min_length=3, max_length=4)


class ToolFileSpec(Strict):
    """Top level of a tool file."""

    name: str = Field(pattern=_NAME)
    description: PlainText = ""
    kind: Literal["torch", "gripper"] = "torch"
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


#: The keys each shape takes (besides name, shape, color).
_SHAPE_KEYS = {"cylinder": ("radius_mm", "from_mm", "to_mm"),
               "capsule": ("radius_mm", "from_mm", "to_mm"),
               "box": ("size_mm", "pos_mm", "euler_zyx_deg"), "sphere": ("radius_mm", "pos_mm")}


def _geom_kwargs(i: int, s: ShapeSpec, where: str) -> dict:
    key = f"{where}: shapes[{i}]"
    unused = [k for k in ("size_mm", "radius_mm", "from_mm", "to_mm", "pos_mm", "euler_zyx_deg")
              if k in s.model_fields_set and k not in _SHAPE_KEYS[s.shape]]
    if unused:
        raise CellError(f"{key}.{unused[0]}: not used with shape = {s.shape!r} (it takes "
                        f"{', '.join(_SHAPE_KEYS[s.shape])})")
    kw: dict = {"name": s.name or f"shape{i}"}
    R = euler_zyx_to_matrix(*np.deg2rad(s.euler_zyx_deg))
    if s.shape in ("cylinder", "capsule"):
        if s.radius_mm is None or s.from_mm is None or s.to_mm is None:
            missing = [k for k in ("radius_mm", "from_mm", "to_mm") if getattr(s, k) is None]
            raise CellError(f"{key}.{missing[0]}: required for a {s.shape}")
        a, b = np.asarray(s.from_mm) * 1e-3, np.asarray(s.to_mm) * 1e-3
        if np.linalg.norm(b - a) < 1e-6:
            raise CellError(f"{key}.to_mm: from_mm and to_mm coincide")
        kw.update(type=s.shape, fromto=[*a, *b], size=[s.radius_mm * 1e-3])
    elif s.shape == "box":
        if s.size_mm is None or min(s.size_mm) <= 0:
            raise CellError(f"{key}.size_mm: a box needs three positive full extents (mm)")
        kw.update(type="box", size=np.asarray(s.size_mm) * 0.5e-3,
                  pos=np.asarray(s.pos_mm) * 1e-3, xyaxes=[*R[:, 0], *R[:, 1]])
    else:
        if s.radius_mm is None:
            raise CellError(f"{key}.radius_mm: required for a sphere")
        kw.update(type="sphere", size=[s.radius_mm * 1e-3], pos=np.asarray(s.pos_mm) * 1e-3)
    if s.color is not None:
        kw["rgba"] = [*s.color, 1.0][:4]
    return kw


class _ToolBuilder:
    """Builds a tool file's MJCF (a class, not a closure, so tools travel to sweep workers)."""

    def __init__(self, spec: ToolFileSpec, mesh_path: Path | None, X: np.ndarray,
                 wire_from: np.ndarray, geoms: list[dict]) -> None:
        self.spec, self.mesh_path, self.X, self.wire_from, self.geoms = (
            spec, mesh_path, X, wire_from, geoms)

    def __call__(self) -> mjcf.RootElement:
        from dm_control import mjcf

        spec, mesh_path, X, wire_from, geoms = (self.spec, self.mesh_path, self.X,
                                                self.wire_from, self.geoms)
        mass = spec.mass_kg
        where = str(mesh_path)
        model = mjcf.RootElement(model=spec.name)
        body = model.worldbody.add("body", name="tool")
        explicit = spec.com_mm is not None
        if explicit:
            body.add("inertial", pos=np.asarray(spec.com_mm) * 1e-3, mass=mass,
                     diaginertia=spec.inertia_kg_m2)
        for kw in geoms:
            body.add("geom", contype=0, conaffinity=0, group=1 if spec.mesh is None else 3,
                     density=0.0 if explicit else 1000.0, **kw)
        if spec.kind == "torch":
            body.add("geom", name="wire", type="cylinder", fromto=[*wire_from, *X[:3, 3]],
                     size=[spec.wire_diameter_mm * 0.5e-3], density=0.0, contype=0,
                     conaffinity=0, rgba=(0.75, 0.75, 0.78, 1.0))
        if mesh_path is not None:
            from sim.cells.meshes import read_mesh

            verts, faces = read_mesh(mesh_path, spec.mesh_unit, where=f"{where}: mesh")
            model.asset.add("mesh", name="tool_mesh", vertex=verts.ravel(), face=faces.ravel())
            body.add("geom", name="mesh", type="mesh", mesh="tool_mesh", contype=0,
                     conaffinity=0, group=1, density=0.0, rgba=(0.3, 0.32, 0.35, 1.0))
        body.add("site", name=TIP_SITE, pos=X[:3, 3], xyaxes=[*X[:3, 0], *X[:3, 1]],
                 size=[0.002], rgba=(1.0, 0.2, 0.1, 1.0))
        if not explicit:
            # uniform solid of the given mass: scale the density so the shapes weigh mass_kg
            import mujoco

            m = mujoco.MjModel.from_xml_string(model.to_xml_string(), model.get_assets())
            total = float(m.body_mass[1])
            for g in body.find_all("geom"):
                if g.density:
                    g.density = 1000.0 * mass / total
        return model


def load_tool_file(path: str | Path) -> ToolSpec:
    """Read a tool file into a :class:`ToolSpec` whose builder makes its MJCF.

    Raises:
        CellError: Unreadable file, unknown key, bad value, missing mesh; one line naming the
            file and the key.
    """
    path = Path(path)
    spec, _ = load_toml(path, ToolFileSpec, CellError)
    where = str(path)
    geoms = [_geom_kwargs(i, s, where) for i, s in enumerate(spec.shapes)]
    names = [g["name"] for g in geoms]
    dup = {n for n in names if names.count(n) > 1} | ({"wire", "mesh"} & set(names))
    if dup:
        raise CellError(f"{where}: shapes: the name {sorted(dup)[0]!r} is used twice (or is "
                        "reserved: 'wire' is the torch's wire, 'mesh' the visual mesh)")
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
    mesh_path = None
    if spec.mesh is not None:
        from sim.cells.meshes import read_mesh

        mesh_path = (path.parent / spec.mesh).resolve()
        read_mesh(mesh_path, spec.mesh_unit, where=f"{where}: mesh")  # checked now, not later
    X = np.eye(4)
    X[:3, :3] = euler_zyx_to_matrix(*np.deg2rad(spec.tcp_euler_zyx_deg))
    X[:3, 3] = np.asarray(spec.tcp_mm) * 1e-3
    straight = bool(np.hypot(X[0, 3], X[1, 3]) < 1e-12 and np.allclose(X[:3, :3], np.eye(3)))
    if straight and X[2, 3] <= 0:
        raise CellError(f"{where}: tcp_mm: the tool centre point must lie beyond the flange face")
    axis = X[:3, 2]
    wire_from = X[:3, 3] - spec.stickout_mm * 1e-3 * axis
    mass = spec.mass_kg

    return ToolSpec(
        name=spec.name, description=spec.description or f"tool file {path.name}",
        mass_kg=mass, length_m=float(np.linalg.norm(X[:3, 3])), kind=spec.kind,
        max_payload_kg=spec.max_payload_kg,
        work_geoms=("wire",) if spec.kind == "torch" else (),
        tcp_in_tool=None if straight else tuple(tuple(float(v) for v in row) for row in X),
        stickout_m=spec.stickout_mm * 1e-3, touch_depth_m=spec.touch_depth_mm * 1e-3,
        source=path.resolve(),
        builder=_ToolBuilder(spec, mesh_path, X, wire_from, geoms))


__all__ = ["ToolFileSpec", "load_tool_file"]
