"""The 5-4-6 joint-space planner with jerk continuity (seed 000, Kacso et al., eq. 18-24).

Through knots tau_0 < tau_1 < ... < tau_m (m >= 2 segments) every joint follows

* segment 1: a quintic in t = (tau - tau_0) / t_1 in [0, 1]                       (eq. 19)
* segments 2 .. m-1: quartics in t = (tau - tau_{k-1}) / t_k in [0, 1]             (eq. 20)
* segment m: a sextic in t_bar = (tau - tau_m) / t_m in [-1, 0]                    (eq. 22)

with position, velocity, acceleration and jerk given at both ends (eq. 18; zero by default),
the knot positions met and velocity, acceleration and jerk continuous at every interior knot
(eq. 21). That is 5m + 3 coefficients per joint and as many conditions, found by one banded
solve for all joints at once (:mod:`planners.knot_system`).

Two segments (m = 2) give a quintic followed by a sextic (5-6): 13 coefficients, 4 + 4
boundary conditions and 5 at the single interior knot.

The printed system of the seed (eq. 23-24) has misprints (signs, and ``q0`` terms where the
end values belong); the implementation imposes the conditions of eq. 18 and 21 directly.

Note: a chain of quartics that interpolates the knots with continuous jerk is an even-degree
spline; its knot-to-knot transfer has an eigenvalue -1 for equal durations, so a disturbance
(a boundary condition, an uneven knot) does not die out along the chain: with many segments
the 5-4-6 velocity can alternate from segment to segment. 4-3-4 (cubic middle segments)
damps such disturbances by a factor about 3.7 per knot.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from planners.knot_system import solve_piecewise, validate_boundary, validate_knots
from planners.trajectory import PiecewisePolynomialTrajectory


def degrees_546(n_segments: int) -> np.ndarray:
    """Segment degrees of a 5-4-6 trajectory: 5, 4, ..., 4, 6 (5, 6 for two segments)."""
    deg = np.full(n_segments, 4, dtype=np.int64)
    deg[0], deg[-1] = 5, 6
    return deg


def plan_546(times: ArrayLike, q: ArrayLike, *, v0: ArrayLike | None = None,
             vf: ArrayLike | None = None, a0: ArrayLike | None = None,
             af: ArrayLike | None = None, j0: ArrayLike | None = None,
             jf: ArrayLike | None = None) -> PiecewisePolynomialTrajectory:
    """Plan a 5-4-6 trajectory through the knots (seed 000 eq. 18-24).

    Args:
        times: Knot times tau_0 .. tau_m, s, shape (m+1,), strictly increasing, m >= 2.
        q: Knot positions, shape (m+1, n_joints) (rad; 1-D means one joint).
        v0, vf: Velocity at tau_0 / tau_m, rad/s: None (0), scalar or shape (n_joints,).
        a0, af: Acceleration at tau_0 / tau_m, rad/s^2: the same.
        j0, jf: Jerk at tau_0 / tau_m, rad/s^3: the same.

    Returns:
        The trajectory; ``planner == "546"``.

    Raises:
        InvalidKnotsError: Bad ``times`` or ``q``.
        InvalidBoundaryError: A boundary value of the wrong shape or not finite.
    """
    t, qa = validate_knots(times, q)
    nj = qa.shape[1]
    start = [validate_boundary("v0", v0, nj), validate_boundary("a0", a0, nj),
             validate_boundary("j0", j0, nj)]
    end = [validate_boundary("vf", vf, nj), validate_boundary("af", af, nj),
           validate_boundary("jf", jf, nj)]
    deg = degrees_546(t.size - 1)
    coef = solve_piecewise(t, qa, deg, start, end)
    return PiecewisePolynomialTrajectory(t, coef, deg, planner="546")
