"""Tool-frame orientation along a Cartesian move.

The tool frame is seed 003's position matrix G (eq. 8) without its position column: a rotation
matrix whose columns are the versors ``n``, ``o``, ``a`` (normal, orientation/sliding, approach)
expressed in the base frame. An orientation law maps the normalized path parameter
``u = s / L`` in [0, 1] to a rotation ``R(u)`` and its derivative ``dR/du``; driving ``u`` by the
move's time law makes the orientation start and stop together with the tool point (seed 003,
conclusions: "the number of angle steps is equal with steps number computed for trajectory
traverse").

Laws:

* :class:`GeodesicOrientation` (``"geodesic"``): the shortest rotation between the start and end
  frames at a uniform rate, ``R(u) = R0 Exp(u Log(R0^T R1))`` (slerp).
* :class:`AxisCarriedOrientation` (``"carry"``): the start frame turned about a fixed axis by
  ``u * angle``; on an arc about the arc's axis this keeps the torch's work and travel angles to
  the seam constant.
* :class:`SphericalVersorOrientation` (``"spherical"``): seed 003 eq. (19)-(24): each versor's
  spherical angles (seed notation: ``varphi`` in the xy-plane from x, ``phi`` from +z) stepped
  linearly. The three versors so obtained are not orthogonal in general; the frame is made
  orthonormal by keeping ``a`` exactly as the seed computes it (the torch/approach axis), taking
  ``o`` as the seed's ``o`` with its component along ``a`` removed and normalized, and
  ``n = o x a``.

Every law returns frames orthonormal with ``det = +1`` to rounding error (~1e-15).
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from planners.errors import InvalidOrientationError

__all__ = [
    "ORIENTATION_MODES",
    "InvalidOrientationError",
    "OrientationLaw",
    "GeodesicOrientation",
    "AxisCarriedOrientation",
    "SphericalVersorOrientation",
    "as_rotation",
    "skew",
    "axis_angle_matrix",
    "rotation_log",
    "angular_velocity",
    "spherical_angles",
    "spherical_versor",
]

#: Names of the orientation laws accepted by the move builders.
ORIENTATION_MODES = ("geodesic", "carry", "spherical")

#: Largest |R^T R - I| entry accepted for a user-given rotation matrix.
ORTHONORMAL_TOL = 1e-6


def as_rotation(R: ArrayLike, field: str = "rotation", tol: float = ORTHONORMAL_TOL
                ) -> NDArray[np.float64]:
    """Check that ``R`` is a rotation matrix and return its nearest exact rotation.

    Args:
        R: Candidate rotation, shape (3, 3), columns n, o, a.
        field: Name used in the error message.
        tol: Largest accepted entry of |R^T R - I|.

    Returns:
        The orthonormal matrix nearest to ``R`` (polar factor by SVD), det = +1, shape (3, 3).

    Raises:
        InvalidOrientationError: wrong shape, NaN/inf, not orthonormal within ``tol``, or det < 0.
    """
    try:
        M = np.asarray(R, dtype=float)
    except (TypeError, ValueError):
        raise InvalidOrientationError(f"{field}: expected a 3x3 rotation matrix, got {R!r}") from None
    if M.shape != (3, 3):
        raise InvalidOrientationError(
            f"{field}: expected a 3x3 rotation matrix (columns n, o, a), got shape {M.shape}")
    if not np.all(np.isfinite(M)):
        raise InvalidOrientationError(f"{field}: rotation matrix contains NaN or inf")
    err = float(np.max(np.abs(M.T @ M - np.eye(3))))
    if err > tol:
        raise InvalidOrientationError(
            f"{field}: columns n, o, a are not orthonormal (max |R^T R - I| = {err:.3g} > {tol:g})")
    if np.linalg.det(M) < 0:
        raise InvalidOrientationError(
            f"{field}: det = -1, a reflection; use a right-handed frame with n = o x a")
    U, _, Vt = np.linalg.svd(M)
    return U @ Vt


def skew(v: ArrayLike) -> NDArray[np.float64]:
    """Cross-product matrix [v]x, shape (..., 3, 3), of vectors ``v`` of shape (..., 3)."""
    v = np.asarray(v, dtype=float)
    K = np.zeros(v.shape[:-1] + (3, 3))
    K[..., 0, 1], K[..., 0, 2] = -v[..., 2], v[..., 1]
    K[..., 1, 0], K[..., 1, 2] = v[..., 2], -v[..., 0]
    K[..., 2, 0], K[..., 2, 1] = -v[..., 1], v[..., 0]
    return K


def axis_angle_matrix(axis: ArrayLike, angle: ArrayLike) -> NDArray[np.float64]:
    """Rotation by ``angle`` (rad, shape (...)) about the unit ``axis`` (3,) (Rodrigues).

    Returns:
        Rotation matrices, shape (..., 3, 3).
    """
    k = np.asarray(axis, dtype=float)
    norm = float(np.linalg.norm(k))
    th = np.asarray(angle, dtype=float)[..., None, None]
    if not norm > 0.0:  # no axis (a zero or underflowing vector): only a zero turn is defined
        if np.any(th != 0.0):
            raise ValueError("axis_angle_matrix: a turn about a zero axis")
        return np.broadcast_to(np.eye(3), th.shape[:-2] + (3, 3)).copy()
    k = k / norm
    K = skew(k)
    return np.eye(3) + np.sin(th) * K + (1.0 - np.cos(th)) * (K @ K)


def rotation_log(R: ArrayLike) -> NDArray[np.float64]:
    """Rotation vector (axis * angle, rad, angle in [0, pi]) of a rotation matrix (3, 3)."""
    return Rotation.from_matrix(np.asarray(R, dtype=float)).as_rotvec()


def angular_velocity(R: ArrayLike, dR: ArrayLike) -> NDArray[np.float64]:
    """Angular velocity w of an orthonormal frame from its derivative: dR = [w]x R.

    Uses ``w = 1/2 sum_i r_i x r_i'`` over the columns r_i; exact for an orthonormal frame.

    Args:
        R: Frames, shape (..., 3, 3).
        dR: Their derivatives with respect to any parameter, shape (..., 3, 3).

    Returns:
        w, base-frame components, shape (..., 3), in rad per unit of that parameter.
    """
    R = np.asarray(R, dtype=float)
    dR = np.asarray(dR, dtype=float)
    return 0.5 * np.sum(np.cross(R, dR, axisa=-2, axisb=-2, axisc=-1), axis=-2)


def spherical_angles(v: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Seed 003 spherical angles of unit vector(s) ``v`` (..., 3).

    Returns:
        ``(varphi, phi)``, rad: ``varphi = atan2(y, x)`` (angle in the xy-plane from x, the
        seed's "polar angle"), ``phi = atan2(hypot(x, y), z)`` (angle from +z, the seed's
        "azimuthal angle"; accurate near the poles, unlike arccos(z)).
    """
    v = np.asarray(v, dtype=float)
    return (np.arctan2(v[..., 1], v[..., 0]),
            np.arctan2(np.hypot(v[..., 0], v[..., 1]), v[..., 2]))


def spherical_versor(varphi: ArrayLike, phi: ArrayLike) -> NDArray[np.float64]:
    """Unit vector(s) of seed 003 eq. (16)-(18) with R = 1: (sin phi cos varphi, sin phi sin varphi, cos phi)."""
    varphi = np.asarray(varphi, dtype=float)
    phi = np.asarray(phi, dtype=float)
    return np.stack([np.sin(phi) * np.cos(varphi), np.sin(phi) * np.sin(varphi), np.cos(phi)], axis=-1)


class OrientationLaw(Protocol):
    """Tool-frame rotation as a function of the normalized path parameter u in [0, 1]."""

    start: NDArray[np.float64]
    end: NDArray[np.float64]

    def evaluate(self, u: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(R, dR/du)`` at ``u`` of shape (...): each of shape (..., 3, 3)."""
        ...


class GeodesicOrientation:
    """Shortest-arc (slerp) rotation from ``start`` to ``end`` at a uniform rate in u.

    For a half-turn (angle = pi) the shortest arc is not unique; one of the two is taken.

    Args:
        start: Start tool frame, (3, 3), columns n, o, a.
        end: End tool frame, (3, 3).
    """

    name = "geodesic"

    def __init__(self, start: ArrayLike, end: ArrayLike) -> None:
        self.start = as_rotation(start, "rotation_start")
        end = as_rotation(end, "rotation_end")
        w = rotation_log(self.start.T @ end)          # body-frame rotation vector, rad
        self.angle = float(np.linalg.norm(w))
        self._axis_body = w / self.angle if self.angle > 0.0 else np.array([0.0, 0.0, 1.0])
        self.axis = self.start @ self._axis_body      # base-frame axis (constant)
        self.end = self.start @ axis_angle_matrix(self._axis_body, self.angle)

    def evaluate(self, u: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        u = np.asarray(u, dtype=float)
        R = self.start @ axis_angle_matrix(self._axis_body, u * self.angle)
        dR = self.angle * (skew(self.axis) @ R)
        return R, dR


class AxisCarriedOrientation:
    """Start frame turned about a fixed base-frame ``axis`` by ``u * angle``.

    Args:
        start: Start tool frame, (3, 3).
        axis: Rotation axis, base frame, (3,) (normalized here).
        angle: Total rotation at u = 1, rad (right-hand rule about ``axis``).
    """

    name = "carry"

    def __init__(self, start: ArrayLike, axis: ArrayLike, angle: float) -> None:
        self.start = as_rotation(start, "rotation_start")
        k = np.asarray(axis, dtype=float)
        self.axis = k / np.linalg.norm(k)
        self.angle = float(angle)
        self.end = axis_angle_matrix(self.axis, self.angle) @ self.start

    def evaluate(self, u: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        u = np.asarray(u, dtype=float)
        R = axis_angle_matrix(self.axis, u * self.angle) @ self.start
        dR = self.angle * (skew(self.axis) @ R)
        return R, dR


def _versor_angle_steps(v0: NDArray[np.float64], v1: NDArray[np.float64]
                        ) -> tuple[float, float, float, float]:
    """Start angles and total changes (varphi0, phi0, dvarphi, dphi) for one versor.

    The varphi change is wrapped to (-pi, pi] (the shorter way round the z axis). A versor on
    the z axis has no varphi; it takes the other end's, so only phi changes.
    """
    (f0, p0), (f1, p1) = spherical_angles(v0), spherical_angles(v1)
    f0, p0, f1, p1 = float(f0), float(p0), float(f1), float(p1)
    pole0 = np.hypot(v0[0], v0[1]) < 1e-15
    pole1 = np.hypot(v1[0], v1[1]) < 1e-15
    if pole0 and not pole1:
        f0 = f1
    elif pole1 and not pole0:
        f1 = f0
    elif pole0 and pole1:
        f1 = f0
    df = (f1 - f0 + np.pi) % (2.0 * np.pi) - np.pi
    if df == -np.pi:
        df = np.pi
    return f0, p0, float(df), p1 - p0


class SphericalVersorOrientation:
    """Seed 003 eq. (19)-(24): per-versor spherical-angle interpolation, made orthonormal.

    Each of ``n``, ``o``, ``a`` gets its own (varphi, phi) stepped linearly from the start to the
    end frame; ``a`` is kept as the seed computes it, ``o`` is orthogonalized against ``a`` and
    ``n = o x a``.

    Args:
        start: Start tool frame, (3, 3), columns n, o, a.
        end: End tool frame, (3, 3).

    Raises:
        InvalidOrientationError: the seed's interpolated ``o`` becomes (nearly) parallel to
            ``a`` somewhere on the move, so no frame can be built (use ``"geodesic"``).
    """

    name = "spherical"

    def __init__(self, start: ArrayLike, end: ArrayLike) -> None:
        self.start = as_rotation(start, "rotation_start")
        end = as_rotation(end, "rotation_end")
        # rows: versors n, o, a; columns: varphi0, phi0, dvarphi, dphi
        self.angles = np.array([_versor_angle_steps(self.start[:, i], end[:, i]) for i in range(3)])
        u = np.linspace(0.0, 1.0, 2049)
        raw = self.raw_versors(u)
        o_perp = raw[..., 1] - np.sum(raw[..., 1] * raw[..., 2], axis=-1)[..., None] * raw[..., 2]
        worst = float(np.min(np.linalg.norm(o_perp, axis=-1)))
        if worst < 1e-3:
            raise InvalidOrientationError(
                "orientation: seed 003 per-versor interpolation makes o parallel to a"
                f" (|o x a| = {worst:.2g}) between these frames; use orientation='geodesic'")
        self.end = self.evaluate(1.0)[0]

    def raw_versors(self, u: ArrayLike) -> NDArray[np.float64]:
        """The seed's versors before orthonormalization, eq. (19)-(24).

        Returns:
            Shape (..., 3, 3): columns n, o, a, each a unit vector.
        """
        u = np.asarray(u, dtype=float)[..., None]
        f = self.angles[:, 0] + u * self.angles[:, 2]
        p = self.angles[:, 1] + u * self.angles[:, 3]
        return np.swapaxes(spherical_versor(f, p), -1, -2)

    def _raw_derivative(self, u: NDArray[np.float64]) -> NDArray[np.float64]:
        u = u[..., None]
        f = self.angles[:, 0] + u * self.angles[:, 2]
        p = self.angles[:, 1] + u * self.angles[:, 3]
        df, dp = self.angles[:, 2], self.angles[:, 3]
        d = np.stack([dp * np.cos(p) * np.cos(f) - df * np.sin(p) * np.sin(f),
                      dp * np.cos(p) * np.sin(f) + df * np.sin(p) * np.cos(f),
                      -dp * np.sin(p)], axis=-1)
        return np.swapaxes(d, -1, -2)

    def evaluate(self, u: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        u = np.asarray(u, dtype=float)
        raw = self.raw_versors(u)
        draw = self._raw_derivative(u)
        a, da = raw[..., 2], draw[..., 2]
        o_raw, do_raw = raw[..., 1], draw[..., 1]
        c = np.sum(o_raw * a, axis=-1)[..., None]
        dc = (np.sum(do_raw * a, axis=-1) + np.sum(o_raw * da, axis=-1))[..., None]
        ot = o_raw - c * a
        dot_ = do_raw - dc * a - c * da
        norm = np.linalg.norm(ot, axis=-1)[..., None]
        o = ot / norm
        do = (dot_ - np.sum(o * dot_, axis=-1)[..., None] * o) / norm
        n = np.cross(o, a)
        dn = np.cross(do, a) + np.cross(o, da)
        R = np.stack([n, o, a], axis=-1)
        dR = np.stack([dn, do, da], axis=-1)
        return R, dR
