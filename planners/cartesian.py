"""Cartesian trajectories: a tool path run by a time law with an orientation law.

Owns :class:`CartesianTrajectory` (a path of :mod:`planners.paths`, a time law of
:mod:`planners.profiles` and a tool-frame law of :mod:`planners.rotations`; ``at(t)`` gives
position, velocity, acceleration, jerk, tool frame, angular velocity, path length and
speed), :class:`CartesianState`, and the continuous-time moves built on seed 003's paths:
:func:`linear_move`, :func:`arc_move`, :func:`circle_move` and :func:`spherical_move` (smooth
start and stop, ramps taken out of the move's own length; see :mod:`planners.adnia`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planners.base import sample_times
from planners.errors import InvalidMoveError
from planners.move_inputs import _positive, adnia_step_count
from planners.paths import CirclePath, LinePath, Path, SphericalPath
from planners.profiles import ConstantSpeedShare, SpeedProfile
from planners.rotations import (
    ORIENTATION_MODES,
    AxisCarriedOrientation,
    GeodesicOrientation,
    InvalidOrientationError,
    OrientationLaw,
    SphericalVersorOrientation,
    angular_velocity,
    as_rotation,
)

#: Path acceleration limit used for the start/stop ramps when neither ``ramp_time`` nor
#: ``max_acceleration`` is given, m/s^2.
DEFAULT_MAX_ACCELERATION = 5.0
#: Largest number of points sample() will build.
_MAX_SAMPLES = 50_000_000


@dataclass(frozen=True)
class CartesianState:
    """Tool-point state at one time (arrays of shape (3,), (3, 3), ()) or M times ((M, 3), ...).

    Attributes:
        position: Tool point, m, (..., 3).
        velocity: m/s, (..., 3).
        acceleration: m/s^2, (..., 3).
        jerk: m/s^3, (..., 3).
        rotation: Tool frame, (..., 3, 3), columns n, o, a (seed 003 G matrix, eq. 8).
        angular_velocity: Of the tool frame, base-frame components, rad/s, (..., 3).
        path_length: Arc length travelled s, m, (...).
        speed: ds/dt, m/s, (...).
    """

    position: NDArray[np.float64]
    velocity: NDArray[np.float64]
    acceleration: NDArray[np.float64]
    jerk: NDArray[np.float64]
    rotation: NDArray[np.float64]
    angular_velocity: NDArray[np.float64]
    path_length: NDArray[np.float64]
    speed: NDArray[np.float64]

    def pose(self) -> NDArray[np.float64]:
        """Seed 003's position matrix G (eq. 8), homogeneous 4x4, shape (..., 4, 4)."""
        G = np.zeros(self.rotation.shape[:-2] + (4, 4))
        G[..., :3, :3] = self.rotation
        G[..., :3, 3] = self.position
        G[..., 3, 3] = 1.0
        return G


class CartesianTrajectory:
    """Tool point moving along a path by a smooth speed law, with an orientation law.

    Conforms to :class:`planners.base.Trajectory`. Build it with :func:`linear_move`,
    :func:`arc_move`, :func:`circle_move` or :func:`spherical_move`.

    Args:
        path: Geometric path by arc length (:class:`LinePath`, :class:`CirclePath`,
            :class:`SphericalPath`).
        orientation: Tool-frame law in u = s / L (:mod:`planners.rotations`).
        profile: Arc-length time law (:class:`planners.profiles.SpeedProfile`) of the same length.
    """

    def __init__(self, path: Path, orientation: OrientationLaw, profile: SpeedProfile) -> None:
        if abs(profile.length - path.length) > 1e-12 * path.length:
            raise InvalidMoveError(
                f"profile: length {profile.length!r} m differs from the path's {path.length!r} m")
        self.path = path
        self.orientation = orientation
        self.profile = profile

    @property
    def kind(self) -> str:
        """``"line"``, ``"arc"`` or ``"spherical"``."""
        return self.path.kind

    @property
    def duration(self) -> float:
        """Total duration, s (``L / v + ramp_time``)."""
        return self.profile.duration

    @property
    def length(self) -> float:
        """Path length L, m."""
        return self.path.length

    @property
    def speed(self) -> float:
        """Programmed constant speed v, m/s."""
        return self.profile.speed

    @property
    def constant_speed_fraction(self) -> ConstantSpeedShare:
        """Share of the time and of the length run at the constant speed v."""
        return self.profile.constant_speed_fraction

    def constant_speed_steps(self, dt: float) -> tuple[int, float]:
        """Seed 003 eq. (5)/(14) for the constant-speed part only (the seed's N after the ramps).

        Returns:
            ``(N, L_c / (v dt))`` where ``L_c`` is the constant-speed length (N = 0 if none).
        """
        dt = _positive(dt, "dt", "s")
        lc = self.profile.constant_speed_length
        if lc <= 0.0:
            return 0, 0.0
        return adnia_step_count(lc, self.speed, dt)

    def at(self, t: ArrayLike) -> CartesianState:
        """State at time(s) ``t`` (s, any shape); times outside [0, duration] are clamped.

        Raises:
            InvalidMoveError: ``t`` contains NaN.
        """
        t = np.asarray(t, dtype=float)
        if np.any(np.isnan(t)):
            raise InvalidMoveError("t: time contains NaN")
        shape = t.shape
        s, sd, sdd, sddd = self.profile.evaluate(t.reshape(-1))
        p, d1, d2, d3 = self.path.evaluate(s)
        sd_, sdd_, sddd_ = sd[:, None], sdd[:, None], sddd[:, None]
        vel = d1 * sd_
        acc = d2 * sd_**2 + d1 * sdd_
        jerk = d3 * sd_**3 + 3.0 * d2 * sd_ * sdd_ + d1 * sddd_
        L = self.path.length
        R, dR = self.orientation.evaluate(s / L)
        w = angular_velocity(R, dR) * (sd / L)[:, None]
        v3 = shape + (3,)
        return CartesianState(position=p.reshape(v3), velocity=vel.reshape(v3),
                              acceleration=acc.reshape(v3), jerk=jerk.reshape(v3),
                              rotation=R.reshape(shape + (3, 3)), angular_velocity=w.reshape(v3),
                              path_length=s.reshape(shape), speed=sd.reshape(shape))

    def sample(self, dt: float) -> tuple[NDArray[np.float64], CartesianState]:
        """``(times, states)`` every controller period ``dt`` (s), the last at ``duration``.

        Raises:
            InvalidMoveError: ``dt`` not positive, or so small that more than 5e7 points result.
        """
        dt = _positive(dt, "dt", "s")
        if self.duration / dt > _MAX_SAMPLES:
            raise InvalidMoveError(
                f"dt: {dt:g} s gives {self.duration / dt:.3g} samples over {self.duration:g} s"
                f" (limit {_MAX_SAMPLES:.0e}); use a larger sampling period")
        times = sample_times(0.0, self.duration, dt)
        return times, self.at(times)


def _profile(length: float, speed: float, ramp_time: float | None, max_acceleration: float | None,
             ramp_shape: str) -> SpeedProfile:
    speed = _positive(speed, "speed", "m/s")
    if ramp_time is not None and max_acceleration is not None:
        raise InvalidMoveError("ramp_time: give ramp_time or max_acceleration, not both")
    if ramp_time is not None:
        return SpeedProfile(length, speed, ramp_time=ramp_time, shape=ramp_shape)
    a = DEFAULT_MAX_ACCELERATION if max_acceleration is None else max_acceleration
    return SpeedProfile.from_max_acceleration(length, speed, a, shape=ramp_shape)


def _orientation(mode: str, rotation_start: ArrayLike | None, rotation_end: ArrayLike | None,
                 carry: tuple[NDArray[np.float64], float] | None) -> OrientationLaw:
    valid = ORIENTATION_MODES if carry is not None else tuple(m for m in ORIENTATION_MODES if m != "carry")
    if mode not in valid:
        raise InvalidOrientationError(
            f"orientation: unknown or unusable mode {mode!r} for this move; valid: {', '.join(valid)}")
    R0 = np.eye(3) if rotation_start is None else as_rotation(rotation_start, "rotation_start")
    if mode == "carry":
        if rotation_end is not None:
            raise InvalidOrientationError(
                "rotation_end: not used with orientation='carry' (the end frame follows from the"
                " arc); omit it or use orientation='geodesic'")
        axis, angle = carry
        return AxisCarriedOrientation(R0, axis, angle)
    R1 = R0 if rotation_end is None else as_rotation(rotation_end, "rotation_end")
    if mode == "geodesic":
        return GeodesicOrientation(R0, R1)
    return SphericalVersorOrientation(R0, R1)


def linear_move(start: ArrayLike, end: ArrayLike, speed: float, *,
                rotation_start: ArrayLike | None = None, rotation_end: ArrayLike | None = None,
                orientation: str = "geodesic", ramp_time: float | None = None,
                max_acceleration: float | None = None, ramp_shape: str = "quintic"
                ) -> CartesianTrajectory:
    """Straight move at constant speed with smooth start and stop (seed 003 eq. 1-7 + ramps).

    Args:
        start, end: P_O and P_F, m, (3,).
        speed: Constant tool speed v, m/s.
        rotation_start: Start tool frame (3, 3), columns n, o, a (default identity, eq. 9).
        rotation_end: End tool frame (default: ``rotation_start``, constant orientation).
        orientation: ``"geodesic"`` (slerp) or ``"spherical"`` (seed eq. 19-24).
        ramp_time: Duration of each start/stop ramp, s (0 = seed's bare constant speed).
        max_acceleration: Alternatively, the ramps' path-acceleration limit, m/s^2
            (default :data:`DEFAULT_MAX_ACCELERATION` when neither is given).
        ramp_shape: ``"quintic"`` (continuous jerk) or ``"septic"`` (continuous snap).

    Raises:
        InvalidMoveError, CoincidentPointsError, InvalidOrientationError,
        planners.profiles.InvalidProfileError, planners.profiles.MoveTooShortError.
    """
    path = LinePath(start, end)
    prof = _profile(path.length, speed, ramp_time, max_acceleration, ramp_shape)
    return CartesianTrajectory(path, _orientation(orientation, rotation_start, rotation_end, None), prof)


def arc_move(start: ArrayLike, via: ArrayLike, end: ArrayLike, speed: float, *,
             rotation_start: ArrayLike | None = None, rotation_end: ArrayLike | None = None,
             orientation: str = "carry", ramp_time: float | None = None,
             max_acceleration: float | None = None, ramp_shape: str = "quintic"
             ) -> CartesianTrajectory:
    """Circular arc through three points (any plane) at constant tangential speed.

    The arc goes from ``start`` through ``via`` to ``end``; its sweep may exceed 180 deg.

    Args:
        start, via, end: Points on the arc in travel order, m, (3,).
        speed: Tangential speed v, m/s.
        rotation_start: Start tool frame (default identity).
        rotation_end: End tool frame (only with ``"geodesic"`` or ``"spherical"``).
        orientation: ``"carry"`` (default: the start frame turns with the arc about its axis,
            so the torch keeps its work and travel angles to the seam), ``"geodesic"`` or
            ``"spherical"``.
        ramp_time, max_acceleration, ramp_shape: As :func:`linear_move`.

    Raises:
        CollinearPointsError: the three points lie on one line. And as :func:`linear_move`.
    """
    path = CirclePath.through(start, via, end)
    prof = _profile(path.length, speed, ramp_time, max_acceleration, ramp_shape)
    law = _orientation(orientation, rotation_start, rotation_end, (path.normal, path.sweep))
    return CartesianTrajectory(path, law, prof)


def circle_move(centre: ArrayLike, axis: ArrayLike, start: ArrayLike, sweep: float, speed: float, *,
                rotation_start: ArrayLike | None = None, rotation_end: ArrayLike | None = None,
                orientation: str = "carry", ramp_time: float | None = None,
                max_acceleration: float | None = None, ramp_shape: str = "quintic"
                ) -> CartesianTrajectory:
    """Full or partial circle about an axis (e.g. a weld seam round a cylinder).

    Args:
        centre: A point on the circle's axis, m, (3,).
        axis: Axis direction, (3,); the tool turns right-handedly about it for ``sweep > 0``.
        start: Start point, m, (3,); the circle lies in the plane through it normal to ``axis``.
        sweep: Angle to travel, rad (2 pi = full circle; negative = the other way).
        speed: Tangential speed, m/s.
        rotation_start, rotation_end, orientation, ramp_time, max_acceleration, ramp_shape:
            As :func:`arc_move`.
    """
    path = CirclePath.about_axis(centre, axis, start, sweep)
    prof = _profile(path.length, speed, ramp_time, max_acceleration, ramp_shape)
    law = _orientation(orientation, rotation_start, rotation_end, (path.normal, path.sweep))
    return CartesianTrajectory(path, law, prof)


def spherical_move(start: ArrayLike, end: ArrayLike, speed: float, *,
                   centre: ArrayLike = (0.0, 0.0, 0.0), rotation_start: ArrayLike | None = None,
                   rotation_end: ArrayLike | None = None, orientation: str = "geodesic",
                   ramp_time: float | None = None, max_acceleration: float | None = None,
                   ramp_shape: str = "quintic") -> CartesianTrajectory:
    """Seed 003's spherical form (eq. 11-18) as a constant-speed move.

    The tool follows the curve on which both seed angles change linearly (the points of
    :func:`adnia_spherical` lie on it), at constant speed along it.

    Args:
        start, end: ``(R, varphi, phi)``: radius, m, and seed angles, rad (same R).
        speed: Tangential speed, m/s.
        centre: Sphere centre, m, (3,).
        rotation_start, rotation_end, ramp_time, max_acceleration, ramp_shape: As :func:`linear_move`.
        orientation: ``"geodesic"`` or ``"spherical"``.
    """
    path = SphericalPath(start, end, centre)
    prof = _profile(path.length, speed, ramp_time, max_acceleration, ramp_shape)
    return CartesianTrajectory(path, _orientation(orientation, rotation_start, rotation_end, None), prof)
