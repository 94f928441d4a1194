"""An independent rigid-body inverse dynamics of a mechanism (turntable, tilt-rotate positioner,
track) with an optional rigid payload on its mount: the judge of the joint torques cellsim
computes for a cell's external axes (issue 28's "tilt and rotate torques equal an independent
rigid-body calculation").

Recursive Newton-Euler written here from first principles, in the base frame, with its own
forward kinematics (nothing from ``sim.robots.mechanisms.kinematics``): the chain's convention is
the spec's, each axis's link frame is its parent's translated by ``pos`` (no rotation at zero),
turned about (revolute) or moved along (prismatic) the unit ``axis`` given in the parent frame.
Gravity enters as an upward acceleration of the base. Per axis it may add the rotor's reflected
inertia (``armature * qdd``), viscous damping (``damping * qd``) and Coulomb friction with
cellsim's law ``F * clip(qd / COULOMB_SPEED, -1, 1)``.

Checked in ``tests/robots/test_mechanism_oracle.py`` against pinocchio and hand cases.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.robots.drive import COULOMB_SPEED


@dataclass(frozen=True)
class OracleAxis:
    """One axis and the link it moves.

    Attributes:
        kind: ``"revolute"`` or ``"prismatic"``.
        pos: Origin of the axis (and of its link frame) in the parent frame at zero, m, (3,).
        axis: Direction of the axis in the parent frame (normalised here), (3,).
        mass: The link's mass, kg.
        com: The link's centre of mass in its frame, m, (3,).
        inertia: Principal moments at the centre of mass along the link frame's axes, kg m^2.
        armature: Reflected rotor inertia at the axis, kg m^2 (or kg).
        damping: Viscous damping, N m s/rad (or N s/m).
        friction: Coulomb friction, N m (or N).
    """

    kind: str
    pos: ArrayLike
    axis: ArrayLike
    mass: float
    com: ArrayLike
    inertia: ArrayLike
    armature: float = 0.0
    damping: float = 0.0
    friction: float = 0.0


@dataclass(frozen=True)
class OraclePayload:
    """A rigid body fixed to the mount (a part on a positioner's faceplate, a robot on a track).

    Attributes:
        mass: kg.
        com: Centre of mass in the mount frame, m, (3,).
        inertia: Inertia tensor at the centre of mass in the mount frame, kg m^2, (3, 3).
    """

    mass: float
    com: ArrayLike
    inertia: ArrayLike = field(default_factory=lambda: np.zeros((3, 3)))


def chain_from_spec(mech, armature: bool = True) -> list[OracleAxis]:
    """The oracle's chain from a :class:`~sim.robots.mechanisms.spec.MechanismSpec`'s own
    numbers (armature: the drive's ``rotor_inertia * gear_ratio**2`` where ``armature``)."""
    return [OracleAxis(a.kind, a.pos, a.axis, a.link.mass, a.link.com, a.link.inertia,
                       a.drive.rotor_inertia * a.drive.gear_ratio**2 if armature else 0.0,
                       a.damping, a.friction) for a in mech.axes]


def _rot(w: NDArray[np.float64], t: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rotations by angles ``t`` (N,) about unit ``w``: ``cos t I + sin t [w]x + (1 - cos t)
    w w^T``, (N, 3, 3)."""
    wx = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    c, s = np.cos(t)[:, None, None], np.sin(t)[:, None, None]
    return c * np.eye(3) + s * wx + (1.0 - c) * np.outer(w, w)


def _mv(R: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
    """Stacked matrix-vector products, (N, 3, 3) x (N, 3) or (3,) -> (N, 3)."""
    return np.einsum("nij,nj->ni", R, np.broadcast_to(v, R.shape[:-1]))


def inverse_dynamics(axes: Sequence[OracleAxis], q: ArrayLike, qd: ArrayLike, qdd: ArrayLike,
                     mount: ArrayLike | None = None, payload: OraclePayload | None = None,
                     gravity: ArrayLike = (0.0, 0.0, -9.81)) -> NDArray[np.float64]:
    """The axis torques (revolute, N m) and forces (prismatic, N) that move the chain along
    ``q, qd, qdd`` (each (N, n) or (n,)): recursive Newton-Euler in the base frame.

    Args:
        axes: The chain, base first.
        q, qd, qdd: Axis positions, speeds and accelerations.
        mount: The mount's pose in the last link's frame, (4, 4) (default identity).
        payload: A rigid body on the mount, or None.
        gravity: Gravity in the base frame, m/s^2.

    Returns:
        (N, n) (or (n,) for one sample): rigid-body torques + armature qdd + damping qd +
        Coulomb friction.
    """
    one = np.ndim(q) == 1
    q, qd, qdd = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (q, qd, qdd))
    N, n = q.shape
    M = np.eye(4) if mount is None else np.asarray(mount, dtype=float)
    R = np.broadcast_to(np.eye(3), (N, 3, 3))
    o = np.zeros((N, 3))
    w = np.zeros((N, 3))
    dw = np.zeros((N, 3))
    a = np.broadcast_to(-np.asarray(gravity, dtype=float), (N, 3)).copy()
    z_all, o_all, f_own, n_own = [], [], [], []
    for i, ax in enumerate(axes):
        u = np.asarray(ax.axis, dtype=float)
        u = u / np.linalg.norm(u)
        z = _mv(R, u)  # the axis in the base frame (the parent's rotation)
        r = _mv(R, np.asarray(ax.pos, dtype=float))
        if ax.kind == "revolute":
            a = a + np.cross(dw, r) + np.cross(w, np.cross(w, r))
            dw = dw + z * qdd[:, i, None] + np.cross(w, z * qd[:, i, None])
            w = w + z * qd[:, i, None]
            R = R @ _rot(u, q[:, i])
        elif ax.kind == "prismatic":
            r = r + z * q[:, i, None]
            a = (a + np.cross(dw, r) + np.cross(w, np.cross(w, r))
                 + 2.0 * np.cross(w, z * qd[:, i, None]) + z * qdd[:, i, None])
        else:
            raise ValueError(f"axis {i}: kind must be revolute or prismatic, got {ax.kind!r}")
        o = o + r
        bodies = [(ax.mass, np.asarray(ax.com, dtype=float), np.diag(ax.inertia))]
        if payload is not None and i == n - 1:
            bodies.append((payload.mass, M[:3, :3] @ np.asarray(payload.com, float) + M[:3, 3],
                           M[:3, :3] @ np.asarray(payload.inertia, float) @ M[:3, :3].T))
        f = np.zeros((N, 3))
        mo = np.zeros((N, 3))
        for m, c_local, I_local in bodies:
            c = _mv(R, c_local)  # centre of mass from the link's origin, base frame
            ac = a + np.cross(dw, c) + np.cross(w, np.cross(w, c))
            Iw = R @ I_local @ np.swapaxes(R, 1, 2)
            F = m * ac
            f = f + F
            mo = mo + _mv(Iw, dw) + np.cross(w, _mv(Iw, w)) + np.cross(c, F)
        z_all.append(z)
        o_all.append(o)
        f_own.append(f)
        n_own.append(mo)
    tau = np.zeros((N, n))
    f_next = np.zeros((N, 3))
    n_next = np.zeros((N, 3))
    for i in range(n - 1, -1, -1):
        lever = o_all[i + 1] - o_all[i] if i + 1 < n else np.zeros((N, 3))
        f_i = f_own[i] + f_next
        n_i = n_own[i] + n_next + np.cross(lever, f_next)
        along = n_i if axes[i].kind == "revolute" else f_i
        tau[:, i] = np.sum(z_all[i] * along, axis=1)
        f_next, n_next = f_i, n_i
    arm = np.array([ax.armature for ax in axes])
    damp = np.array([ax.damping for ax in axes])
    fric = np.array([ax.friction for ax in axes])
    tau = tau + arm * qdd + damp * qd + fric * np.clip(qd / COULOMB_SPEED, -1.0, 1.0)
    return tau[0] if one else tau


__all__ = ["OracleAxis", "OraclePayload", "chain_from_spec", "inverse_dynamics"]
