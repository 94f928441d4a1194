"""Weaving: a periodic offset of the tool point across the seam, over a Cartesian move.

A weld weave moves the torch tip side to side while it travels along the seam. The offset lies
in the plane normal to the torch axis: ``lateral`` is perpendicular to the travel direction
(positive to the left of travel, seen from the torch: ``travel x torch axis``) and
``longitudinal`` along the travel. The travel along the seam keeps the move's own time law, so
the travel speed stays the set speed; the tool point itself moves faster.

Patterns, per cycle of period ``P = 1 / frequency`` (``v`` the cycle's progress, 0..1):

* ``"sine"``: lateral ``A sin(2 pi v)``;
* ``"zigzag"``: lateral triangle wave (constant lateral speed between the extremes);
* ``"triangle"``: the zigzag with the tool ``A / 2`` behind the seam point at each extreme and
  level with it at the centre: relative to the travelling seam point it runs on a V, and on the
  work it traces a row of triangles;
* ``"circle"``: lateral ``A sin(2 pi v)``, longitudinal ``A cos(2 pi v)``: loops of radius A.

``dwell`` holds the offset at each lateral extreme for that long; it is part of the period, so
``frequency`` is the number of whole cycles per second and the moving part of a cycle lasts
``P - 2 dwell``. The weave fades in and out with the move's start and stop ramps (a smooth
envelope from 0 to 1 over each ramp, at least half a cycle), so it starts and ends on the
seam. Moves that blend into each other under one weave (a TP program's CNT moves between
``Weave`` and ``Weave End``) carry it on: the next move continues the cycle (``clock``) and
neither fades where they join.

:class:`WeavingTrajectory` wraps a :class:`planners.adnia.CartesianTrajectory`: ``at(t)`` and
``sample(dt)`` as for any trajectory, and :meth:`WeavingTrajectory.breakpoints` gives the times
where the pattern turns (its extremes and dwell ends), so that a sampler can put points there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planners.base import sample_times
from planners.errors import InvalidMoveError
from planners.profiles import quintic_smoothstep

#: The patterns, in the order the docs list them.
PATTERNS = ("sine", "zigzag", "triangle", "circle")


@dataclass(frozen=True)
class Weave:
    """A weave pattern (module docstring).

    Attributes:
        pattern: One of :data:`PATTERNS`.
        amplitude: Lateral amplitude A, m (half the width, > 0).
        frequency: Whole cycles per second, Hz (> 0).
        dwell: Hold at each lateral extreme, s (>= 0, ``2 dwell < 0.8 / frequency``).
    """

    pattern: str
    amplitude: float
    frequency: float
    dwell: float = 0.0

    def __post_init__(self) -> None:
        if self.pattern not in PATTERNS:
            raise InvalidMoveError(f"weave.pattern: unknown pattern {self.pattern!r}; valid: "
                                   f"{', '.join(PATTERNS)}")
        for name, v in (("amplitude", self.amplitude), ("frequency", self.frequency)):
            if not (math.isfinite(v) and v > 0):
                raise InvalidMoveError(f"weave.{name}: must be > 0, got {v!r}")
        if not (math.isfinite(self.dwell) and 0.0 <= 2.0 * self.dwell < 0.8 / self.frequency):
            raise InvalidMoveError(
                f"weave.dwell: {self.dwell!r} s at each extreme leaves no time to move in a "
                f"cycle of {1.0 / self.frequency:.4g} s (2 dwell must be under 80 % of it)")

    @property
    def period(self) -> float:
        return 1.0 / self.frequency

    def progress(self, tau: NDArray[np.float64]) -> NDArray[np.float64]:
        """The cycle progress ``v`` (0..1 per cycle, dwells held at 0.25 and 0.75) of the
        weave's own time ``tau`` (s)."""
        P, d = self.period, self.dwell
        m = P - 2.0 * d
        tau = np.asarray(tau, dtype=float)
        k = np.floor(tau / P)
        r = tau - k * P
        v = np.where(r < m / 4, r / m,
            np.where(r < m / 4 + d, 0.25,
            np.where(r < 3 * m / 4 + d, (r - d) / m,
            np.where(r < 3 * m / 4 + 2 * d, 0.75, (r - 2 * d) / m))))
        return k + v

    def shape(self, v: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(lateral, longitudinal)`` offsets, m, at cycle progress ``v``."""
        A = self.amplitude
        frac = v - np.floor(v)
        tri = np.where(frac < 0.25, 4 * frac, np.where(frac < 0.75, 2 - 4 * frac, 4 * frac - 4))
        if self.pattern == "sine":
            return A * np.sin(2 * np.pi * v), np.zeros_like(v)
        if self.pattern == "zigzag":
            return A * tri, np.zeros_like(v)
        if self.pattern == "triangle":
            return A * tri, -0.5 * A * np.abs(tri)
        return A * np.sin(2 * np.pi * v), A * np.cos(2 * np.pi * v)

    def turn_times(self, duration: float) -> NDArray[np.float64]:
        """Times in [0, duration] where the pattern turns: each extreme and dwell end, and the
        zigzag's centre crossings (s)."""
        P, d = self.period, self.dwell
        m = P - 2.0 * d
        within = np.array([m / 4, m / 4 + d, 3 * m / 4 + d, 3 * m / 4 + 2 * d, P])
        if self.pattern == "triangle":  # its V turns at the centre too
            within = np.r_[within, m / 2 + d]
        n = int(math.ceil(duration / P)) + 1
        t = (np.arange(n)[:, None] * P + within[None, :]).ravel()
        return np.unique(t[(t > 0.0) & (t < duration)])


class WeavingTrajectory:
    """A Cartesian move with a weave on top (module docstring).

    Args:
        base: The move (:class:`planners.adnia.CartesianTrajectory`).
        weave: The pattern.
        approach_column: Column of the tool frame that is the torch axis (2 for a z-approach
            tool frame, 0 for the 5-axis family's x).
    """

    def __init__(self, base, weave: Weave, approach_column: int = 2, *, clock: float = 0.0,
                 fade_in: bool = True, fade_out: bool = True) -> None:
        self.base = base
        self.weave = weave
        self.approach_column = int(approach_column)
        #: The weave's own time at the move's start, s: a move that a weave carries on into
        #: (a TP program's CNT moves between ``Weave`` and ``Weave End``) continues its cycle.
        self.clock = float(clock)
        ramp = float(getattr(base.profile, "ramp_time", 0.0))
        # fade over the move's ramps, and over half a cycle at least (a phase that blends in
        # or out has no ramp)
        self.fade = min(max(ramp, 0.5 * weave.period), 0.5 * base.duration)
        #: How long the weave fades in at the start and out at the end, s (0 where it
        #: carries on from the move before or into the move after).
        self.fade_in = self.fade if fade_in else 0.0
        self.fade_out = self.fade if fade_out else 0.0

    @property
    def duration(self) -> float:
        return self.base.duration

    @property
    def length(self) -> float:
        return self.base.length

    @property
    def speed(self) -> float:
        return self.base.speed

    @property
    def kind(self) -> str:
        return self.base.kind

    @property
    def constant_speed_fraction(self):
        return self.base.constant_speed_fraction

    @property
    def orientation(self):
        return self.base.orientation

    @property
    def steady(self):
        """The base move's part at the set speed (a blended window's), on its clock, s."""
        return getattr(self.base, "steady", None)

    @property
    def path(self):
        return self.base.path

    @property
    def profile(self):
        return self.base.profile

    def envelope(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        """0 at a start and an end the weave fades at, 1 between (and at the ends it carries
        on through)."""
        t = np.asarray(t, dtype=float)
        T = self.duration
        e = quintic_smoothstep(t / self.fade_in)[0] if self.fade_in > 0 else np.ones_like(t)
        return e * (quintic_smoothstep((T - t) / self.fade_out)[0] if self.fade_out > 0 else 1.0)

    def travel_direction(self, t: ArrayLike) -> NDArray[np.float64]:
        """The unit tangent of the base path at times ``t``, (..., 3): the direction of travel
        (the weave's longitudinal direction is its part normal to the torch axis, shorter by
        the cosine of the travel angle)."""
        t = np.asarray(t, dtype=float)
        s = self.base.at(t).path_length.reshape(-1)
        d1 = self.base.path.evaluate(s)[1].reshape(t.shape + (3,))
        return d1 / np.linalg.norm(d1, axis=-1, keepdims=True)

    def frame(self, t: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Unit lateral and longitudinal directions at times ``t``, (..., 3) each."""
        t = np.asarray(t, dtype=float)
        st = self.base.at(t)
        a = st.rotation[..., :, self.approach_column]
        s = st.path_length.reshape(-1)
        _, d1, _, _ = self.base.path.evaluate(s)
        tang = d1.reshape(a.shape)
        tang = tang - np.sum(tang * a, axis=-1, keepdims=True) * a  # in the plane normal to a
        tang /= np.linalg.norm(tang, axis=-1, keepdims=True)
        lat = np.cross(tang, a)
        return lat, tang

    def offset(self, t: ArrayLike) -> NDArray[np.float64]:
        """The weave's displacement of the tool point at times ``t``, m, (..., 3)."""
        t = np.asarray(t, dtype=float)
        lat, lon = self.frame(t)
        y, x = self.weave.shape(self.weave.progress(self.clock + t))
        e = self.envelope(t)
        return (e * y)[..., None] * lat + (e * x)[..., None] * lon

    def at(self, t: ArrayLike):
        """The base move's state with the weave added to position, velocity, acceleration
        (central differences of the offset, h = 1e-4 s; jerk left as the base's)."""
        t = np.asarray(t, dtype=float)
        st = self.base.at(t)
        h = 1e-4
        o0 = self.offset(t)
        op, om = self.offset(np.clip(t + h, 0, self.duration)), self.offset(
            np.clip(t - h, 0, self.duration))
        return replace(st, position=st.position + o0,
                       velocity=st.velocity + (op - om) / (2 * h),
                       acceleration=st.acceleration + (op - 2 * o0 + om) / (h * h))

    def breakpoints(self) -> NDArray[np.float64]:
        """Times where the pattern turns (its extremes and dwell ends), on the move's clock, s."""
        t = self.weave.turn_times(self.clock + self.duration) - self.clock
        return t[t > 0.0]

    def sample(self, dt: float):
        times = sample_times(0.0, self.duration, dt)
        return times, self.at(times)


def measure_weave(t: ArrayLike, lateral: ArrayLike) -> dict[str, float]:
    """Amplitude and frequency of a recorded lateral offset (m) at times ``t`` (s, uniform).

    The frequency is the FFT peak of the mean-free signal, refined by a parabola through the
    peak bin and its neighbours (on a Hann window); the amplitude is half the peak-to-peak; the
    centre is the mean over whole cycles.

    Returns:
        ``{"frequency_hz", "amplitude_m", "centre_m"}``.
    """
    t = np.asarray(t, dtype=float)
    y = np.asarray(lateral, dtype=float)
    if len(t) < 16:
        return {"frequency_hz": float("nan"), "amplitude_m": float("nan"),
                "centre_m": float("nan")}
    dt = float(np.median(np.diff(t)))
    z = (y - y.mean()) * np.hanning(len(y))
    n = 1 << int(math.ceil(math.log2(len(y) * 8)))
    spec = np.abs(np.fft.rfft(z, n))
    k = int(np.argmax(spec[1:])) + 1
    if 1 <= k < len(spec) - 1:
        a, b, c = np.log(spec[k - 1:k + 2] + 1e-300)
        k = k + 0.5 * (a - c) / (a - 2 * b + c)
    f = k / (n * dt)
    cycles = int((t[-1] - t[0]) * f)
    if cycles >= 1:
        sel = t <= t[0] + cycles / f
        centre = float(y[sel].mean())
    else:
        centre = float(y.mean())
    return {"frequency_hz": float(f), "amplitude_m": float((y.max() - y.min()) / 2),
            "centre_m": centre}


__all__ = ["PATTERNS", "Weave", "WeavingTrajectory", "measure_weave"]
