"""Composing a cell for a robot: :func:`build_cell` (the robot, its tool and payload, the cell's
world and the ``home`` keyframe) and the checks of what a cell takes (:func:`resolve_tool`)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from sim.cells.compose import (
    ROBOT_PREFIX,
    Ring,
    add_home_keyframe,
    prepare_robot,
    suction_actuator_name,
    tip_site_name,
)
from sim.cells.mechanisms import tune_gains
from sim.cells.registry import BARE, tool_from_ref
from sim.cells.spec import MOUNTS, NO_TOOL, Cell, CellSpec
from sim.cells.tools import TOOLS, ToolSpec
from sim.errors import CellError, UnknownNameError
from sim.robots.registry import RobotSpec


def _check_payload(payload_kg: float) -> float:
    try:
        p = float(payload_kg)
    except (TypeError, ValueError):
        raise CellError(f"payload_kg must be a number >= 0 (kg), got {payload_kg!r}") from None
    if not math.isfinite(p) or p < 0.0:
        raise CellError(f"payload_kg must be a finite number >= 0 (kg), got {payload_kg!r}")
    return p


#: ``build_cell(..., tool=CELL_DEFAULT)``: the cell's default tool.
CELL_DEFAULT = object()


def resolve_tool(cell: CellSpec, name: str | None, base: Path | None = None
                 ) -> ToolSpec | None:
    """The tool a cell gets for a requested tool name.

    Args:
        cell: The cell (:data:`BARE` for the robot alone).
        name: A tool name, a tool file (``*.toml``, relative to ``base``), ``None`` for the
            cell's default tool, or ``"none"`` for no tool.
        base: Folder that a tool file's path is relative to (the scenario's).

    Raises:
        UnknownNameError: Unknown tool (the message lists the tools).
        CellError: The cell does not take that tool (the message lists the ones it takes).
    """
    if name is None:
        return cell.default_tool
    if name == NO_TOOL:
        return None
    tool = tool_from_ref(name, base)
    _check_tool(cell, tool)
    return tool


def _check_tool(cell: CellSpec, tool: ToolSpec | None) -> None:
    if tool is None:
        if cell.needs_tool:
            raise CellError(f"cell {cell.name!r} needs a tool; tools: "
                            f"{', '.join(t.name for t in cell.tools) or ', '.join(TOOLS)} "
                            "or a tool file")
        return
    if cell.any_tool or cell is BARE:
        return
    if not tool.shipped:  # a tool file of its own: any tool of the kind the cell works with
        kinds = sorted({t.kind for t in cell.tools})
        if tool.kind not in kinds:
            raise CellError(f"cell {cell.name!r} works with a {' or '.join(kinds)}; tool "
                            f"{tool.name!r} ({tool.source}) is a {tool.kind}")
        return
    if tool not in cell.tools and tool != cell.default_tool:
        raise CellError(f"cell {cell.name!r} does not take tool {tool.name!r}; tools: "
                        f"{', '.join(sorted({*(t.name for t in cell.tools), NO_TOOL}))}")


def build_cell(cell: CellSpec | None, robot: RobotSpec, *,
               tool: ToolSpec | None | object = CELL_DEFAULT, mount: str = "floor",
               payload_kg: float = 0.0) -> Cell:
    """Compose a cell for a robot.

    Args:
        cell: The cell (an entry of :data:`CELLS`), or None for the robot's bare scene.
        robot: The robot.
        tool: The tool, None for no tool, or :data:`CELL_DEFAULT` for the cell's default tool
            (bare scene: no tool); :func:`resolve_tool` turns a scenario's tool name into one.
        mount: ``"floor"`` or ``"ceiling"`` (each cell lists the ones it supports).
        payload_kg: Lumped payload at the tcp, kg (>= 0).

    Returns:
        The composed :class:`Cell` (its ``mjcf`` compiles; keyframe ``home`` added).

    Raises:
        UnknownNameError: Unknown mount (the message lists the valid ones).
        CellError: Robot, tool or mount not supported by the cell, negative payload.
    """
    cspec = BARE if cell is None else cell
    spec_r = robot
    if not cspec.any_robot and spec_r.name not in cspec.robots:
        raise CellError(f"cell {cspec.name!r} is not built for robot {spec_r.name!r}; "
                        f"robots: {', '.join(cspec.robots)}")
    if mount not in MOUNTS:
        raise UnknownNameError("mount", str(mount), MOUNTS)
    if mount not in cspec.mounts:
        raise CellError(f"cell {cspec.name!r} does not support mount {mount!r}; "
                        f"mounts: {', '.join(cspec.mounts)}")
    tool_spec = cspec.default_tool if tool is CELL_DEFAULT else tool
    assert tool_spec is None or isinstance(tool_spec, ToolSpec)
    _check_tool(cspec, tool_spec)
    payload = _check_payload(payload_kg)

    rig = prepare_robot(spec_r, tool_spec, payload)
    layout = cspec.build(rig, mount)
    home_q = layout.home_q if layout.home_q is not None else rig.home_q
    compiled, home_qpos = add_home_keyframe(layout.world, rig, home_q, layout.mechanisms,
                                            layout.partners)
    if layout.mechanisms:
        tune_gains(layout.world, layout.mechanisms, compiled, home_qpos)
    p = ROBOT_PREFIX
    axes = [n for pm in layout.mechanisms for n in pm.joint_names]
    friction = [a.friction for pm in layout.mechanisms for a in pm.spec.axes]
    for cr in layout.partners:  # the other robots' joints after the axes
        axes += list(cr.placed.joint_names)
        friction += list(cr.rig.statics.frictionloss)
    actuators = axes[:len(axes) - sum(cr.robot.n_joints for cr in layout.partners)] + [
        a for cr in layout.partners for a in cr.placed.actuator_names]
    return Cell(
        name=cspec.name, robot=spec_r, tool=tool_spec, mount=mount, mjcf=layout.world,
        joint_names=[f"{p}/{j}" for j in spec_r.joints] + axes,
        actuator_names=[f"{p}/a{i + 1}" for i in range(spec_r.n_joints)] + actuators,
        tcp_site=f"{p}/tcp", frame0_site=f"{p}/frame0", flange_site=f"{p}/flange",
        seams=layout.seams, parts=layout.parts, slots=layout.slots, cameras=layout.cameras,
        world_from_frame0=layout.world_from_frame0,
        adhesion_actuator=suction_actuator_name(rig), home_q=np.asarray(home_q, float),
        start_q=layout.start_q, payload_kg=payload, tip_site=tip_site_name(rig),
        dims={k: float(v) for k, v in layout.dims.items()}, description=cspec.description,
        frictionloss=np.concatenate([rig.statics.frictionloss, friction]),
        objects={name: tuple(g.full_identifier for g in geoms)
                 for name, geoms in layout.objects.items()},
        seam_objects=dict(layout.seam_objects), frames=dict(layout.frames),
        source=cspec.source, _rig=rig,
        rings={name: dict(geoms.params) for name, geoms in layout.objects.items()
               if isinstance(geoms, Ring)}, mechanisms=layout.mechanisms,
        partners=layout.partners)


__all__ = ["CELL_DEFAULT", "build_cell", "resolve_tool"]
