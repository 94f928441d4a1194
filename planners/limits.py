"""Joint limit checks of a planned trajectory: position range, |velocity|, |acceleration|.

The worst value of every joint and quantity is taken from the exact extremes of the
polynomials (:meth:`PiecewisePolynomialTrajectory.extrema`) and, as a cross-check and for any
:class:`planners.base.Trajectory` without ``extrema``, from a dense sampling. Limits and the
values kept in the violations are SI (rad, rad/s, rad/s^2); messages show degrees for
readability.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planners.base import Trajectory
from planners.errors import InvalidBoundaryError, LimitViolationError
from planners.knot_system import per_joint_array

#: Relative slack before a value counts as exceeding its limit (rounding, not tolerance).
RELATIVE_SLACK = 1e-9

_UNITS = {"position": "deg", "velocity": "deg/s", "acceleration": "deg/s^2"}


@dataclass(frozen=True)
class LimitViolation:
    """One joint exceeding one limit, at its worst.

    Attributes:
        joint: Joint index, 0-based.
        joint_name: Name used in messages.
        quantity: "position", "velocity" or "acceleration".
        time: Time of the worst value, s (knot clock).
        value: Worst value: the position itself for position limits, the signed velocity or
            acceleration otherwise (rad, rad/s, rad/s^2).
        limit: The limit exceeded (the lower or upper bound, or the magnitude limit), SI.
        first_time: First sampled time at which the limit is exceeded, s.
        linear: The joint is linear (a track's): values in m, messages in mm.
    """

    joint: int
    joint_name: str
    quantity: str
    time: float
    value: float
    limit: float
    first_time: float
    linear: bool = False

    def message(self) -> str:
        """One-line description, in degrees (a linear joint's in mm)."""
        unit = _UNITS[self.quantity]
        deg = np.degrees
        if self.linear:
            unit = unit.replace("deg", "mm")

            def deg(x: float) -> float:
                return 1e3 * x
        if self.quantity == "position":
            side = "below lower" if self.value < self.limit else "above upper"
            what = f"position {deg(self.value):.4g} {unit} is {side} limit {deg(self.limit):.4g} {unit}"
        else:
            what = (f"{self.quantity} {deg(self.value):.4g} {unit} exceeds limit "
                    f"+/-{deg(self.limit):.4g} {unit}")
        return (f"joint {self.joint_name}: {what} at t={self.time:.4f} s "
                f"(first exceeded at t={self.first_time:.4f} s)")


def _per_joint(name: str, value: ArrayLike | None, n: int) -> NDArray[np.float64] | None:
    if value is None:
        return None
    v = per_joint_array(name, value, n, "limits")
    if np.any(np.isnan(v)):
        raise InvalidBoundaryError(f"{name}: limits must not be NaN (use inf for no limit)")
    return v


def find_limit_violations(traj: Trajectory, *, lower: ArrayLike | None = None,
                          upper: ArrayLike | None = None, max_velocity: ArrayLike | None = None,
                          max_acceleration: ArrayLike | None = None,
                          joint_names: Sequence[str] | None = None, dt: float | None = None,
                          linear: Sequence[bool] | None = None) -> list[LimitViolation]:
    """Every (joint, quantity) whose limit the trajectory exceeds, without raising.

    Args:
        traj: A trajectory; ``extrema()`` is used when it has one.
        lower, upper: Position limits, rad: scalar or shape (n_joints,); None to skip.
        max_velocity: |velocity| limit, rad/s: scalar or (n_joints,); None to skip.
        max_acceleration: |acceleration| limit, rad/s^2: scalar or (n_joints,); None to skip.
        joint_names: Names for messages; default "j1", "j2", ...
        dt: Sampling period, s; default: 2000 samples over the duration and at least 20 per
            segment when the trajectory has knots.
        linear: Per joint, whether it is linear (m; its messages in mm); default none is.

    Returns:
        Violations ordered by joint, then position (lower, upper), velocity, acceleration.

    Raises:
        InvalidBoundaryError: A limit of the wrong shape or NaN, or wrong joint_names length.
    """
    # Dense sampling (also for trajectories without knots or extrema).
    if dt is None:
        knots = getattr(traj, "knots", None)
        t0 = float(getattr(traj, "start", 0.0))
        times = np.linspace(t0, t0 + traj.duration, 2001)
        if knots is not None:
            k = np.asarray(knots, dtype=float)
            per_seg = k[:-1, None] + np.diff(k)[:, None] * np.linspace(0, 1, 21)[None, :]
            times = np.unique(np.concatenate([times, per_seg.ravel(), k]))
        states = traj.at(times)
    else:
        times, states = traj.sample(dt)
    n = states.q.shape[-1]
    names = list(joint_names) if joint_names is not None else [f"j{i + 1}" for i in range(n)]
    if len(names) != n:
        raise InvalidBoundaryError(f"joint_names: {len(names)} name(s) given for {n} joints")
    lo = _per_joint("lower", lower, n)
    hi = _per_joint("upper", upper, n)
    vmax = _per_joint("max_velocity", max_velocity, n)
    amax = _per_joint("max_acceleration", max_acceleration, n)
    ext = traj.extrema() if hasattr(traj, "extrema") else None

    def worst(series: NDArray[np.float64], j: int, sign: float, exact: tuple[float, float] | None
              ) -> tuple[float, float]:
        """Largest sign*value of joint j (sampled, or exact if larger): (value, time)."""
        i = int(np.argmax(sign * series[:, j]))
        val, t = float(series[i, j]), float(times[i])
        if exact is not None and sign * exact[0] >= sign * val:
            val, t = exact
        return val, t

    def first(mask: NDArray[np.bool_], t_worst: float) -> float:
        return float(times[np.argmax(mask)]) if mask.any() else t_worst

    lin = [False] * n if linear is None else [bool(x) for x in linear]
    out: list[LimitViolation] = []
    for j in range(n):
        if lo is not None:
            ex = (float(ext.q_min[j]), float(ext.q_min_time[j])) if ext is not None else None
            val, t = worst(states.q, j, -1.0, ex)
            lim = float(lo[j])
            if val < lim - RELATIVE_SLACK * max(1.0, abs(lim)):
                out.append(LimitViolation(j, names[j], "position", t, val, lim,
                                          first(states.q[:, j] < lim, t), lin[j]))
        if hi is not None:
            ex = (float(ext.q_max[j]), float(ext.q_max_time[j])) if ext is not None else None
            val, t = worst(states.q, j, 1.0, ex)
            lim = float(hi[j])
            if val > lim + RELATIVE_SLACK * max(1.0, abs(lim)):
                out.append(LimitViolation(j, names[j], "position", t, val, lim,
                                          first(states.q[:, j] > lim, t), lin[j]))
        for quantity, series, lim_arr, peak, tpk in (
                ("velocity", states.qd, vmax, "qd_peak", "qd_time"),
                ("acceleration", states.qdd, amax, "qdd_peak", "qdd_time")):
            if lim_arr is None:
                continue
            lim = abs(float(lim_arr[j]))
            i = int(np.argmax(np.abs(series[:, j])))
            val, t = float(series[i, j]), float(times[i])
            if ext is not None and float(getattr(ext, peak)[j]) >= abs(val):
                t = float(getattr(ext, tpk)[j])
                # Signed value at the exact peak time.
                val = float(getattr(traj.at(t), {"velocity": "qd", "acceleration": "qdd"}[quantity])[j])
                val = np.copysign(float(getattr(ext, peak)[j]), val)
            if abs(val) > lim * (1.0 + RELATIVE_SLACK):
                out.append(LimitViolation(j, names[j], quantity, t, float(val), lim,
                                          first(np.abs(series[:, j]) > lim, t), lin[j]))
    return out


def check_limits(traj: Trajectory, *, lower: ArrayLike | None = None,
                 upper: ArrayLike | None = None, max_velocity: ArrayLike | None = None,
                 max_acceleration: ArrayLike | None = None,
                 joint_names: Sequence[str] | None = None, dt: float | None = None) -> None:
    """Raise on the first limit the trajectory exceeds (see :func:`find_limit_violations`).

    Raises:
        LimitViolationError: Names the joint, quantity, time, value and limit (degrees in the
            message, SI in the attributes); says how many other violations there are.
        InvalidBoundaryError: A limit of the wrong shape.
    """
    found = find_limit_violations(traj, lower=lower, upper=upper, max_velocity=max_velocity,
                                  max_acceleration=max_acceleration, joint_names=joint_names,
                                  dt=dt)
    if found:
        v = found[0]
        more = f" (and {len(found) - 1} more violation(s))" if len(found) > 1 else ""
        raise LimitViolationError(v.message() + more, joint=v.joint, quantity=v.quantity,
                                  time=v.time, value=v.value, limit=v.limit)
