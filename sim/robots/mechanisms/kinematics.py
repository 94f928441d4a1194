"""Forward kinematics of a mechanism (placeholder until the full module lands)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from sim.robots.mechanisms.spec import MechanismSpec


def _rot(axis: NDArray[np.float64], angle: NDArray[np.float64]) -> NDArray[np.float64]:
    a = axis / np.linalg.norm(axis)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    s, c = np.sin(angle)[..., None, None], np.cos(angle)[..., None, None]
    return np.eye(3) + s * K + (1 - c) * (K @ K)


def link_poses(mech: MechanismSpec, q: NDArray[np.float64]) -> NDArray[np.float64]:
    q = np.asarray(q, dtype=float)
    lead = q.shape[:-1]
    T = np.broadcast_to(np.eye(4), (*lead, 4, 4)).copy()
    out = []
    for i, ax in enumerate(mech.axes):
        J = np.broadcast_to(np.eye(4), (*lead, 4, 4)).copy()
        J[..., :3, 3] = ax.pos
        M = np.broadcast_to(np.eye(4), (*lead, 4, 4)).copy()
        if ax.kind == "revolute":
            M[..., :3, :3] = _rot(np.asarray(ax.axis, float), q[..., i])
        else:
            M[..., :3, 3] = q[..., i, None] * np.asarray(ax.axis, float)
        T = T @ J @ M
        out.append(T)
    return np.stack(out, axis=-3)


def mount_pose(mech: MechanismSpec, q: NDArray[np.float64]) -> NDArray[np.float64]:
    return link_poses(mech, q)[..., -1, :, :] @ mech.mount
