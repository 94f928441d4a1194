"""Interpolation of recorded MuJoCo states at arbitrary times (video frame times).

A video frame at time ``t`` lies between two recorded samples ``t[i] <= t <= t[i+1]``. Its
``qpos`` is interpolated joint by joint:

* hinge and slide joints: linearly;
* free joints: position linearly, orientation quaternion by spherical linear interpolation
  (slerp, shortest arc: the second quaternion's sign is flipped when the dot product is
  negative; normalized lerp when the two are nearly equal);
* ball joints: slerp.

Times outside the record are clamped to the first/last sample.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from sim.errors import UsageError


def slerp(q0: np.ndarray, q1: np.ndarray, u: float) -> np.ndarray:
    """Spherical linear interpolation of unit quaternions (w, x, y, z).

    Args:
        q0: Quaternion at ``u = 0``, (4,).
        q1: Quaternion at ``u = 1``, (4,).
        u: Fraction in [0, 1].

    Returns:
        Unit quaternion (4,) on the shorter arc from ``q0`` to ``q1``.
    """
    a = np.asarray(q0, dtype=float) / np.linalg.norm(q0)
    b = np.asarray(q1, dtype=float) / np.linalg.norm(q1)
    dot = float(np.dot(a, b))
    if dot < 0.0:
        b, dot = -b, -dot
    if dot > 0.9995:  # nearly parallel: normalized lerp is accurate and avoids 0/0
        out = a + u * (b - a)
        return out / np.linalg.norm(out)
    theta = np.arccos(min(dot, 1.0))
    s = np.sin(theta)
    return (np.sin((1.0 - u) * theta) / s) * a + (np.sin(u * theta) / s) * b


class QposInterpolator:
    """``qpos`` of a model at any time, from recorded samples.

    Args:
        model: The ``mujoco.MjModel`` the samples belong to.
        t: Sample times (N,), s, strictly increasing.
        qpos: Recorded ``qpos`` (N, model.nq).

    Raises:
        ValueError: ``qpos`` does not have ``model.nq`` columns or N rows.
    """

    def __init__(self, model: Any, t: np.ndarray, qpos: np.ndarray) -> None:
        import mujoco

        t = np.asarray(t, dtype=float)
        qpos = np.asarray(qpos, dtype=float)
        if qpos.ndim != 2 or qpos.shape != (t.size, model.nq):
            raise UsageError(
                f"qpos has shape {qpos.shape}, expected ({t.size}, {model.nq}) (nq of the model)"
            )
        self.t = t
        self.qpos = qpos
        linear = np.ones(model.nq, dtype=bool)
        self._quats: list[int] = []  # qpos address of each quaternion
        for j in range(model.njnt):
            adr = int(model.jnt_qposadr[j])
            jtype = model.jnt_type[j]
            if jtype == mujoco.mjtJoint.mjJNT_FREE:
                self._quats.append(adr + 3)
                linear[adr + 3 : adr + 7] = False
            elif jtype == mujoco.mjtJoint.mjJNT_BALL:
                self._quats.append(adr)
                linear[adr : adr + 4] = False
        self._linear = np.flatnonzero(linear)

    def __call__(self, time: float, out: np.ndarray | None = None) -> np.ndarray:
        """Interpolated ``qpos`` at ``time`` (s), (nq,); written into ``out`` when given."""
        t = self.t
        if out is None:
            out = np.empty(self.qpos.shape[1])
        if time <= t[0]:
            out[:] = self.qpos[0]
            return out
        if time >= t[-1]:
            out[:] = self.qpos[-1]
            return out
        i = int(np.searchsorted(t, time, side="right")) - 1
        u = (time - t[i]) / (t[i + 1] - t[i])
        a, b = self.qpos[i], self.qpos[i + 1]
        lin = self._linear
        out[lin] = a[lin] + u * (b[lin] - a[lin])
        for adr in self._quats:
            out[adr : adr + 4] = slerp(a[adr : adr + 4], b[adr : adr + 4], u)
        return out


def interp_rows(t: np.ndarray, values: np.ndarray, time: float) -> np.ndarray:
    """Linear interpolation of each column of ``values`` (N, ...) at ``time``, clamped."""
    if time <= t[0]:
        return values[0]
    if time >= t[-1]:
        return values[-1]
    i = int(np.searchsorted(t, time, side="right")) - 1
    u = (time - t[i]) / (t[i + 1] - t[i])
    return values[i] + u * (values[i + 1] - values[i])


def sample_index(t: np.ndarray, time: float) -> int:
    """Index of the last sample at or before ``time`` (0 before the first)."""
    return max(int(np.searchsorted(t, time, side="right")) - 1, 0)
