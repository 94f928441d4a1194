"""Forward kinematics and Jacobians through MuJoCo, for cross-checking the closed forms.

The pose reported is that of site ``tcp`` expressed in site ``frame0`` (both defined in each
robot's MJCF), with the joints ``j1..jN`` set to ``q`` and every other joint at its ``qpos0``.
The Jacobian comes from ``mj_jacSite`` (world frame) rotated into ``frame0``.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.errors import KinematicsError
from sim.robots.spec import RobotSpec


class MujocoKinematics:
    """tcp pose and Jacobian of an MJCF chain, in the frame of a reference site.

    Args:
        model: Compiled MuJoCo model.
        joints: Names of the driven joints, in order.
        tcp_site: Name of the tool site.
        base_site: Name of the reference site (``None``: the world frame).
    """

    def __init__(self, model: mujoco.MjModel, joints: tuple[str, ...], tcp_site: str = "tcp",
                 base_site: str | None = "frame0") -> None:
        self.model = model
        self.data = mujoco.MjData(model)
        self.qpos_adr = []
        self.dof_adr = []
        for j in joints:
            jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j)
            if jid < 0:
                raise KinematicsError(f"MJCF model has no joint named {j!r}")
            self.qpos_adr.append(int(model.jnt_qposadr[jid]))
            self.dof_adr.append(int(model.jnt_dofadr[jid]))
        self.tcp = self._site(tcp_site)
        self.base = None if base_site is None else self._site(base_site)

    def _site(self, name: str) -> int:
        sid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, name)
        if sid < 0:
            raise KinematicsError(f"MJCF model has no site named {name!r}")
        return int(sid)

    @classmethod
    def for_robot(cls, spec: RobotSpec) -> MujocoKinematics:
        """Load a robot's MJCF (``RobotSpec.robot_path``)."""
        return cls.from_file(spec.robot_path, spec.joints)

    @classmethod
    def from_file(cls, path: str | Path, joints: tuple[str, ...], **kw) -> MujocoKinematics:
        if not Path(path).is_file():
            raise KinematicsError(f"model file {path} not found")
        return cls(mujoco.MjModel.from_xml_path(str(path)), joints, **kw)

    @classmethod
    def from_xml_string(cls, xml: str, joints: tuple[str, ...], **kw) -> MujocoKinematics:
        return cls(mujoco.MjModel.from_xml_string(xml), joints, **kw)

    def _set(self, q: NDArray[np.float64]) -> None:
        self.data.qpos[:] = self.model.qpos0
        self.data.qpos[self.qpos_adr] = q
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_comPos(self.model, self.data)

    def _base_pose(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        if self.base is None:
            return np.eye(3), np.zeros(3)
        return (self.data.site_xmat[self.base].reshape(3, 3).copy(),
                self.data.site_xpos[self.base].copy())

    def fk(self, q: ArrayLike) -> NDArray[np.float64]:
        """tcp pose in the base site frame: (4, 4) or (N, 4, 4) for q (n,) or (N, n)."""
        Q = np.asarray(q, dtype=float)
        single = Q.ndim == 1
        Q = np.atleast_2d(Q)
        out = np.zeros((Q.shape[0], 4, 4))
        for k, qk in enumerate(Q):
            self._set(qk)
            Rb, pb = self._base_pose()
            out[k, :3, :3] = Rb.T @ self.data.site_xmat[self.tcp].reshape(3, 3)
            out[k, :3, 3] = Rb.T @ (self.data.site_xpos[self.tcp] - pb)
            out[k, 3, 3] = 1.0
        return out[0] if single else out

    def jacobian(self, q: ArrayLike) -> NDArray[np.float64]:
        """Geometric Jacobian of the tcp (``mj_jacSite``), rows [v; omega] in the base frame.

        Returns:
            Shape (6, n) or (N, 6, n).
        """
        Q = np.asarray(q, dtype=float)
        single = Q.ndim == 1
        Q = np.atleast_2d(Q)
        nv = self.model.nv
        jacp = np.zeros((3, nv))
        jacr = np.zeros((3, nv))
        out = np.zeros((Q.shape[0], 6, len(self.dof_adr)))
        for k, qk in enumerate(Q):
            self._set(qk)
            mujoco.mj_jacSite(self.model, self.data, jacp, jacr, self.tcp)
            Rb, _ = self._base_pose()
            out[k, :3] = Rb.T @ jacp[:, self.dof_adr]
            out[k, 3:] = Rb.T @ jacr[:, self.dof_adr]
        return out[0] if single else out
