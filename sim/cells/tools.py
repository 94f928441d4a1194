"""The shipped end-of-arm tools: :data:`TOOLS`, read on first use from the tool files of
``models/tools`` (the same reader and format as a user's tool file: :mod:`sim.cells.toolfile`,
``docs/cell-format.md``), and :func:`build_tool`, a tool's MJCF.

Every tool is built in its own *tool frame*: origin on the robot's flange face, ``+z`` along the
flange's approach axis (out of the flange), so that a tool is *straight*: its tool centre point
(site ``tip``) lies on the flange axis at ``(0, 0, length_m)``, with the orientation of the tool
frame. The seeds' closed-form kinematics therefore still hold with the tool length added (5R
family: ``l3_eff = (J4 axis -> flange) + length_m``; LR Mate 200iC: ``r = length_m`` in seed 004
eq. 6-7). :mod:`sim.cells` attaches a tool at the robot's ``flange`` site, turning the tool frame
so that its ``+z`` is the flange approach axis, and moves the robot's ``tcp`` site onto the tool
tip.

The shipped tools (each file's comments give its parts, masses and materials):

``mig_torch`` - a straight robotic MIG/MAG torch, 145 mm from the flange face to the wire tip
(the LR Mate 100iB's l3 = 225 mm = 80 mm flange + 145 mm torch), 1.0 kg.

``mig_torch_long`` - the same design for the large 5R welding robot, 300 mm (the 5R robot's
l3 = 400 mm = 100 mm flange + 300 mm torch), 1.70 kg.

``vacuum_gripper`` - a single Ø40 mm suction cup on a stem, 100 mm from the flange face to the
cup lip, 0.25 kg: a cup body (``cup``) with a ring of 8 lip spheres and a MuJoCo ``adhesion``
actuator (``suction``, 40 N at ``ctrl = 1``).

With its default torch each robot's tcp is where the seed dimensions put it, so
``sim/robots/registry.py``'s dims hold as they are in the welding cells. Touch sensing (the wire
tip set on the root with the arc off) may press the tip up to ``touch_depth_m`` = 0.5 mm beyond
the wire's radius into the work (:mod:`sim.simulation.collisions`). Torch geoms do not collide
with anything (``contype = conaffinity = 0``).

Integrator: with a suction tool the cell switches the model from ``implicitfast`` to ``implicit``:
with ``implicitfast`` a 0.5 kg part held by adhesion started to tumble and the simulation diverged
within 0.35 s of lifting, while ``implicit``, ``Euler`` and ``RK4`` held it (see
:func:`sim.cells.compose.prepare_robot`).

:class:`~sim.cells.toolspec.ToolSpec` and the names a tool model and a cell agree on live in
:mod:`sim.cells.toolspec`; they are re-exported here.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

from planners.registry import Registry
from sim.cells.toolfile import load_tool_file
from sim.cells.toolspec import (
    CONTACT_CUP,
    CONTACT_FIXTURE,
    CONTACT_PART_AFFINITY,
    CONTACT_PART_TYPE,
    CUP_BODY,
    GRAVITY,
    SUCTION_ACTUATOR,
    SUCTION_SAFETY,
    TIP_SITE,
    VACUUM_TIME_CONSTANT_S,
    ToolSpec,
)
from sim.core.registry import LazyRegistry
from sim.core.resources import models_dir
from sim.errors import InternalError

if TYPE_CHECKING:  # dm_control is imported where a tool model is built
    from dm_control import mjcf


def tools_dir() -> Path:
    """Folder of the shipped tool files (``models/tools``)."""
    return models_dir() / "tools"


def _shipped_tools() -> Iterator[tuple[str, ToolSpec]]:
    """The shipped tool files, by name (the file's stem is the tool's name)."""
    for path in sorted(tools_dir().glob("*.toml")):
        spec = load_tool_file(path, shipped=True)
        if spec.name != path.stem:
            raise InternalError(f"{path}: name {spec.name!r} is not the file's name")
        yield spec.name, spec


#: The shipped tools by name, read from ``models/tools/*.toml`` on first use.
TOOLS: Registry[ToolSpec] = LazyRegistry("tool", _shipped_tools)


def get_tool(name: str) -> ToolSpec:
    """Look a tool up by name.

    Raises:
        UnknownNameError: Not a registered tool; the message lists the known ones.
    """
    return TOOLS.get(name)


def build_tool(spec: ToolSpec) -> mjcf.RootElement:
    """Build a tool's MJCF model in its tool frame (origin on the flange face, +z out).

    Args:
        spec: The tool.

    Returns:
        A ``dm_control.mjcf`` model named ``name`` with one top-level body, a site ``tip`` at
        the tool centre point and, for a suction gripper, a body ``cup`` and an adhesion
        actuator ``suction``.
    """
    if spec.builder is None:
        raise InternalError(f"tool {spec.name!r} has no builder (a ToolSpec is made by "
                            "sim.cells.toolfile.load_tool_file)")
    return spec.builder()  # type: ignore[return-value]


__all__ = ["CONTACT_CUP", "CONTACT_FIXTURE", "CONTACT_PART_AFFINITY", "CONTACT_PART_TYPE",
           "CUP_BODY", "GRAVITY", "SUCTION_ACTUATOR", "SUCTION_SAFETY", "TIP_SITE", "TOOLS",
           "VACUUM_TIME_CONSTANT_S", "ToolSpec", "build_tool", "get_tool", "tools_dir"]
