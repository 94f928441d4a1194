"""The inputs of a Cartesian move checked, and its number of sampling periods.

Owns the checks every Cartesian move and path makes of what it is given (a point of three
finite coordinates, a positive finite number, two points that do not coincide, a step count),
each raising :class:`planners.errors.InvalidMoveError` (or a subclass) that names the field,
and seed 003's step count ``N = round(L / (v dt))`` (eq. 5, 14: :func:`adnia_step_count`),
which the discrete ADNIA (:mod:`planners.adnia`) and the continuous moves' constant-speed
part (:meth:`planners.cartesian.CartesianTrajectory.constant_speed_steps`) both take.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planners.errors import CoincidentPointsError, InvalidMoveError

#: Points closer than this (relative to max(1, coordinate size)) are taken as coincident.
_COINCIDENT_TOL = 1e-9
#: Three points whose sine of the angle at the first point is below this are collinear.
_COLLINEAR_TOL = 1e-9


def _point(value: ArrayLike, field: str) -> NDArray[np.float64]:
    try:
        p = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidMoveError(f"{field}: expected 3 coordinates (x, y, z), got {value!r}") from None
    if p.shape != (3,):
        raise InvalidMoveError(f"{field}: expected 3 coordinates (x, y, z), got shape {p.shape}")
    if not np.all(np.isfinite(p)):
        raise InvalidMoveError(f"{field}: coordinates must be finite, got {p.tolist()}")
    return p


def _positive(value: float, field: str, unit: str) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InvalidMoveError(f"{field}: expected a positive number of {unit}, got {value!r}") from None
    if not math.isfinite(x) or x <= 0.0:
        raise InvalidMoveError(f"{field}: must be a positive finite number of {unit}, got {value!r}")
    return x


def _distinct(p: NDArray[np.float64], q: NDArray[np.float64], what: str) -> float:
    d = float(np.linalg.norm(q - p))
    scale = max(1.0, float(np.max(np.abs(p))), float(np.max(np.abs(q))))
    if d <= _COINCIDENT_TOL * scale:
        raise CoincidentPointsError(f"{what} coincide ({p.tolist()}); a move needs distinct points")
    return d


def _steps(value: int, field: str = "steps") -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise InvalidMoveError(f"{field}: must be a positive integer number of sampling periods, got {value!r}")
    return int(value)


def adnia_step_count(length: float, speed: float, dt: float) -> tuple[int, float]:
    """Number of sampling periods N of a move, seed 003 eq. (5) and (14).

    ``N = round(L / (v dt))`` with halves rounded up and N >= 1 (a move shorter than half a step
    still takes one step).

    Args:
        length: Path length L (any length unit).
        speed: Tool speed v (same length unit per second).
        dt: Controller sampling period, s.

    Returns:
        ``(N, L / (v dt))``: the step count and the unrounded ratio.
    """
    length = _positive(length, "length", "length units")
    speed = _positive(speed, "speed", "length units per second")
    dt = _positive(dt, "dt", "s")
    ratio = length / (speed * dt)
    return max(1, int(math.floor(ratio + 0.5))), ratio


def _step_count(length: float, speed: float | None, dt: float | None, steps: int | None
                ) -> tuple[int, float]:
    if steps is not None:
        n = _steps(steps)
        ratio = (length / (_positive(speed, "speed", "length units per second") * _positive(dt, "dt", "s"))
                 if speed is not None and dt is not None else float("nan"))
        return n, ratio
    if speed is None or dt is None:
        raise InvalidMoveError("steps: give either steps=N or both speed and dt (eq. 5: N = round(L/(v dt)))")
    return adnia_step_count(length, speed, dt)
