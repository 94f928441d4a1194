"""Numeric inverse kinematics for any serial chain: Newton steps with damping, from many seeds.

For arms without a closed form (neither OPW, offset-wrist nor 5R: e.g. a URDF with a tilted
wrist). Each seed
(the current configuration first, then seeds spread over the joint ranges by a fixed-seed
generator, so results repeat) runs damped Gauss-Newton steps on the 6-d pose error (position m,
orientation as the rotation vector of ``R_target R^T``), ``dq = J^T (J J^T + lambda^2 I)^-1 e``
with ``lambda`` shrinking as the error falls, until the error is below ``tol`` (1e-12 by
default: the position in m and the angle in rad). Converged configurations within the joint
limits are kept, deduplicated modulo 2 pi, nearest to the current configuration first.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.robots.kinematics.chain import Chain


def pose_error(T: NDArray[np.float64], target: NDArray[np.float64]) -> NDArray[np.float64]:
    """6-d error from ``T`` to ``target``: position (m) then rotation vector (rad), base frame."""
    e = np.empty(6)
    e[:3] = target[:3, 3] - T[:3, 3]
    R = target[:3, :3] @ T[:3, :3].T
    c = max(-1.0, min(1.0, (np.trace(R) - 1.0) / 2.0))
    angle = math.acos(c)
    v = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if angle < 1e-9:
        e[3:] = 0.5 * v
    elif np.pi - angle < 1e-6:  # near pi: the axis from the symmetric part
        k = int(np.argmax(np.diag(R)))
        axis = (R[:, k] + np.eye(3)[k]) / math.sqrt(2.0 * (1.0 + R[k, k]))
        e[3:] = angle * axis * (1.0 if axis @ v >= 0 else -1.0)
    else:
        e[3:] = angle / (2.0 * math.sin(angle)) * v
    return e


#: A seed still this far off after :data:`GIVE_UP_AFTER` steps is abandoned for the next one
#: (it is caught in a local minimum or crawling along a singular direction).
GIVE_UP_ERROR, GIVE_UP_AFTER = 1e-2, 12


def solve_one(chain: Chain, target: NDArray[np.float64], q0: NDArray[np.float64], *,
              tol: float = 1e-12, max_iter: int = 40) -> tuple[NDArray[np.float64], float]:
    """Damped Newton from ``q0``; returns the last configuration and its error norm."""
    q = np.array(q0, dtype=float)
    J, T = chain.jacobian(q)
    e = pose_error(T, target)
    err = float(np.linalg.norm(e))
    for it in range(max_iter):
        if err < tol or (it >= GIVE_UP_AFTER and err > GIVE_UP_ERROR):
            break
        lam2 = min(1e-2, err * err)
        dq = J.T @ np.linalg.solve(J @ J.T + lam2 * np.eye(6), e)
        step = float(np.max(np.abs(dq)))
        if step > 0.5:  # keep the steps local far from the solution
            dq *= 0.5 / step
        q_new = q + dq
        J_new, T_new = chain.jacobian(q_new)
        e_new = pose_error(T_new, target)
        err_new = float(np.linalg.norm(e_new))
        if err_new < err or step < 1e-3:
            q, J, e, err = q_new, J_new, e_new, err_new
        else:
            q = q + 0.3 * dq
            J, T = chain.jacobian(q)
            e = pose_error(T, target)
            err = float(np.linalg.norm(e))
    return q, err


def _wrap_into(q: NDArray[np.float64], lo: NDArray[np.float64], hi: NDArray[np.float64]
               ) -> NDArray[np.float64]:
    """Each joint turned by whole turns into [lo, hi] where possible."""
    out = q.copy()
    for i in range(len(q)):
        if np.isfinite(lo[i]) and np.isfinite(hi[i]):
            k = math.ceil((lo[i] - q[i]) / (2 * np.pi) - 1e-12)
            cand = q[i] + 2 * np.pi * k
            if cand <= hi[i] + 1e-9:
                out[i] = cand
    return out


def solve_ik(chain: Chain, target: ArrayLike, current: ArrayLike | None = None, *,
             seeds: int = 32, tol: float = 1e-12,
             first: bool = False, seed: int = 0) -> list[NDArray[np.float64]]:
    """All configurations found for a flange pose, within the joint limits.

    Args:
        chain: The arm.
        target: Flange pose in the base frame, (4, 4).
        current: The configuration to start from (and rank by), rad, (n,).
        seeds: Random seeds tried after ``current``.
        tol: Pose error accepted (position m + rotation rad, 2-norm).
        first: Return as soon as one solution is found.
        seed: Random generator seed.

    Returns:
        Solutions (rad, (n,) each), deduplicated modulo 2 pi, nearest to ``current`` first.
    """
    T = np.asarray(target, dtype=float)
    lo, hi = chain.lower, chain.upper
    q_cur = np.zeros(chain.n) if current is None else np.asarray(current, dtype=float)
    rng = np.random.default_rng(seed)
    span_lo = np.where(np.isfinite(lo), lo, -np.pi)
    span_hi = np.where(np.isfinite(hi), hi, np.pi)
    found: list[NDArray[np.float64]] = []
    for k in range(seeds + 1):
        q0 = q_cur if k == 0 else rng.uniform(span_lo, span_hi)
        q, err = solve_one(chain, T, q0, tol=tol)
        if err < tol:
            q = _wrap_into(q, lo, hi)
            if np.all(q >= lo - 1e-9) and np.all(q <= hi + 1e-9):
                d = [np.max(np.abs(np.angle(np.exp(1j * (q - f))))) for f in found]
                if not d or min(d) > 1e-6:
                    found.append(q)
                    if first:
                        break
    found.sort(key=lambda s: float(np.sum(np.abs(s - q_cur))))
    return found


__all__ = ["pose_error", "solve_ik", "solve_one"]
