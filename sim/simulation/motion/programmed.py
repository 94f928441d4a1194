"""A Cartesian phase as programmed: the moves ``cellsim export`` writes as TP motion lines.

Owns :class:`ProgrammedMove` (end pose, via pose, speed, blend), a planned move as its
programmed moves (:func:`_programmed`: an arc of more than 170 deg in pieces), a blended
polyline's legs and corner-zone points (:func:`_programmed_legs`); the TP blend share
:data:`~sim.scenario.program.CNT_SHARE` is the program reader's.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.scenario.program import CNT_SHARE


@dataclass(frozen=True)
class ProgrammedMove:
    """A Cartesian move as programmed (frame 0): its end pose (and via pose for an arc), the
    blend radius into the next move (m, 0: it stops there), its length and the next move's.
    What ``cellsim export`` writes as a TP motion line."""

    kind: str
    end: NDArray[np.float64]
    via: NDArray[np.float64] | None
    speed: float
    blend: float = 0.0
    length: float = 0.0
    next_length: float = 0.0


def _programmed(cart: Any, kind: str, speed: float, blend: float = 0.0,
                next_length: float = 0.0) -> list[ProgrammedMove]:
    """The move as programmed: one entry, or for an arc of more than 170 deg one per piece of
    at most 170 deg (a TP circular move through three points cannot close a circle), the
    pieces stopping at their ends and the last keeping the blend."""
    L = cart.length
    sweep = float(getattr(cart.path, "sweep", 0.0))
    pieces = max(1, int(np.ceil(np.degrees(sweep) / 170.0 - 1e-9))) if kind == "circular" else 1

    def pose(s: float) -> NDArray[np.float64]:
        T = np.eye(4)
        T[:3, 3] = cart.path.evaluate(np.array([s]))[0][0]
        T[:3, :3] = cart.orientation.evaluate(np.array([s / L]))[0][0]
        return T

    out = []
    for k in range(pieces):
        s0, s1 = L * k / pieces, L * (k + 1) / pieces
        last = k == pieces - 1
        out.append(ProgrammedMove(kind, pose(s1), pose(0.5 * (s0 + s1)) if kind == "circular"
                                  else None, speed, blend if last else 0.0, s1 - s0,
                                  next_length if last else 0.0))
    return out


#: An exported polyline's points where its corner zones begin and end blend over this share
#: of the shorter adjacent move (CNT20: the rounding stays near the zone's ends).
ZONE_POINT_CNT = 0.2
#: Moves an exported polyline takes across each corner zone (to its planned poses there).
ZONE_POINTS = 1


def _programmed_legs(path: Any, t_start: float, t_end: float,
                     corners: list[tuple[float, float]], speed: float) -> list[ProgrammedMove]:
    """A polyline phase as TP moves, from its planned tool path (``path.at(t)``, the phase's
    window ``[t_start, t_end]`` and its corners' time windows, on the path's clock): each leg
    to where its corner zone begins at the set speed, then :data:`ZONE_POINTS` moves across
    the zone to poses of the plan there, each timed as planned (slower where the corner was
    slowed for the turn), and a ``FINE`` stop on the seam's end. A TP linear move turns the
    torch evenly between its ends, so one point per corner would turn it over the whole next
    leg; these points keep each leg's posture and turn it inside the zone, as planned."""
    times = [float(t) for ta, tb in corners
             for t in ta + (tb - ta) * np.arange(ZONE_POINTS + 1) / ZONE_POINTS] + [t_end]
    st = path.at(np.array([t_start, *times]))
    out = []
    for j, t in enumerate(times):
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = st.rotation[j + 1], st.position[j + 1]
        length = float(np.linalg.norm(st.position[j + 1] - st.position[j]))
        t_prev = t_start if j == 0 else times[j - 1]
        in_zone = any(ta + 1e-12 < t <= tb + 1e-12 for ta, tb in corners)
        v = min(speed, length / max(t - t_prev, 1e-9)) if in_zone else speed
        nxt = (float(np.linalg.norm(st.position[j + 2] - st.position[j + 1]))
               if j + 1 < len(times) else 0.0)
        blend = ZONE_POINT_CNT * CNT_SHARE * min(length, nxt) if nxt > 0 else 0.0
        out.append(ProgrammedMove("linear", T, None, v, blend, length, nxt))
    return out
