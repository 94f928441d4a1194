"""The maker's joint convention of each robot: the joint values its controller shows.

cellsim's joint values are the seeds' (the papers' generalized coordinates, serial joints). A
FANUC controller shows other numbers for the same posture:

* **LR Mate 200iC/5L**: the ROS-Industrial URDF's joints are ``J_urdf = s * theta`` with
  ``s = (+1, -1, +1, -1, +1, -1)`` (``models/fanuc_lrmate200ic/README.md``, checked against the
  URDF chain in ``tests/robots/test_models.py``), and FANUC measures J3 from the horizontal (the
  J2/J3 interaction: the ROS-Industrial FANUC driver converts ``URDF J3 = FANUC J3 + FANUC J2``), so
  ``FANUC = (U1, U2, U3 - U2, U4, U5, U6)`` with ``U = s * theta``. FANUC J3 = 0 therefore
  keeps the forearm horizontal whatever J2 is (tested).
* **LR Mate 100iB** (5 axes): the RoboDK-derived table of ``../shared/reference/robots.md``,
  whose joints are FANUC's J1, J2, J3 (from the horizontal), J5, J6:
  ``theta = (J1, J2, -J2 - J3, -J5, -J6)``.
* **5R welding robot**: no maker; its joint values are the seed's.

Each map is linear, ``maker = M @ theta`` (:attr:`RobotSpec.maker_matrix`), so velocities map
the same way.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.robots.spec import RobotSpec


def maker_matrix(spec: RobotSpec) -> NDArray[np.float64]:
    """``M`` with ``maker = M @ theta``, (n, n) (the identity for a robot without a maker's
    convention)."""
    if not spec.maker_matrix:
        return np.eye(spec.n_joints)
    return np.array(spec.maker_matrix, dtype=float)


def to_maker(spec: RobotSpec, theta: ArrayLike) -> NDArray[np.float64]:
    """The maker's joint values of seed joint values (rad; (n,) or (N, n))."""
    return np.asarray(theta, dtype=float) @ maker_matrix(spec).T


def from_maker(spec: RobotSpec, maker: ArrayLike) -> NDArray[np.float64]:
    """Seed joint values of the maker's joint values (rad; (n,) or (N, n))."""
    return np.asarray(maker, dtype=float) @ np.linalg.inv(maker_matrix(spec)).T


def maker_joint_names(spec: RobotSpec) -> tuple[str, ...]:
    """The maker's joint names (the seed's when it has no convention of its own)."""
    return spec.maker_joints or spec.joints


__all__ = ["from_maker", "maker_joint_names", "maker_matrix", "to_maker"]
