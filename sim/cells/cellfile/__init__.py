"""Cells as data: a TOML file lays out a user's cell (format and figure: ``docs/cell-format.md``).

A cell file places the robot's base, the static objects (fixtures, workpieces: boxes,
cylinders, spheres, STL/OBJ meshes), the parts that can be picked, the weld seams (in their
workpiece's frame, with AWS work and travel angles), the slots parts go to and the cameras.
:func:`read_cell_file` reads and checks it once (every problem is one line naming the file and
the key) and :func:`make_builder` gives the builder that composes the world around any robot
(:func:`sim.cells.load_cell` wraps both into a :class:`sim.cells.CellSpec`); the scenario names
the file (``cell = "cells/my_cell.toml"``, relative to the scenario).

Frames and units: lengths in mm and angles in deg in the file, SI inside. ``pos_mm`` and
``euler_zyx_deg`` place an object in world (``R = Rz(a) Ry(b) Rx(c)``); a box is centred on its
position, a cylinder too with its axis along the object's z. The robot base frame (the MJCF
model's origin: the base plane on the J1 axis) is at ``base_pos_mm`` turned by
``base_euler_zyx_deg``; ``mount = "ceiling"`` turns it further by 180 deg about its x axis (J1
pointing down), so ``base_pos_mm`` is then where the base plane meets the ceiling.

The package, one concept per module, each importing only those before it:
:mod:`~sim.cells.cellfile.schema` (the keys, pydantic) <- :mod:`~sim.cells.cellfile.solids`
(objects as solids: poses, distances, mesh pieces) <- :mod:`~sim.cells.cellfile.seams` (seams in
world, the torch-angle convention and the stand-off) <- :mod:`~sim.cells.cellfile.reader` (the
file checked as a whole: :class:`CellFile`) <- :mod:`~sim.cells.cellfile.builder` (the MJCF
world around a robot rig).
"""

from sim.cells.cellfile.builder import FileBuilder, make_builder
from sim.cells.cellfile.reader import CellFile, read_cell_file
from sim.cells.cellfile.schema import (
    CameraBlock,
    CellFileSpec,
    ObjectBlock,
    RobotBlock,
    SeamBlock,
    SlotBlock,
)

__all__ = ["CameraBlock", "CellFile", "CellFileSpec", "FileBuilder", "ObjectBlock", "RobotBlock",
           "SeamBlock", "SlotBlock", "make_builder", "read_cell_file"]
