"""Kinematic table rows: one type per convention, the single row type of cellsim's chains and
both MJCF writers.

* :class:`DHRow`, standard Denavit-Hartenberg: ``i-1 T i = Rz(theta) Tz(d) Tx(a) Rx(alpha)``;
  the joint variable adds to ``theta`` (R) or ``d`` (P); joint i moves about/along z_{i-1}.
* :class:`MDHRow`, modified DH of Khalil-Dombre (seed 004 eq. 1, Table 1):
  ``j-1 T j = Rx(alpha) Tx(d) Rz(theta) Tz(r)``; the variable adds to ``theta`` (R) or
  ``r`` (P); joint j moves about/along z_j.
* :class:`ScrewAxis` (seed 000 Table 1, product of exponentials in the base frame):
  unit axis ``k`` and a point ``p`` on it at the zero configuration.

A robot.toml's ``dh`` rows become these rows (:func:`sim.robots.kinematics.chain.chain_from_dh`,
whose :class:`~sim.robots.kinematics.chain.Chain` :mod:`sim.robots.mjcf.generate` writes), and
:class:`sim.robots.mjcf.builder.KinematicChain` holds them directly.

Units: metres, radians.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sim.core.rotations import make_transform, rot_x, rot_z
from sim.errors import KinematicsError

_JOINT_TYPES = ("R", "P")


def check_joint(kind: str) -> None:
    """Refuse a joint type other than ``"R"`` (revolute) or ``"P"`` (prismatic)."""
    if kind not in _JOINT_TYPES:
        raise KinematicsError(f"joint type must be 'R' (revolute) or 'P' (prismatic), got {kind!r}")


def _tz(d: float) -> NDArray[np.float64]:
    return make_transform(np.eye(3), [0.0, 0.0, d])


def _tx(a: float) -> NDArray[np.float64]:
    return make_transform(np.eye(3), [a, 0.0, 0.0])


def _rx(a: float) -> NDArray[np.float64]:
    return make_transform(rot_x(a), np.zeros(3))


def _rz(a: float) -> NDArray[np.float64]:
    return make_transform(rot_z(a), np.zeros(3))


@dataclass(frozen=True)
class DHRow:
    """Standard DH row; ``theta``/``d`` are the offsets the joint variable adds to."""

    theta: float
    d: float
    a: float
    alpha: float
    joint: str = "R"
    limits: tuple[float, float] | None = None

    def motion(self, q: float) -> NDArray[np.float64]:
        """Joint motion about/along the local z axis, (4, 4)."""
        return _rz(q) if self.joint == "R" else _tz(q)

    def fixed(self) -> NDArray[np.float64]:
        """The row's transform at q = 0, ``Rz(theta) Tz(d) Tx(a) Rx(alpha)``."""
        return _rz(self.theta) @ _tz(self.d) @ _tx(self.a) @ _rx(self.alpha)

    def transform(self, q: float) -> NDArray[np.float64]:
        """``i-1 T i`` at joint value q (rad or m)."""
        if self.joint == "R":
            return _rz(self.theta + q) @ _tz(self.d) @ _tx(self.a) @ _rx(self.alpha)
        return _rz(self.theta) @ _tz(self.d + q) @ _tx(self.a) @ _rx(self.alpha)


@dataclass(frozen=True)
class MDHRow:
    """Modified DH row (seed 004 eq. 1); ``theta``/``r`` are the offsets the variable adds to."""

    alpha: float
    d: float
    theta: float
    r: float
    joint: str = "R"
    limits: tuple[float, float] | None = None

    def fixed(self) -> NDArray[np.float64]:
        """The row's transform at q = 0, ``Rx(alpha) Tx(d) Rz(theta) Tz(r)``."""
        return _rx(self.alpha) @ _tx(self.d) @ _rz(self.theta) @ _tz(self.r)

    def motion(self, q: float) -> NDArray[np.float64]:
        return _rz(q) if self.joint == "R" else _tz(q)

    def transform(self, q: float) -> NDArray[np.float64]:
        """``j-1 T j`` at joint value q (rad or m)."""
        if self.joint == "R":
            return _rx(self.alpha) @ _tx(self.d) @ _rz(self.theta + q) @ _tz(self.r)
        return _rx(self.alpha) @ _tx(self.d) @ _rz(self.theta) @ _tz(self.r + q)


@dataclass(frozen=True)
class ScrewAxis:
    """Joint axis in the base frame at q = 0 (seed 000 Table 1): unit ``k``, point ``p`` (m)."""

    k: tuple[float, float, float]
    p: tuple[float, float, float] = (0.0, 0.0, 0.0)
    joint: str = "R"
    limits: tuple[float, float] | None = None

    def exp(self, q: float) -> NDArray[np.float64]:
        """``exp([xi] q)``: rotation about / translation along the axis, (4, 4)."""
        k = np.asarray(self.k, dtype=float)
        p = np.asarray(self.p, dtype=float)
        if self.joint == "P":
            return make_transform(np.eye(3), k * q)
        K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
        R = np.eye(3) + np.sin(q) * K + (1 - np.cos(q)) * K @ K
        return make_transform(R, p - R @ p)


__all__ = ["DHRow", "MDHRow", "ScrewAxis", "check_joint"]
