"""Trajectory planners of cellsim.

Joint-space piecewise polynomials through via points (4-3-4 after seed 001, 5-4-6 after
seed 000) and Cartesian ADNIA interpolation of the tool point (seed 003). Every planner
returns a trajectory with ``duration``, ``at(t)`` and ``sample(dt)``.

Cartesian moves are built from separate parts: geometric paths by arc length
(:mod:`planners.paths`), time laws (:mod:`planners.profiles`), tool-frame laws
(:mod:`planners.rotations`), their trajectories and move builders (:mod:`planners.cartesian`),
corner blends and weaves on top (:mod:`planners.blend`, :mod:`planners.weave`); seed 003's
algorithm itself is :mod:`planners.adnia` (which re-exports the moves).

Planners work in SI units: seconds, radians (joints) and metres (Cartesian).
"""

from typing import TYPE_CHECKING, Any

from planners.errors import (
    InvalidBoundaryError,
    InvalidKnotsError,
    LimitViolationError,
    PlannerError,
    UnknownPlannerError,
)

if TYPE_CHECKING:
    from planners.limits import LimitViolation, check_limits, find_limit_violations
    from planners.poly434 import plan_434
    from planners.poly546 import plan_546
    from planners.registry import PLANNERS, get_planner
    from planners.trajectory import PiecewisePolynomialTrajectory, TrajectoryExtrema

#: The planners' names, imported on first use (the errors above import nothing heavy: a
#: process that only needs cellsim's exception tree, a video worker, does not load SciPy).
_LAZY = {"LimitViolation": "planners.limits", "check_limits": "planners.limits",
         "find_limit_violations": "planners.limits", "plan_434": "planners.poly434",
         "plan_546": "planners.poly546", "PLANNERS": "planners.registry",
         "get_planner": "planners.registry", "PiecewisePolynomialTrajectory": "planners.trajectory",
         "TrajectoryExtrema": "planners.trajectory"}


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'planners' has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


__all__ = [
    "PlannerError",
    "InvalidKnotsError",
    "InvalidBoundaryError",
    "LimitViolationError",
    "UnknownPlannerError",
    "plan_434",
    "plan_546",
    "PLANNERS",
    "get_planner",
    "PiecewisePolynomialTrajectory",
    "TrajectoryExtrema",
    "LimitViolation",
    "check_limits",
    "find_limit_violations",
]
