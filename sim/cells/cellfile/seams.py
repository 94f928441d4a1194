"""A cell file's seams as :class:`~sim.cells.seam.Seam` objects in world.

Seam torch angles (AWS A3.0 terms; the file's convention, converted for :class:`Seam`):

* ``work_angle_deg``: angle between the torch axis and the reference surface (the plane whose
  outward ``normal`` the seam gives), measured in the plane perpendicular to the seam; 90 deg
  puts the torch along ``-normal``, 45 deg is the usual fillet posture. The torch leans to the
  ``lean`` side (``"left"`` or ``"right"`` of the travel direction, seen from the torch side);
* ``travel_angle_deg``: tilt in the plane of the torch axis and the seam, positive = push
  (the torch points ahead), negative = drag.

:class:`Seam` measures its work angle from the normal, so it receives ``90 - work_angle_deg``.

A seam's ``ctwd_mm`` (contact-tip-to-work distance; ``stickout_mm`` is the same distance under
its older name, and a seam gives at most one of the two) becomes its stand-off,
``Seam.standoff_m = ctwd - the torch's nominal stick-out``: the tool point (the wire tip at the
nominal stick-out) then runs that far back from the seam along the torch axis, on lines, arcs
and polylines alike (:mod:`sim.cells.seam`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from sim.cells.cellfile.schema import SeamBlock
from sim.cells.seam import Seam
from sim.cells.tools import ToolSpec
from sim.errors import CellError, CellsimError

#: The shortest seam, mm, through its points: anything shorter is a mistake.
MIN_SEAM_MM = 1.0

#: A seam too short whose every coordinate is at most this (mm) was typed in metres.
METRES_LOOK_MM = 5.0


def seam_points(sb: SeamBlock, key: str) -> NDArray[np.float64]:
    """A seam block's points, m (N, 3), checked: as many as its kind takes, three values
    each, finite, and at least :data:`MIN_SEAM_MM` long through them."""
    want = {"line": "2", "arc": "3 (start, via, end)", "polyline": "at least 2"}[sb.kind]
    ok = {"line": len(sb.points_mm) == 2, "arc": len(sb.points_mm) == 3,
          "polyline": len(sb.points_mm) >= 2}[sb.kind]
    if not ok:
        raise CellError(f"{key}.points_mm: a {sb.kind} seam takes {want} points, got "
                        f"{len(sb.points_mm)}")
    for k, p in enumerate(sb.points_mm):
        if len(p) != 3:
            raise CellError(f"{key}.points_mm[{k}]: {len(p)} values; a point is [x, y, z] mm")
    pts = np.asarray(sb.points_mm, dtype=float) * 1e-3
    if not np.all(np.isfinite(pts)):
        raise CellError(f"{key}.points_mm: must be finite numbers")
    # the length through the given points (an arc's through its via point): no weld seam is
    # shorter than a millimetre, and one that is was typed in metres (0.4 for 400 mm)
    length_mm = float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1))) * 1e3
    if 0.0 < length_mm < MIN_SEAM_MM:  # (coinciding points are named by the seam itself)
        mm = np.asarray(sb.points_mm, dtype=float)
        hint = ""
        if np.max(np.abs(mm)) <= METRES_LOOK_MM:  # every coordinate a few "mm": metres
            hint = (f": typed in metres? ({mm[0].tolist()} would be {(mm[0] * 1e3).tolist()} "
                    "mm)")
        raise CellError(f"{key}.points_mm: the seam is {length_mm:.3g} mm long through its "
                        f"points (at least {MIN_SEAM_MM:g} mm); points_mm are millimetres in "
                        f"the object's frame{hint}")
    return pts


def ctwd_key(sb: SeamBlock) -> str | None:
    """The key that sets a seam's contact-tip-to-work distance (``ctwd_mm`` or its synonym
    ``stickout_mm``), or None."""
    if sb.ctwd_mm is not None:
        return "ctwd_mm"
    return "stickout_mm" if sb.stickout_mm is not None else None


def seam_standoff(sb: SeamBlock, i: int, tool: ToolSpec | None, where: str) -> float:
    """A seam's stand-off, m (:mod:`sim.cells.seam`): its contact-tip-to-work distance less
    the torch's nominal stick-out; 0 when the seam gives none.

    Raises:
        CellError: The distance is shorter than the nominal stick-out: the modelled wire (that
            long) would reach into the work.
    """
    key = ctwd_key(sb)
    if key is None:
        return 0.0
    ctwd = float(getattr(sb, key)) * 1e-3
    if tool is None or tool.kind != "torch":
        return ctwd
    try:
        return tool.standoff(ctwd)
    except CellsimError as exc:
        raise CellError(f"{where}: seams[{i}].{key}: {exc}; give at least the nominal, or a "
                        "tool with a shorter stickout_mm") from None


def seam_in_world(sb: SeamBlock, T_obj: NDArray[np.float64], pts: NDArray[np.float64], *,
                   tool_axis: int, world_from_frame0: NDArray[np.float64],
                   standoff: float) -> Seam:
    R, t = T_obj[:3, :3], T_obj[:3, 3]
    normal = np.asarray(sb.normal, dtype=float)
    if not np.all(np.isfinite(normal)) or np.linalg.norm(normal) < 1e-9:
        raise CellsimError("normal: must be a non-zero vector")
    return Seam(name=sb.name, kind=sb.kind, points=pts @ R.T + t, normal=None,
                torch_work_angle_deg=90.0 - sb.work_angle_deg,
                torch_travel_angle_deg=sb.travel_angle_deg,
                surface_normal=R @ (normal / np.linalg.norm(normal)),
                torch_side=1 if sb.lean == "left" else -1, tool_axis=tool_axis,
                world_from_frame0=world_from_frame0, description=sb.description,
                standoff_m=standoff)


__all__ = ["METRES_LOOK_MM", "MIN_SEAM_MM", "ctwd_key", "seam_in_world", "seam_points", "seam_standoff"]
