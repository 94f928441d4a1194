"""Time law s(t) of a Cartesian move: smooth start, constant speed, smooth stop.

Seed 003 (ADNIA) interpolates at a *constant* tool speed and says that "the acceleration and
the deceleration of the movement are not included in those computations ... the number of
steps N must be adapted ... the length L is shorter, the difference is the linear distance
necessary for acceleration and deceleration". This module supplies that missing part: a path
parameter ``s(t)`` (arc length along the move, m) that

* starts and ends at rest (``s' = s'' = s''' = 0`` at both ends when ``ramp_time > 0``),
* ramps the speed up over ``ramp_time`` with a polynomial smoothstep ``v h(t / T)``,
* runs at the constant speed ``v`` in between (the seed's ADNIA part),
* ramps down symmetrically; the ramps are taken out of the move's own length, as the seed says.

Smoothstep shapes ``h`` (``h(0) = 0``, ``h(1) = 1``):

* ``"quintic"``: ``h = 10 x^3 - 15 x^4 + 6 x^5``; ``h' = h'' = 0`` at both ends, so the tool's
  velocity, acceleration and jerk are continuous (jerk-limited start and stop).
* ``"septic"``: ``h = 35 x^4 - 84 x^5 + 70 x^6 - 20 x^7``; also ``h''' = 0`` at the ends
  (continuous snap as well).

Both have ``integral(h, 0, 1) = 1/2``, so each ramp covers ``v T / 2`` and the move lasts
``L / v + T``. A move shorter than ``v T`` cannot hold both ramps and is rejected with
:class:`MoveTooShortError`. ``ramp_time = 0`` gives the seed's bare constant-speed law
``s = v t`` (the velocity then jumps from 0 to ``v`` at the ends).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.polynomial import Polynomial
from numpy.typing import ArrayLike, NDArray

from planners.errors import InvalidProfileError, MoveTooShortError

__all__ = [
    "RAMP_SHAPES",
    "InvalidProfileError",
    "MoveTooShortError",
    "ConstantSpeedShare",
    "SpeedProfile",
    "smoothstep",
    "quintic_smoothstep",
]

#: Smoothstep speed-ramp shapes, by name: coefficients of h(x) in increasing powers of x.
RAMP_SHAPES: dict[str, tuple[float, ...]] = {
    "quintic": (0.0, 0.0, 0.0, 10.0, -15.0, 6.0),
    "septic": (0.0, 0.0, 0.0, 0.0, 35.0, -84.0, 70.0, -20.0),
}


@dataclass(frozen=True)
class _Shape:
    h: Polynomial          # speed ramp, h(0) = 0, h(1) = 1
    H: Polynomial          # integral of h from 0, H(1) = 1/2
    dh: Polynomial         # h'
    ddh: Polynomial        # h''
    peak_dh: float         # max of |h'| on [0, 1]
    peak_ddh: float        # max of |h''| on [0, 1]


def _peak_abs(p: Polynomial) -> float:
    """max |p(x)| for x in [0, 1], from the end points and the real roots of p'."""
    candidates = [0.0, 1.0]
    for r in p.deriv().roots():
        if abs(r.imag) < 1e-12 and 0.0 <= r.real <= 1.0:
            candidates.append(float(r.real))
    return float(np.max(np.abs(p(np.array(candidates)))))


@lru_cache(maxsize=None)
def _shape(name: str) -> _Shape:
    if name not in RAMP_SHAPES:
        raise InvalidProfileError(
            f"ramp_shape: unknown ramp shape {name!r}; valid: {', '.join(sorted(RAMP_SHAPES))}")
    h = Polynomial(RAMP_SHAPES[name])
    dh = h.deriv()
    ddh = dh.deriv()
    return _Shape(h=h, H=h.integ(), dh=dh, ddh=ddh, peak_dh=_peak_abs(dh), peak_ddh=_peak_abs(ddh))


def smoothstep(x: ArrayLike, shape: str = "quintic") -> NDArray[np.float64]:
    """The speed-ramp function h(x) of ``shape`` (x clipped to [0, 1]); dimensionless."""
    return _shape(shape).h(np.clip(np.asarray(x, dtype=float), 0.0, 1.0))


def quintic_smoothstep(x: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                               NDArray[np.float64], NDArray[np.float64]]:
    """The quintic smoothstep ``h = 10 x^3 - 15 x^4 + 6 x^5`` (:data:`RAMP_SHAPES`'
    ``"quintic"``) in closed form, x clipped to [0, 1]: ``(h, h', h'', H)``, ``H`` its integral
    from 0 (``H(1) = 1/2``). What a corner blend's turn and speed changes
    (:mod:`planners.blend`) and a weave's fade (:mod:`planners.weave`) ramp with;
    :class:`SpeedProfile` evaluates its shapes from their coefficients instead."""
    x = np.clip(x, 0.0, 1.0)
    return (x**3 * (10 - 15 * x + 6 * x * x), 30 * x * x * (1 - x) ** 2,
            60 * x * (1 - x) * (1 - 2 * x), x**4 * (2.5 - 3 * x + x * x))


@dataclass(frozen=True)
class ConstantSpeedShare:
    """Share of a move spent at the constant programmed speed.

    Attributes:
        time: Constant-speed time / total duration, in [0, 1].
        length: Constant-speed path length / total path length, in [0, 1].
    """

    time: float
    length: float


def _positive(value: float, field: str, unit: str, allow_zero: bool = False) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InvalidProfileError(f"{field}: expected a number in {unit}, got {value!r}") from None
    if not math.isfinite(x) or x < 0 or (x == 0 and not allow_zero):
        word = "non-negative" if allow_zero else "positive"
        raise InvalidProfileError(f"{field}: must be a {word} finite number of {unit}, got {value!r}")
    return x


class SpeedProfile:
    """Arc-length law s(t) with smooth ramps: rest -> constant speed -> rest.

    Args:
        length: Path length L of the move, m (> 0).
        speed: Constant programmed tool speed v, m/s (> 0).
        ramp_time: Duration T of each ramp, s (>= 0; 0 = seed 003's bare constant speed).
        shape: Ramp shape, one of :data:`RAMP_SHAPES`.

    Raises:
        InvalidProfileError: a non-positive or non-finite value, or an unknown shape.
        MoveTooShortError: ``length < speed * ramp_time`` (the two ramps do not fit).
    """

    def __init__(self, length: float, speed: float, ramp_time: float = 0.0,
                 shape: str = "quintic") -> None:
        self.length = _positive(length, "length", "m")
        self.speed = _positive(speed, "speed", "m/s")
        self.ramp_time = _positive(ramp_time, "ramp_time", "s", allow_zero=True)
        self.shape = shape
        self._shape = _shape(shape)
        need = self.speed * self.ramp_time
        if self.length < need * (1.0 - 1e-12):
            raise MoveTooShortError(
                f"length: move of {self.length * 1e3:.6g} mm is too short for its start/stop ramps,"
                f" which need speed*ramp_time = {need * 1e3:.6g} mm"
                f" (speed={self.speed:g} m/s, ramp_time={self.ramp_time:g} s);"
                f" lower speed or ramp_time/raise max_acceleration")
        self.duration = self.length / self.speed + self.ramp_time

    @classmethod
    def from_max_acceleration(cls, length: float, speed: float, max_acceleration: float,
                              shape: str = "quintic") -> SpeedProfile:
        """Profile whose ramps reach at most ``max_acceleration`` (m/s^2) along the path.

        The ramp time is ``T = v * max|h'| / a_max`` (``max|h'|`` = 15/8 quintic, 35/16 septic).
        """
        a = _positive(max_acceleration, "max_acceleration", "m/s^2")
        v = _positive(speed, "speed", "m/s")
        return cls(length, v, ramp_time=v * _shape(shape).peak_dh / a, shape=shape)

    # --- summary figures -------------------------------------------------------------------
    @property
    def ramp_length(self) -> float:
        """Path length covered by one ramp, m (``v T / 2``)."""
        return 0.5 * self.speed * self.ramp_time

    @property
    def constant_speed_length(self) -> float:
        """Path length run at the constant speed, m."""
        return max(self.length - 2.0 * self.ramp_length, 0.0)

    @property
    def constant_speed_time(self) -> float:
        """Time spent at the constant speed, s."""
        return max(self.duration - 2.0 * self.ramp_time, 0.0)

    @property
    def constant_speed_fraction(self) -> ConstantSpeedShare:
        """Share of the duration and of the length run at the constant speed."""
        return ConstantSpeedShare(time=self.constant_speed_time / self.duration,
                                  length=self.constant_speed_length / self.length)

    @property
    def peak_acceleration(self) -> float:
        """Largest |s''| of the profile, m/s^2 (0 for a bare constant-speed law)."""
        if self.ramp_time == 0.0:
            return 0.0
        return self.speed * self._shape.peak_dh / self.ramp_time

    @property
    def peak_jerk(self) -> float:
        """Largest |s'''| of the profile, m/s^3 (0 for a bare constant-speed law)."""
        if self.ramp_time == 0.0:
            return 0.0
        return self.speed * self._shape.peak_ddh / self.ramp_time**2

    # --- evaluation ------------------------------------------------------------------------
    def evaluate(self, t: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                              NDArray[np.float64], NDArray[np.float64]]:
        """Arc length and its time derivatives at time(s) ``t``.

        Times outside ``[0, duration]`` are clamped (the tool rests at the end points).

        Args:
            t: Time(s), s, any shape.

        Returns:
            ``(s, sd, sdd, sddd)``: m, m/s, m/s^2, m/s^3, each with the shape of ``t``.
        """
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        v, T, L, D = self.speed, self.ramp_time, self.length, self.duration
        s = v * (t - 0.5 * T)
        sd = np.full_like(t, v)
        sdd = np.zeros_like(t)
        sddd = np.zeros_like(t)
        if T > 0.0:
            sh = self._shape
            up = t < T
            if np.any(up):
                x = t[up] / T
                s[up] = v * T * sh.H(x)
                sd[up] = v * sh.h(x)
                sdd[up] = v * sh.dh(x) / T
                sddd[up] = v * sh.ddh(x) / T**2
            down = t > D - T
            if np.any(down):
                x = (D - t[down]) / T
                s[down] = L - v * T * sh.H(x)
                sd[down] = v * sh.h(x)
                sdd[down] = -v * sh.dh(x) / T
                sddd[down] = v * sh.ddh(x) / T**2
        else:
            s = v * t
        # exact end points, whatever the rounding of the constant-speed expression
        s = np.where(t >= D, L, s)
        return s, sd, sdd, sddd
