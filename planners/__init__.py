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

from planners.errors import (
    InvalidBoundaryError,
    InvalidKnotsError,
    LimitViolationError,
    PlannerError,
    UnknownPlannerError,
)
from planners.limits import LimitViolation, check_limits, find_limit_violations
from planners.poly434 import plan_434
from planners.poly546 import plan_546
from planners.registry import PLANNERS, get_planner
from planners.trajectory import PiecewisePolynomialTrajectory, TrajectoryExtrema

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
