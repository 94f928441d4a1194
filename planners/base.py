"""The interface every cellsim trajectory shares.

Joint-space planners (4-3-4, 5-4-6) and the Cartesian ADNIA interpolator all return objects
with ``duration``, ``at(t)`` and ``sample(dt)``; code that only drives or plots a trajectory
depends on :class:`Trajectory` alone.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planners.errors import UsageError


@dataclass(frozen=True)
class JointState:
    """Joint-space state at one or many times.

    Each array has shape (n_joints,) for a scalar time, or (N, n_joints) for N times.
    Units: rad, rad/s, rad/s^2, rad/s^3 (or whatever unit the knots were given in).
    """

    q: NDArray[np.float64]
    qd: NDArray[np.float64]
    qdd: NDArray[np.float64]
    qddd: NDArray[np.float64]


@runtime_checkable
class Trajectory(Protocol):
    """What every planner returns."""

    @property
    def duration(self) -> float:
        """Total duration, s."""
        ...

    def at(self, t: ArrayLike):
        """State at time(s) ``t``, s, on the trajectory's own clock (that of its knot times)."""
        ...

    def sample(self, dt: float):
        """``(times, states)`` at a fixed period ``dt`` (s), first and last time included."""
        ...


def sample_times(t0: float, t1: float, dt: float) -> NDArray[np.float64]:
    """Times from ``t0`` to ``t1`` every ``dt`` seconds; ``t1`` is always the last sample.

    Raises:
        ValueError: ``dt`` is not a positive finite number.
    """
    if not np.isfinite(dt) or dt <= 0:
        raise UsageError(f"sample period dt must be a positive number of seconds, got {dt!r}")
    n = int(np.floor((t1 - t0) / dt + 1e-9))
    t = t0 + dt * np.arange(n + 1)
    if t1 - t[-1] > 1e-12 * max(1.0, abs(t1)):
        t = np.append(t, t1)
    else:
        t[-1] = t1
    return t
