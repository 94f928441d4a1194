"""Jacobians, manipulability and distance-to-singularity measures (vectorized over N configs).

* :func:`geometric_jacobian`: 6 x n geometric Jacobian of the tcp in frame 0, rows
  ``[v_x, v_y, v_z, w_x, w_y, w_z]`` (linear velocity of the tcp point, m/s per rad/s, then
  angular velocity), column ``i = [z_i x (p - o_i); z_i]`` from the closed-form joint axes.
* :func:`task_jacobian_5r`: 5 x 5 Jacobian of seed 000's task vector eq. (8)
  ``X = [p_x, p_y, p_z, beta_y, gamma_x]`` (eq. 7 gives ``beta = q2+q3+q4``, ``gamma = q5``;
  ``alpha = q1`` is not independent). These are the "appropriate rows" for the 5-axis robots:
  a 5-axis arm cannot realize an arbitrary 6-D twist, and its 6 x 5 geometric Jacobian has
  ``det(J J^T) = 0`` everywhere.
* :func:`manipulability`: Yoshikawa's ``sqrt(det(J J^T))``: on the 6 x 6 geometric Jacobian
  for the 200iC, on the 5 x 5 task Jacobian for the 5-axis robots.
* :func:`singularity_measures`: smallest singular value plus the explicit factors of
  ``det J``:

  - 200iC (seed 004 eq. 22-25): ``det J = -d3 * (R4 c3 - d4 s3) * rho_w * s5`` where
    ``rho_w = d2 - d3 s2 + R4 c23 - d4 s23`` is the signed distance of the wrist centre from
    the J1 axis. Wrist: ``s5`` (eq. 23), elbow: ``R4 c3 - d4 s3`` (eq. 24, zero at
    ``theta3 = atan2(R4, d4)`` and that +pi), shoulder: ``rho_w`` (eq. 25, see the note there).
  - 5R (seed 000): ``det J_task = reach * d1 * l2 * c3`` with
    ``reach = l1 + d1 s2 + l2 c23 + l3 c234`` (tool point distance from the J1 axis, signed)
    and ``c3 = cos q3`` (elbow stretched when ``q3 = +-90 deg``).

Note on seed 004 eq. (25): as printed, ``d2 + d3 S2 + C2 (R4 C3 - d4 S3) + S2 (R4 S3 + d4 C3)``
equals ``d2 + d3 sin t2 + R4 cos(t2 - t3) + d4 sin(t2 - t3)``, i.e. ``rho_w`` with theta2 of the
opposite sign. With the seed's own eq. (6) (the forward model every cellsim module uses),
the factor that vanishes is ``rho_w`` above (tested: it is eq. 25 with ``theta2 -> -theta2``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.errors import KinematicsError
from sim.robots.families import FiveR
from sim.robots.families.base import geometric_from_frames
from sim.robots.kinematics.model import KinematicModel


def geometric_jacobian(model: KinematicModel, q: ArrayLike) -> NDArray[np.float64]:
    """Geometric Jacobian of the tcp in frame 0, from the closed-form joint axes.

    Args:
        model: The robot's kinematic model.
        q: Joint values, rad, shape (n,) or (N, n).

    Returns:
        J, shape (6, n) or (N, 6, n): rows v (m/s per rad/s) then omega (rad/s per rad/s).
    """
    return geometric_from_frames(*model.joint_frames(q))


def task_jacobian_5r(model: KinematicModel, q: ArrayLike) -> NDArray[np.float64]:
    """Jacobian of seed 000's task vector ``[p_x, p_y, p_z, beta_y, gamma_x]`` (eq. 7-8).

    Args:
        model: A ``"5r"`` model.
        q: Joint values, rad, shape (5,) or (N, 5).

    Returns:
        Shape (5, 5) or (N, 5, 5).
    """
    if not isinstance(model.family, FiveR):
        raise KinematicsError(f"task_jacobian_5r needs a 5R model, got {model.family.name}")
    return model.family.task_jacobian(geometric_jacobian(model, q))


def task_jacobian(model: KinematicModel, q: ArrayLike) -> NDArray[np.float64]:
    """The square Jacobian used for manipulability: 6 x 6 geometric (200iC), 5 x 5 task (5R)."""
    return model.family.task_jacobian(geometric_jacobian(model, q))


def manipulability(J: ArrayLike) -> NDArray[np.float64]:
    """Yoshikawa's measure ``sqrt(det(J J^T))`` of Jacobian(s) J, shape (..., m, n) -> (...)."""
    J = np.asarray(J, dtype=float)
    d = np.linalg.det(J @ np.swapaxes(J, -1, -2))
    return np.sqrt(np.clip(d, 0.0, None))


def numeric_jacobian(model: KinematicModel, q: ArrayLike, eps: float = 1e-6) -> NDArray[np.float64]:
    """Central finite-difference geometric Jacobian of the tcp (an independent check), (6, n).

    The angular rows come from the rotation difference ``vee(R(q+h) R(q-h)^T) / 2h``.
    """
    q = np.asarray(q, dtype=float)
    n = q.size
    J = np.zeros((6, n))
    for i in range(n):
        dq = np.zeros(n)
        dq[i] = eps
        Tp, Tm = model.fk(q + dq), model.fk(q - dq)
        J[:3, i] = (Tp[:3, 3] - Tm[:3, 3]) / (2 * eps)
        dR = Tp[:3, :3] @ Tm[:3, :3].T
        J[3:, i] = np.array([dR[2, 1] - dR[1, 2], dR[0, 2] - dR[2, 0], dR[1, 0] - dR[0, 1]]) / (
            2 * 2 * eps)
    return J


def singularity_measures(model: KinematicModel, q: ArrayLike) -> dict[str, NDArray[np.float64]]:
    """Distance-to-singularity measures along a joint trajectory.

    Args:
        model: The robot's kinematic model.
        q: Joint values, rad, shape (n,) or (N, n).

    Returns:
        Dict of arrays of shape () or (N,):

        * ``sigma_min``: smallest singular value of :func:`task_jacobian` (mixed units; 0 at
          a singularity);
        * ``manipulability``: Yoshikawa's measure of the same Jacobian;
        * ``det``: its determinant (where it is square; else the product of its singular
          values);
        * ``wrist``/``elbow``/``shoulder``: the explicit factors of ``det`` (module docstring):
          200iC: ``sin theta5``, ``(R4 c3 - d4 s3) / sqrt(R4^2 + d4^2)`` (dimensionless),
          ``rho_w`` (m); 5R: ``wrist`` is absent, ``elbow = cos q3``, ``shoulder = reach`` (m).
    """
    Q = np.asarray(q, dtype=float)
    J = task_jacobian(model, Q)
    sv = np.linalg.svd(J, compute_uv=False)
    out: dict[str, NDArray[np.float64]] = {
        "sigma_min": sv[..., -1],
        "manipulability": manipulability(J),
        # an arm with fewer or more joints than its task's dimensions has no determinant:
        # the product of the singular values (the same up to sign where J is square)
        "det": np.linalg.det(J) if J.shape[-1] == J.shape[-2] else np.prod(sv, axis=-1),
    }
    out.update(model.family.singular_factors(Q))
    return out
