"""Cells layer: tools, seams and the welding and pick cells composed with ``dm_control.mjcf``
(robot + tool + fixtures + parts). May import: planners, :mod:`sim.errors`, :mod:`sim.core`,
:mod:`sim.robots`.

Public API::

    from sim.cells import CELLS, Cell, Seam, build_cell
    cell = build_cell(CELLS["weld_cylinder"], ROBOTS["robot_5r"], mount="floor")
    model = cell.compile()                      # mujoco.MjModel, keyframe "home"

Cells are data (``docs/cell-format.md``): :data:`CELLS` holds the shipped cell files of
``models/cells/`` (written by ``models/cells/generate.py`` from the Python derivations in
:data:`DERIVED`; each module's docstring gives its dimensions and the reasons for them), and a
scenario may name a cell file of its own (:func:`resolve_cell`, :func:`load_cell`; the format's
reader is :mod:`sim.cells.cellfile`, meshes :mod:`sim.cells.meshes`, tool files
:mod:`sim.cells.toolfile`).

===============  ======================  ===============  ================  =================
cell             robots                  default tool     tools allowed     mounts
===============  ======================  ===============  ================  =================
weld_cylinder    robot_5r                mig_torch_long   mig_torch_long    floor, ceiling
weld_table       lrmate100ib, 200ic5l    mig_torch        mig_torch(_long)  floor
pick             lrmate200ic5l           vacuum_gripper   vacuum_gripper    floor
(a cell file)    every robot, or its     its ``tool``     its ``tools``,    its ``[robot]
                 ``[robot] model``                        else any          mount``
(None: bare)     every robot             none             any, or none      floor, ceiling
===============  ======================  ===============  ================  =================

A tool file of the kind a shipped cell works with (a torch for the welding cells) is taken too.

The package, one concept per module: :mod:`~sim.cells.spec` (what a cell is: :class:`CellSpec`,
:class:`Cell`), :mod:`~sim.cells.registry` (the shipped cells, read on first use, and resolving
a scenario's cell and tool references), :mod:`~sim.cells.builder` (:func:`build_cell`);
:mod:`~sim.cells.compose` (the shared MJCF composition), :mod:`~sim.cells.tools` and
:mod:`~sim.cells.toolfile` (tools), :mod:`~sim.cells.seam` (seams). This module only re-exports.

Names in the compiled model: robot joints ``robot/j1..jN``, actuators ``robot/a1..aN`` (the
drives) and ``robot/friction_j1..`` (each joint's Coulomb friction, :mod:`sim.cells.compose`),
sites ``robot/frame0``, ``robot/flange``, ``robot/tcp`` (moved onto the tool tip), tool elements
``robot/tool/...`` (tip site ``robot/tool/tip``, suction ``robot/tool/suction``), payload body
``robot/payload`` (at the tcp; massless, its marker invisible, at 0 kg); cell elements keep
their plain names (``part0``, cameras ``overview`` and ``tool``). A cell file's other robots
(``[[robots]]``, :mod:`~sim.cells.partners`) have the same names under their own name
(``r2/j1``, ``r2/a1``, ``r2/tcp``, ``r2/tool/...``); their joints follow the first robot's and
the mechanisms' axes in :attr:`Cell.joint_names`.
"""

from sim.cells.builder import CELL_DEFAULT, build_cell, resolve_tool
from sim.cells.partners import CellRobot, PlacedRobot
from sim.cells.registry import (
    BARE,
    CELLS,
    DERIVED,
    is_file_ref,
    load_cell,
    resolve_cell,
    tool_from_ref,
)
from sim.cells.seam import Seam
from sim.cells.spec import MOUNTS, NO_TOOL, Cell, CellSpec

__all__ = ["BARE", "CELLS", "CELL_DEFAULT", "DERIVED", "MOUNTS", "NO_TOOL", "Cell", "CellRobot",
           "CellSpec", "PlacedRobot", "Seam", "build_cell", "is_file_ref", "load_cell",
           "resolve_cell", "resolve_tool", "tool_from_ref"]
