"""Rotations and homogeneous transforms used by the kinematics.

Euler angles follow seed 000 eq. (6): ``R = Rz(alpha) @ Ry(beta) @ Rx(gamma)`` (Z-Y-X, moving
axes; equivalently X-Y-Z about fixed axes). All angles in radians; functions that take stacks of
angles broadcast over leading dimensions.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray


def rot_x(angle: ArrayLike) -> NDArray[np.float64]:
    """Rotation about x by ``angle`` (rad); shape ``angle.shape + (3, 3)``."""
    a = np.asarray(angle, dtype=float)
    c, s = np.cos(a), np.sin(a)
    if a.ndim == 0:  # one angle (the inverse kinematics' case): no stacking
        c, s = float(c), float(s)
        return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1),
                     np.stack([z, s, c], -1)], -2)


def rot_y(angle: ArrayLike) -> NDArray[np.float64]:
    """Rotation about y by ``angle`` (rad); shape ``angle.shape + (3, 3)``."""
    a = np.asarray(angle, dtype=float)
    c, s = np.cos(a), np.sin(a)
    if a.ndim == 0:  # one angle (the inverse kinematics' case): no stacking
        c, s = float(c), float(s)
        return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1),
                     np.stack([-s, z, c], -1)], -2)


def rot_z(angle: ArrayLike) -> NDArray[np.float64]:
    """Rotation about z by ``angle`` (rad); shape ``angle.shape + (3, 3)``."""
    a = np.asarray(angle, dtype=float)
    c, s = np.cos(a), np.sin(a)
    if a.ndim == 0:  # one angle (the inverse kinematics' case): no stacking
        c, s = float(c), float(s)
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1),
                     np.stack([z, z, o], -1)], -2)


def euler_zyx_to_matrix(alpha: ArrayLike, beta: ArrayLike, gamma: ArrayLike) -> NDArray[np.float64]:
    """``Rz(alpha) Ry(beta) Rx(gamma)`` (seed 000 eq. 6); angles in rad, shape (..., 3, 3)."""
    return rot_z(alpha) @ rot_y(beta) @ rot_x(gamma)


def matrix_to_euler_zyx(R: ArrayLike) -> NDArray[np.float64]:
    """Z-Y-X Euler angles ``(alpha, beta, gamma)`` of a rotation matrix (seed 000 eq. 6).

    The branch with ``cos(beta) >= 0`` (beta in [-pi/2, pi/2]) is returned. At the
    representation singularity ``cos(beta) = 0`` only ``alpha -+ gamma`` is defined; gamma is
    then set to 0.

    Args:
        R: Rotation matrix, shape (..., 3, 3).

    Returns:
        Angles in rad, shape (..., 3).
    """
    R = np.asarray(R, dtype=float)
    sb = np.clip(-R[..., 2, 0], -1.0, 1.0)
    cb = np.hypot(R[..., 0, 0], R[..., 1, 0])
    beta = np.arctan2(sb, cb)
    regular = cb > 1e-9
    alpha = np.where(regular, np.arctan2(R[..., 1, 0], R[..., 0, 0]),
                     np.arctan2(-R[..., 0, 1], R[..., 1, 1]))
    gamma = np.where(regular, np.arctan2(R[..., 2, 1], R[..., 2, 2]), 0.0)
    return np.stack([alpha, beta, gamma], -1)


def make_transform(R: ArrayLike, p: ArrayLike) -> NDArray[np.float64]:
    """Homogeneous transform from rotation ``R`` (..., 3, 3) and position ``p`` (..., 3)."""
    R = np.asarray(R, dtype=float)
    p = np.asarray(p, dtype=float)
    T = np.zeros(np.broadcast_shapes(R.shape[:-2], p.shape[:-1]) + (4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = p
    T[..., 3, 3] = 1.0
    return T


def invert_transform(T: ArrayLike) -> NDArray[np.float64]:
    """Inverse of homogeneous transform(s) ``T``, shape (..., 4, 4)."""
    T = np.asarray(T, dtype=float)
    R = T[..., :3, :3]
    Rt = np.swapaxes(R, -1, -2)
    return make_transform(Rt, -(Rt @ T[..., :3, 3:4])[..., 0])


def rotation_angle_between(R1: ArrayLike, R2: ArrayLike) -> NDArray[np.float64]:
    """Angle (rad) of the relative rotation ``R1^T R2``; shape (...)."""
    R = np.swapaxes(np.asarray(R1, dtype=float), -1, -2) @ np.asarray(R2, dtype=float)
    c = (np.trace(R, axis1=-2, axis2=-1) - 1.0) / 2.0
    # acos is ill-conditioned near 0: use the skew part too.
    s = 0.5 * np.linalg.norm(np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0],
                                       R[..., 1, 0] - R[..., 0, 1]], -1), axis=-1)
    return np.arctan2(s, np.clip(c, -1.0, 1.0))


def wrap_to_pi(angle: ArrayLike) -> NDArray[np.float64]:
    """Wrap angle(s) into [-pi, pi)."""
    a = np.asarray(angle, dtype=float)
    return (a + np.pi) % (2 * np.pi) - np.pi
