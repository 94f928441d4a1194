"""Kinematic model of one cellsim robot: vectorized forward kinematics, joint axes, limits.

A :class:`KinematicModel` joins the seeds' closed forms with what the MJCF adds:

* ``family == "5r"`` (LR Mate 100iB, the 5R welding robot): seed 000 Table 1 screw axes,
  product of exponentials; identical to seed 000 eq. (5) (:func:`closed_form.fk_5r`).
* ``family == "fanuc6"`` (LR Mate 200iC/5L): seed 004 Table 1 modified DH (Khalil-Dombre),
  tool frame E = frame 6 moved ``R6 + tool_length`` along z6; identical to seed 004 eq. (6)-(7).

Frames: frame 0 (the MJCF site ``frame0``) lies on the J1 axis at the height of J2. The tool
frame of the seeds ("seed tool frame") may differ from the MJCF site ``tcp`` by a constant
transform ``tcp_offset`` (``T_0,tcp = T_0,seed(q) @ tcp_offset``), read from the MJCF by
:func:`kinematic_model` when the robot's model file exists.

Units: metres, radians. Batched functions take joint arrays of shape (n,) or (N, n) and return
arrays with a matching leading dimension.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.errors import KinematicsError
from sim.core.rotations import invert_transform, make_transform
from sim.robots.registry import RobotSpec, get_robot


def rodrigues(axis: ArrayLike, angle: ArrayLike) -> NDArray[np.float64]:
    """Rotation by ``angle`` (rad, shape (...)) about unit ``axis`` (shape (3,)): (..., 3, 3)."""
    k = np.asarray(axis, dtype=float)
    a = np.asarray(angle, dtype=float)[..., None, None]
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(a) * K + (1.0 - np.cos(a)) * (K @ K)


def screw_table_5r(dims: dict[str, float]) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                                     NDArray[np.float64]]:
    """Seed 000 Table 1: joint axes ``k`` (5, 3), points ``p`` (5, 3) at q = 0, and tool point (3,).

    All in frame 0, metres. Row 6 of the table is the tool point ``(l1+l2+l3, 0, d1)``.
    """
    l1, d1, l2, l3 = dims["l1"], dims["d1"], dims["l2"], dims["l3"]
    k = np.array([[0, 0, 1], [0, 1, 0], [0, 1, 0], [0, 1, 0], [1, 0, 0]], dtype=float)
    p = np.array([[0, 0, 0], [l1, 0, 0], [l1, 0, d1], [l1 + l2, 0, d1], [l1 + l2, 0, d1]],
                 dtype=float)
    return k, p, np.array([l1 + l2 + l3, 0.0, d1])


def _as_batch(q: ArrayLike, n: int) -> tuple[NDArray[np.float64], bool]:
    Q = np.asarray(q, dtype=float)
    single = Q.ndim == 1
    Q = np.atleast_2d(Q)
    if Q.shape[-1] != n or Q.ndim != 2:
        raise KinematicsError(f"joint array must have shape ({n},) or (N, {n}), got {np.shape(q)}")
    return Q, single


@dataclass
class KinematicModel:
    """Closed-form kinematics of one robot (see the module docstring for the frames).

    Attributes:
        name: Robot registry name.
        family: ``"5r"`` or ``"fanuc6"``.
        dims: Kinematic dimensions, m (see :class:`sim.robots.RobotSpec`).
        tool_length: ``fanuc6`` only: tool length r beyond R6 along z6, m.
        tcp_offset: Constant transform seed tool frame -> tcp frame, (4, 4).
        lower, upper: Joint position limits, rad, shape (n,), or None when unknown.
        max_speed: Joint speed limits, rad/s, shape (n,); weights of the IK ranking.
    """

    name: str
    family: str
    dims: dict[str, float]
    tool_length: float = 0.0
    tcp_offset: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    lower: NDArray[np.float64] | None = None
    upper: NDArray[np.float64] | None = None
    max_speed: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        if self.family not in ("5r", "fanuc6"):
            raise KinematicsError(f"unknown kinematic family {self.family!r}; known: 5r, fanuc6")
        self.tcp_offset = np.asarray(self.tcp_offset, dtype=float)
        if self.max_speed is None:
            self.max_speed = np.ones(self.n_joints)
        self.max_speed = np.asarray(self.max_speed, dtype=float)
        if self.family == "5r":
            off = self.tcp_offset[:3, 3]
            if np.hypot(off[1], off[2]) > 1e-9:
                raise KinematicsError(
                    f"robot {self.name!r}: the tcp is {1e3 * np.hypot(off[1], off[2]):.3f} mm off "
                    "the J5 axis; the 5R analytic kinematics needs it on that axis")

    @property
    def n_joints(self) -> int:
        return 5 if self.family == "5r" else 6

    # ------------------------------------------------------------------ frames
    def joint_frames(self, q: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                                  NDArray[np.float64]]:
        """Joint axes, points on them, and the tcp transform, in frame 0.

        Args:
            q: Joint values, rad, shape (n,) or (N, n).

        Returns:
            ``(axes, points, T)``: unit joint axes (N, n, 3), a point on each axis (N, n, 3), m,
            and the tcp pose (N, 4, 4) (leading N dropped for a single configuration).
        """
        Q, single = _as_batch(q, self.n_joints)
        N = Q.shape[0]
        axes = np.empty((N, self.n_joints, 3))
        points = np.empty((N, self.n_joints, 3))
        if self.family == "5r":
            k, p, tool = screw_table_5r(self.dims)
            G = np.tile(np.eye(4), (N, 1, 1))
            for i in range(5):
                axes[:, i] = G[:, :3, :3] @ k[i]
                points[:, i] = (G[:, :3, :3] @ p[i]) + G[:, :3, 3]
                R = rodrigues(k[i], Q[:, i])
                E = make_transform(R, p[i] - (R @ p[i]))
                G = G @ E
            T = G @ make_transform(np.eye(3), tool)
        else:
            T = np.tile(np.eye(4), (N, 1, 1))
            d = self.dims
            h = np.pi / 2
            rows = [(0.0, 0.0, 0.0, 0.0), (h, d["d2"], h, 0.0), (0.0, d["d3"], 0.0, 0.0),
                    (h, d["d4"], 0.0, d["R4"]), (-h, 0.0, 0.0, 0.0), (h, 0.0, 0.0, 0.0)]
            for i, (alpha, dd, theta0, r) in enumerate(rows):
                T = T @ _mdh_batch(alpha, dd, theta0 + Q[:, i], r)
                axes[:, i] = T[:, :3, 2]
                points[:, i] = T[:, :3, 3]
            E = np.eye(4)
            E[2, 3] = self.dims["R6"] + self.tool_length
            T = T @ E
        T = T @ self.tcp_offset
        if single:
            return axes[0], points[0], T[0]
        return axes, points, T

    def fk(self, q: ArrayLike) -> NDArray[np.float64]:
        """Pose of the tcp in frame 0: (4, 4) or (N, 4, 4) for q of shape (n,) or (N, n)."""
        return self.joint_frames(q)[2]

    def fk_seed(self, q: ArrayLike) -> NDArray[np.float64]:
        """Pose of the seed's tool frame (without ``tcp_offset``), (4, 4) or (N, 4, 4)."""
        return self.fk(q) @ invert_transform(self.tcp_offset)

    # ------------------------------------------------------------------ limits
    def within_limits(self, q: ArrayLike, tol: float = 1e-9) -> NDArray[np.bool_] | bool:
        """Whether configuration(s) lie inside the joint ranges (True when ranges are unknown)."""
        Q = np.asarray(q, dtype=float)
        if self.lower is None or self.upper is None:
            return True if Q.ndim == 1 else np.ones(Q.shape[0], dtype=bool)
        ok = np.all((Q >= self.lower - tol) & (Q <= self.upper + tol), axis=-1)
        return bool(ok) if Q.ndim == 1 else ok


def _mdh_batch(alpha: float, d: float, theta: NDArray[np.float64], r: float) -> NDArray[np.float64]:
    """Vectorized :func:`sim.robots.closed_form.mdh_transform` over ``theta`` (N,): (N, 4, 4).
    """
    T = np.zeros(theta.shape + (4, 4))
    ca, sa = np.cos(alpha), np.sin(alpha)
    ct, st = np.cos(theta), np.sin(theta)
    T[..., 0, 0], T[..., 0, 1], T[..., 0, 3] = ct, -st, d
    T[..., 1, 0], T[..., 1, 1], T[..., 1, 2], T[..., 1, 3] = ca * st, ca * ct, -sa, -r * sa
    T[..., 2, 0], T[..., 2, 1], T[..., 2, 2], T[..., 2, 3] = sa * st, sa * ct, ca, r * ca
    T[..., 3, 3] = 1.0
    return T


def joint_limits(spec: RobotSpec) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """Joint position ranges (lower, upper), rad, each shape (n,), or None if not known yet.

    Read through ``sim.robots.joint_ranges`` when it exists, else from the robot's MJCF
    (joints ``j1..jN``, MuJoCo's compiled ``jnt_range``, always radians).
    """
    import sim.robots.registry as robots_module

    fn = getattr(robots_module, "joint_ranges", None)
    if fn is not None:
        try:
            rng = np.asarray(fn(spec.name), dtype=float)
            if rng.shape == (spec.n_joints, 2):
                return rng[:, 0].copy(), rng[:, 1].copy()
            if rng.shape == (2, spec.n_joints):
                return rng[0].copy(), rng[1].copy()
        except Exception:  # noqa: BLE001 - fall back to reading the MJCF
            pass
    if not spec.robot_path.is_file():
        return None
    model = _load_mjcf(str(spec.robot_path))
    import mujoco

    lo, hi = [], []
    for j in spec.joints:
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j)
        if jid < 0:
            raise KinematicsError(f"{spec.robot_path}: no joint named {j!r}")
        if not model.jnt_limited[jid]:
            lo.append(-np.inf)
            hi.append(np.inf)
        else:
            lo.append(model.jnt_range[jid, 0])
            hi.append(model.jnt_range[jid, 1])
    return np.array(lo), np.array(hi)


@lru_cache(maxsize=8)
def _load_mjcf(path: str):
    import mujoco

    return mujoco.MjModel.from_xml_path(path)


def closed_form_model(name: str, tool_length: float = 0.0) -> KinematicModel:
    """Model of robot ``name`` from the seeds' closed forms and ``sim.robots.registry`` dims only.

    The tool frame is the seed's (no MJCF tcp offset); joint limits are attached when known.
    """
    spec = get_robot(name)
    lim = joint_limits(spec)
    return KinematicModel(name=spec.name, family=spec.family, dims=dict(spec.dims),
                          tool_length=tool_length, lower=None if lim is None else lim[0],
                          upper=None if lim is None else lim[1],
                          max_speed=np.asarray(spec.max_speed))


def kinematic_model(name: str) -> KinematicModel:
    """Model of robot ``name`` whose tool frame is the MJCF site ``tcp`` (when the file exists).

    The constant ``tcp_offset`` is measured from the MJCF at q = 0 (site ``tcp`` in site
    ``frame0``); :mod:`sim.robots.mujoco_fk` checks it holds at every q (tests).
    Without a model file the seed's tool frame is used.
    """
    model = closed_form_model(name)
    spec = get_robot(name)
    if spec.robot_path.is_file():
        from sim.robots.mujoco_fk import MujocoKinematics

        mj = MujocoKinematics.for_robot(name)
        T_mj = mj.fk(np.zeros(model.n_joints))
        offset = invert_transform(model.fk(np.zeros(model.n_joints))) @ T_mj
        offset[np.abs(offset) < 1e-12] = 0.0
        try:
            model.tcp_offset = offset
            model.__post_init__()
        except KinematicsError as exc:
            warnings.warn(f"{exc}; using the seed's tool frame", stacklevel=2)
            model.tcp_offset = np.eye(4)
    return model
