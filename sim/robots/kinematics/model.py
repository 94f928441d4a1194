"""Kinematic model of one cellsim robot: its family with a tool frame, joint ranges, speeds.

A :class:`KinematicModel` joins a robot's kinematic family (:mod:`sim.robots.families`: the
seeds' closed forms with their dimensions) with what the MJCF adds: the constant transform
``tcp_offset`` from the seed's tool frame to the MJCF site ``tcp``
(``T_0,tcp = T_0,seed(q) @ tcp_offset``, read by :func:`kinematic_model`), the joint ranges,
and the joint speed limits (the weights of the IK ranking).

Frames: frame 0 (the MJCF site ``frame0``) lies on the J1 axis at the height of J2.

Units: metres, radians. Batched functions take joint arrays of shape (n,) or (N, n) and return
arrays with a matching leading dimension.
"""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.core.rotations import invert_transform
from sim.errors import KinematicsError
from sim.robots.families import KinematicFamily
from sim.robots.spec import RobotSpec, joint_ranges


def _as_batch(q: ArrayLike, n: int) -> tuple[NDArray[np.float64], bool]:
    Q = np.asarray(q, dtype=float)
    single = Q.ndim == 1
    Q = np.atleast_2d(Q)
    if Q.shape[-1] != n or Q.ndim != 2:
        raise KinematicsError(f"joint array must have shape ({n},) or (N, {n}), got {np.shape(q)}")
    return Q, single


@dataclass
class KinematicModel:
    """Closed-form kinematics of one robot with its tcp frame (see the module docstring).

    Attributes:
        name: Robot registry name.
        family: The kinematic family with its dimensions (and tool).
        tcp_offset: Constant transform seed tool frame -> tcp frame, (4, 4).
        lower, upper: Joint position limits, rad, shape (n,), or None when unknown.
        max_speed: Joint speed limits, rad/s, shape (n,); weights of the IK ranking.
    """

    name: str
    family: KinematicFamily
    tcp_offset: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    lower: NDArray[np.float64] | None = None
    upper: NDArray[np.float64] | None = None
    max_speed: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.family, KinematicFamily):
            raise KinematicsError(f"robot {self.name!r}: family must be a KinematicFamily object, "
                                  f"got {type(self.family).__name__}")
        self.tcp_offset = np.asarray(self.tcp_offset, dtype=float)
        if self.max_speed is None:
            self.max_speed = np.ones(self.n_joints)
        self.max_speed = np.asarray(self.max_speed, dtype=float)
        self.family.check_tcp_offset(self.name, self.tcp_offset)

    @property
    def n_joints(self) -> int:
        return self.family.n_joints

    @property
    def dims(self) -> dict[str, float]:
        """The family's dimensions, m."""
        return self.family.dims

    def with_family(self, family: KinematicFamily) -> KinematicModel:
        """The same model with another family object (e.g. the arm with a tool)."""
        return dataclasses.replace(self, family=family)

    # ------------------------------------------------------------------ frames
    def joint_frames(self, q: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                                  NDArray[np.float64]]:
        """Joint axes, points on them, and the tcp transform, in frame 0.

        Args:
            q: Joint values, rad, shape (n,) or (N, n).

        Returns:
            ``(axes, points, T)``: unit joint axes (N, n, 3), a point on each axis (N, n, 3), m,
            and the tcp pose (N, 4, 4) (leading N dropped for a single configuration).
        """
        Q, single = _as_batch(q, self.n_joints)
        axes, points, T = self.family.joint_frames(Q)
        T = T @ self.tcp_offset
        if single:
            return axes[0], points[0], T[0]
        return axes, points, T

    def fk(self, q: ArrayLike) -> NDArray[np.float64]:
        """Pose of the tcp in frame 0: (4, 4) or (N, 4, 4) for q of shape (n,) or (N, n)."""
        return self.joint_frames(q)[2]

    def fk_seed(self, q: ArrayLike) -> NDArray[np.float64]:
        """Pose of the seed's tool frame (without ``tcp_offset``), (4, 4) or (N, 4, 4)."""
        return self.fk(q) @ invert_transform(self.tcp_offset)

    # ------------------------------------------------------------------ limits
    def within_limits(self, q: ArrayLike, tol: float = 1e-9) -> NDArray[np.bool_] | bool:
        """Whether configuration(s) lie inside the joint ranges (True when ranges are unknown)."""
        Q = np.asarray(q, dtype=float)
        if self.lower is None or self.upper is None:
            return True if Q.ndim == 1 else np.ones(Q.shape[0], dtype=bool)
        ok = np.all((Q >= self.lower - tol) & (Q <= self.upper + tol), axis=-1)
        return bool(ok) if Q.ndim == 1 else ok


def joint_limits(spec: RobotSpec) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Joint position ranges (lower, upper), rad, each shape (n,), from the robot's MJCF
    (:func:`sim.robots.registry.joint_ranges`, the single source of truth)."""
    rng = joint_ranges(spec)
    return rng[:, 0].copy(), rng[:, 1].copy()


def closed_form_model(spec: RobotSpec) -> KinematicModel:
    """Model of a robot from the seeds' closed forms and its family's dimensions only.

    The tool frame is the seed's (no MJCF tcp offset); the joint ranges are attached.
    """
    lo, hi = joint_limits(spec)
    return KinematicModel(name=spec.name, family=spec.family, lower=lo, upper=hi,
                          max_speed=np.asarray(spec.max_speed))


def kinematic_model(spec: RobotSpec) -> KinematicModel:
    """Model of a robot whose tool frame is the MJCF site ``tcp``.

    The constant ``tcp_offset`` is measured from the MJCF at q = 0 (site ``tcp`` in site
    ``frame0``); :mod:`sim.robots.kinematics.mujoco_fk` checks it holds at every q (tests). An
    offset the family's analytic IK cannot handle falls back to the seed's tool frame with a
    warning.
    """
    # imports mujoco, so only when used (not a cycle: mujoco_fk imports spec, not this module)
    from sim.robots.kinematics.mujoco_fk import MujocoKinematics

    model = closed_form_model(spec)
    mj = MujocoKinematics.for_robot(spec)
    T_mj = mj.fk(np.zeros(model.n_joints))
    offset = invert_transform(model.fk(np.zeros(model.n_joints))) @ T_mj
    offset[np.abs(offset) < 1e-12] = 0.0
    try:
        model.tcp_offset = offset
        model.__post_init__()
    except KinematicsError as exc:
        warnings.warn(f"{exc}; using the seed's tool frame", stacklevel=2)
        model.tcp_offset = np.eye(4)
    return model
