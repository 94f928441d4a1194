"""The 4-3-4 joint-space planner (seed 001, Bugnar, eq. 5-17).

Through knots tau_0 < tau_1 < ... < tau_n (n >= 2 segments) every joint follows

* segment 1: a quartic in t = (tau - tau_0) / t_1 in [0, 1]                      (eq. 5)
* segments 2 .. n-1: cubics in t = (tau - tau_{i-1}) / t_i in [0, 1]             (eq. 11)
* segment n: a quartic in t_bar = (tau - tau_n) / t_n in [-1, 0]                 (eq. 8-9)

with position, velocity and acceleration given at both ends (eq. 12, 17; zero by default) and
the knot positions met and velocity and acceleration continuous at every interior knot
(eq. 13-16). With n = 2 there is no cubic: the trajectory is 4-4. There are 4n + 2
coefficients per joint and as many conditions; they are found by one banded solve for all
joints at once (:mod:`planners.knot_system`). The jerk is piecewise linear and jumps at
interior knots.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from planners.errors import InvalidBoundaryError
from planners.knot_system import solve_piecewise, validate_boundary, validate_knots
from planners.trajectory import PiecewisePolynomialTrajectory


def degrees_434(n_segments: int) -> np.ndarray:
    """Segment degrees of a 4-3-4 trajectory: 4, 3, ..., 3, 4 (4, 4 for two segments)."""
    deg = np.full(n_segments, 3, dtype=np.int64)
    deg[0] = deg[-1] = 4
    return deg


def plan_434(times: ArrayLike, q: ArrayLike, *, v0: ArrayLike | None = None,
             vf: ArrayLike | None = None, a0: ArrayLike | None = None,
             af: ArrayLike | None = None, j0: ArrayLike | None = None,
             jf: ArrayLike | None = None) -> PiecewisePolynomialTrajectory:
    """Plan a 4-3-4 trajectory through the knots (seed 001 eq. 5-17).

    Args:
        times: Knot times tau_0 .. tau_n, s, shape (n+1,), strictly increasing, n >= 2.
        q: Knot positions, shape (n+1, n_joints) (rad; 1-D means one joint).
        v0, vf: Velocity at tau_0 / tau_n, rad/s: None (0), scalar or shape (n_joints,).
        a0, af: Acceleration at tau_0 / tau_n, rad/s^2: the same.
        j0, jf: Not accepted (a 4-3-4 trajectory has no jerk conditions); present only so
            that every registered planner takes the same keywords.

    Returns:
        The trajectory; ``planner == "434"``.

    Raises:
        InvalidKnotsError: Bad ``times`` or ``q``.
        InvalidBoundaryError: A boundary value of the wrong shape or not finite, or j0/jf
            given.
    """
    for name, value in (("j0", j0), ("jf", jf)):
        if value is not None:
            raise InvalidBoundaryError(
                f"{name}: the 4-3-4 planner has no jerk boundary conditions; "
                "use planner '546' to impose a boundary jerk")
    t, qa = validate_knots(times, q)
    nj = qa.shape[1]
    start = [validate_boundary("v0", v0, nj), validate_boundary("a0", a0, nj)]
    end = [validate_boundary("vf", vf, nj), validate_boundary("af", af, nj)]
    deg = degrees_434(t.size - 1)
    coef = solve_piecewise(t, qa, deg, start, end)
    return PiecewisePolynomialTrajectory(t, coef, deg, planner="434")
