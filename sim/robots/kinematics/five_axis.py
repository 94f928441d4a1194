"""The 5-axis closed form (seed 000's family) for a 5-axis arm given as data.

A 5-axis arm given by a DH table or a URDF is solved with the seeds' 5R closed form
(:class:`sim.robots.families.FiveR`) when its joint axes at q = 0 have the 5R structure: J1
vertical (along the base z axis, through the base origin), J2, J3 and J4 parallel and
horizontal, J5 perpendicular to J4 along the approach, every anchor in the vertical plane through
J1 (no lateral offset), and the flange point on the J5 axis. Its dimensions come from the
anchors (``l1``: J1 axis to J2, ``d1``: J2 to J3, ``l2``: J3 to J4, ``l3``: J4 to the flange
point) and the map from the arm's joint values to the family's is, per joint,
``theta = sign * q + offset`` (signs from the axis directions, offsets from the arm's zero
pose), with the family's frame 0 the base raised to the J2 height and a constant transform from
the family's tool frame (x = approach) to the arm's flange frame. The map is checked on random
configurations; an arm that does not fit keeps the numeric solver, with the reason.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from sim.errors import KinematicsError, UnreachableError
from sim.robots.families import FiveR

TOL = 1e-9


@dataclass(frozen=True)
class FiveAxisMap:
    """A 5-axis arm as the seeds' 5R family (module docstring).

    Attributes:
        dims: ``l1, d1, l2, l3``, m.
        height: Family frame 0 = the arm's base raised by this along z, m.
        signs: Per joint, +1 or -1. offsets: Per joint, rad (``theta = sign * q + offset``).
        flange: Family tool frame -> the arm's flange frame, (4, 4).
    """

    dims: dict[str, float]
    height: float
    signs: tuple[int, ...]
    offsets: tuple[float, ...]
    flange: NDArray[np.float64] = field(compare=False)

    def family(self) -> FiveR:
        return FiveR(self.dims)

    def theta(self, q) -> NDArray[np.float64]:
        return np.asarray(self.signs) * np.asarray(q, dtype=float) + np.asarray(self.offsets)

    def q(self, theta) -> NDArray[np.float64]:
        return (np.asarray(theta, dtype=float) - np.asarray(self.offsets)) * np.asarray(self.signs)

    def forward(self, q) -> NDArray[np.float64]:
        """The arm's flange pose in its base frame, (4, 4)."""
        T = self.family().fk(self.theta(q))
        T = T.copy()
        T[2, 3] += self.height
        return T @ self.flange

    def inverse(self, T) -> list[tuple[NDArray[np.float64], str]]:
        """Every closed-form solution (joint values of the arm, branch label) of a flange pose
        in the base frame; [] when unreachable."""
        Tf = np.asarray(T, dtype=float) @ np.linalg.inv(self.flange)
        Tf = Tf.copy()
        Tf[2, 3] -= self.height
        try:
            sols = self.family().ik(Tf, np.zeros(5))
        except UnreachableError:
            return []
        return [(self.q(th), label) for th, label in sols]


def five_axis_from_chain(chain) -> FiveAxisMap:
    """The 5R map of a 5-joint chain (module docstring).

    Raises:
        KinematicsError: Why the chain is not of the 5R family (one line).
    """
    if chain.n != 5:
        raise KinematicsError(f"{chain.n} joints (the 5-axis closed form is for 5)")
    axes, pts, F = chain.frames(np.zeros(5))
    z = np.array([0.0, 0.0, 1.0])
    if abs(abs(axes[0] @ z) - 1.0) > TOL or np.hypot(*pts[0][:2]) > TOL:
        raise KinematicsError("J1 is not the base z axis")
    y = axes[1]
    if abs(y @ z) > TOL or any(abs(abs(axes[i] @ y) - 1.0) > TOL for i in (2, 3)):
        raise KinematicsError("J2, J3, J4 are not parallel and horizontal")
    yf = y / np.linalg.norm(y)
    if np.cross(yf, z) @ F[:3, 3] < 0:  # the family's x points from J1 towards the tool
        yf = -yf
    e = np.cross(yf, z)  # the arm's horizontal direction at q = 0 (family x)
    # the flange point and J5's axis in the vertical plane through J1 (along e): no lateral
    # offset (where the parallel axes J2..J4 are anchored along themselves does not matter)
    flange = F[:3, 3]
    for p in (flange, pts[4]):
        if abs(p @ yf) > TOL:
            raise KinematicsError("a lateral offset (the flange or J5 is not in the vertical "
                                  "plane through J1)")
    pts = pts.copy()
    for i in (1, 2, 3):  # each parallel axis' point in that plane
        pts[i] = pts[i] - (pts[i] @ yf) * yf

    def plane(v):
        return float(v @ e), float(v @ z)

    h = float(pts[1] @ z)
    l1 = float(pts[1] @ e)
    # anchors on the parallel axes J2..J4: their positions in the plane (any point of an axis
    # projects to the same plane point)
    x23, z23 = plane(pts[2] - pts[1])
    x34, z34 = plane(pts[3] - pts[2])
    a5 = axes[4]
    # J5's axis meets J4's axis and carries the flange point
    v4f = flange - pts[3]
    l3 = float(np.linalg.norm(v4f))
    if (l3 < TOL or abs(abs(a5 @ v4f) / l3 - 1.0) > 1e-9
            or np.linalg.norm(np.cross(a5, pts[4] - pts[3])) > TOL):
        raise KinematicsError("the flange point is not on the J5 axis through J4")
    if abs(a5 @ yf) > TOL:
        raise KinematicsError("J5 is not perpendicular to J4")
    d1, l2 = math.hypot(x23, z23), math.hypot(x34, z34)
    if d1 < TOL or l2 < TOL:
        raise KinematicsError("a zero upper arm or forearm")
    x4f, z4f = plane(v4f)
    th2 = math.atan2(x23, z23)  # family: J2 -> J3 = d1 (sin t2, cos t2)
    th23 = math.atan2(-z34, x34)  # J3 -> J4 = l2 (cos t23, -sin t23)
    th234 = math.atan2(-z4f, x4f)  # J4 -> tcp = l3 (cos t234, -sin t234)
    signs = (int(np.sign(axes[0] @ z)), int(np.sign(axes[1] @ yf)), int(np.sign(axes[2] @ yf)),
             int(np.sign(axes[3] @ yf)), int(np.sign(a5 @ v4f)))
    offsets = (math.atan2(e[1], e[0]), th2, th23 - th2, th234 - th23, 0.0)
    dims = {"l1": l1, "d1": d1, "l2": l2, "l3": l3}
    T0 = FiveR(dims).fk(np.asarray(offsets))
    T0 = T0.copy()
    T0[2, 3] += h
    flange_T = np.linalg.inv(T0) @ F
    if np.linalg.norm(flange_T[:3, 3]) > 1e-9:
        raise KinematicsError("the flange is not the 5R tool point")
    m = FiveAxisMap(dims, h, signs, offsets, flange_T)
    rng = np.random.default_rng(0)
    for q in rng.uniform(-math.pi, math.pi, size=(20, 5)):
        if np.abs(m.forward(q) - chain.fk(q)).max() > 1e-9:
            raise KinematicsError("the 5R closed form does not reproduce the chain")
    return m


__all__ = ["FiveAxisMap", "five_axis_from_chain"]
