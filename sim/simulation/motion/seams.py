"""The cell's seams as the motion uses them: by name, a seam end as a tool pose, and
whether a 5-axis arm can hold a seam's torch posture.

Owns :func:`_seam` (a seam by name, the error listing the cell's), :func:`_seam_pose` (the
tcp pose of a ``to_seam`` target, backed off along the torch axis) and
:func:`_check_five_axis_torch` (a 5-axis arm holds its torch only in the vertical plane
through J1 and the tool point).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.errors import ReachError, ScenarioError
from sim.simulation.motion.context import CartesianContext


def _seam(ctx: CartesianContext, name: str, label: str) -> Any:
    if name not in ctx.seams:
        from sim.errors import UnknownNameError

        raise ScenarioError(f"{label}: {UnknownNameError('seam', name, ctx.seams)}")
    return ctx.seams[name]


def _seam_pose(tgt: Any, ctx: CartesianContext, label: str) -> NDArray[np.float64]:
    """The tcp pose (frame 0) of a seam target: the seam's start or end tool point in its
    torch posture there, moved ``tgt.offset`` back along the torch axis (``approach_mm``,
    ``retract_mm``)."""
    seam = _seam(ctx, tgt.seam, f"{label}.to_seam")
    s = 0.0 if tgt.seam_end == "start" else seam.length()
    if ctx.kinematics.family.five_axis:
        _check_five_axis_torch(seam, label, "to_seam", at=(s,))
    T = np.eye(4)
    T[:3, 3] = ctx.to_frame0(seam.tcp_point(s) - tgt.offset * seam.torch_axis(s))
    T[:3, :3] = ctx.rot_to_frame0(seam.torch_rotation(s))
    return T


def _check_five_axis_torch(seam: Any, label: str, key: str = "seam",
                           at: tuple[float, ...] | None = None) -> None:
    """A 5-axis arm holds its torch in the vertical plane through J1 and the tool point: a
    seam's work and travel angles that leave that plane somewhere along it cannot be held.
    The error names the angle (work, travel or both), the seam point, and the nearest angles
    the arm can hold there (the torch axis projected into the plane)."""
    from sim.robots.families.five_r import PLANE_TOL

    limit = float(np.degrees(np.arcsin(PLANE_TOL)))
    for s in (at if at is not None else np.linspace(0.0, seam.length(), 41)):
        dev = seam.plane_deviation_deg(float(s))
        if dev <= limit:
            continue
        T = seam.world_from_frame0
        k1, o1 = T[:3, 2], T[:3, 3]
        p = seam.point(float(s))
        d = p - o1
        rho = d - (d @ k1) * k1
        m = np.cross(k1, rho / np.linalg.norm(rho))
        a = seam.torch_axis(float(s))
        a2 = a - (a @ m) * m
        a2 /= np.linalg.norm(a2)
        t = seam.tangent(float(s))
        n = seam.surface_normal - (seam.surface_normal @ t) * t
        n /= np.linalg.norm(n)
        e = seam.torch_side * np.cross(n, t)
        tau = float(np.degrees(np.arcsin(np.clip(a2 @ t, -1.0, 1.0))))
        perp = a2 - (a2 @ t) * t
        w_int = float(np.degrees(np.arctan2(-(perp @ e), -(perp @ n))))
        work, work_set = 90.0 - w_int, 90.0 - seam.torch_work_angle_deg
        travel_set = seam.torch_travel_angle_deg
        which = [name for name, have, want in (("work", work, work_set),
                                               ("travel", tau, travel_set))
                 if abs(have - want) > 0.05]
        raise ReachError(
            f"{label}.{key}: a 5-axis arm cannot hold the {' and '.join(which) or 'work/travel'}"
            f" angle{'s' if len(which) > 1 else ''} of seam {seam.name!r} at {s * 1e3:.1f} mm "
            "from its start: "
            f"its torch stays in the vertical plane through J1 (the seam's posture is "
            f"{dev:.2f} deg out of it); there it can hold work {work:.1f} deg, travel "
            f"{tau:.1f} deg (set: work {work_set:.1f}, travel {travel_set:.1f})")
