"""Registry of the joint-space planners by name.

``PLANNERS`` maps ``"434"`` (seed 001) and ``"546"`` (seed 000) to their planning functions;
both take ``(times, q, *, v0, vf, a0, af, j0, jf)`` and return a
:class:`planners.trajectory.PiecewisePolynomialTrajectory` (4-3-4 rejects j0/jf).
"""

from __future__ import annotations

import difflib
from typing import Callable

from planners.errors import UnknownPlannerError
from planners.poly434 import plan_434
from planners.poly546 import plan_546
from planners.trajectory import PiecewisePolynomialTrajectory

Planner = Callable[..., PiecewisePolynomialTrajectory]

#: Planner name -> planning function.
PLANNERS: dict[str, Planner] = {"434": plan_434, "546": plan_546}


def get_planner(name: str) -> Planner:
    """The planning function called ``name`` ("434" or "546"; "4-3-4" and "5-4-6" also work).

    Raises:
        UnknownPlannerError: Unknown name; the message lists the valid names.
    """
    key = str(name).strip().replace("-", "")
    if key in PLANNERS:
        return PLANNERS[key]
    valid = sorted(PLANNERS)
    close = difflib.get_close_matches(key, valid, n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    raise UnknownPlannerError(f"planner: unknown planner {name!r}{hint}; known: {', '.join(valid)}")
