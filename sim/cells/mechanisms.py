"""Mechanisms placed in a cell (turntables, positioners, tracks): :class:`PlacedMechanism` and
their MJCF (:func:`add_mechanism`).

A placed mechanism is a :class:`~sim.robots.mechanisms.MechanismSpec` at a pose in the world
with its home axis values. Its axes are driven joints of the cell like the robot's, named
``<mechanism>_<axis>`` (``positioner_tilt``): joint, position actuator and body share that
name, the friction actuator is ``friction_<mechanism>_<axis>``. The chain is built directly in
the world body (:func:`add_mechanism`):

* body ``<mechanism>`` at the placement pose, holding the base's solids (static);
* one body per axis (``<mechanism>_<axis>`` at the axis origin, a hinge or slide joint along
  the axis, the link's inertial: mass, centre of mass and principal inertia, and its solids);
* body ``<mechanism>_mount`` at the mount pose in the last link (no inertial of its own): the
  workpieces mounted on the mechanism (a cell file's ``on``) are its geoms, and MuJoCo derives
  their mass and inertia from their shapes (a given ``mass_kg``, else solid steel); a robot on
  a track is attached there (site ``<mechanism>_mount``).

Gains: each axis's position servo gets ``kp = I w^2``, ``kv = 2 I w`` (critically damped at
:data:`SERVO_HZ`), ``I`` the axis's inertia at home with everything it carries (read from the
compiled cell by :func:`tune_gains`). The feed-forward carries the torque; the gains only hold
the axis on its reference.

Contacts: a mechanism's solids and what is mounted on it are cell geometry: in the simulation
they touch parts only (:data:`CONTACT_MOVING`); the collision checks measure them against the
robot and its tool.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from sim.cells.toolspec import CONTACT_CUP
from sim.robots.mechanisms import MechanismSpec, Shape
from sim.robots.mechanisms.kinematics import mount_pose

if TYPE_CHECKING:
    from dm_control import mjcf

#: Natural frequency of a mechanism axis's position servo, Hz (critically damped).
SERVO_HZ = 8.0
#: Contact bits of a moving solid (a mechanism's, or an object it carries): it touches parts
#: only (its type bit is in the parts' affinity and in no fixture's: with the fixture bits it
#: would touch the floor and the fixtures, and hold the axis).
CONTACT_MOVING = {"contype": CONTACT_CUP, "conaffinity": 0}
#: Name suffix of a mechanism's mount body and site.
MOUNT = "mount"


@dataclass(frozen=True, eq=False)
class PlacedMechanism:
    """A mechanism in a cell.

    Attributes:
        name: The cell's name for it (the prefix of its axes' names).
        spec: The mechanism.
        pose: Its base in the world, (4, 4).
        home: Its axis values at the cell's home, rad or m, (n_axes,).
        carries: What is mounted on it: object names, and ``"robot"`` for a robot's base.
    """

    name: str
    spec: MechanismSpec
    pose: NDArray[np.float64]
    home: NDArray[np.float64]
    carries: tuple[str, ...] = ()

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The cell's names of its axes (``<mechanism>_<axis>``), in chain order."""
        return tuple(f"{self.name}_{a.name}" for a in self.spec.axes)

    @property
    def names(self) -> frozenset[str]:
        """Every name its model takes in the cell (bodies, joints, geoms, the mount)."""
        spec = self.spec
        geoms = [f"{self.name}_{s.name or f'base{k}'}" for k, s in enumerate(spec.base_shapes)]
        geoms += [f"{self.name}_{s.name or f'{a.name}{k}'}" for a in spec.axes
                  for k, s in enumerate(a.link.shapes)]
        return frozenset({self.name, self.mount_body, *self.joint_names, *geoms})

    @property
    def mount_body(self) -> str:
        return f"{self.name}_{MOUNT}"

    def mount_in_world(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """The mount's pose in the world at axis values ``q`` (..., n_axes) -> (..., 4, 4)."""
        return self.pose @ mount_pose(self.spec, np.asarray(q, dtype=float))

    def displacement(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """The rigid motion of what the mechanism carries from home to ``q``, in the world:
        ``mount(q) mount(home)^-1`` (..., 4, 4)."""
        home = self.mount_in_world(self.home)
        return self.mount_in_world(q) @ np.linalg.inv(home)


def quat_from_matrix(R: NDArray[np.float64]) -> NDArray[np.float64]:
    """Unit quaternion (w, x, y, z) of a rotation matrix (3, 3)."""
    import mujoco

    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.asarray(R, dtype=float).reshape(9))
    return q


def _add_shape(body: mjcf.Element, shape: Shape, name: str) -> None:
    size = np.asarray(shape.size, dtype=float)
    kw: dict[str, Any] = {}
    if not np.allclose(shape.rot, np.eye(3)):
        kw["quat"] = quat_from_matrix(shape.rot)
    body.add("geom", name=name, type=shape.kind,
             size=size if shape.kind == "box" else size[:2], pos=shape.pos, rgba=shape.rgba,
             **CONTACT_MOVING, mass=0.0, **kw)


def add_mechanism(world: mjcf.RootElement, pm: PlacedMechanism) -> mjcf.Element:
    """Build a placed mechanism in the world (module docstring); returns its mount body."""
    spec = pm.spec
    base = world.worldbody.add("body", name=pm.name, pos=pm.pose[:3, 3],
                               quat=quat_from_matrix(pm.pose[:3, :3]))
    for k, shape in enumerate(spec.base_shapes):
        _add_shape(base, shape, f"{pm.name}_{shape.name or f'base{k}'}")
    parent = base
    for axis, name in zip(spec.axes, pm.joint_names, strict=True):
        body = parent.add("body", name=name, pos=axis.pos)
        link = axis.link
        body.add("inertial", pos=link.com, mass=link.mass, diaginertia=link.inertia)
        lo, hi = axis.range
        body.add("joint", name=name, type="hinge" if axis.kind == "revolute" else "slide",
                 axis=axis.axis, range=[lo, hi], limited=True,
                 armature=axis.drive.reflected_inertia, damping=axis.damping)
        for k, shape in enumerate(link.shapes):
            _add_shape(body, shape, f"{pm.name}_{shape.name or f'{axis.name}{k}'}")
        world.actuator.add("position", name=name, joint=name, kp=1.0, kv=0.0,
                           ctrllimited=False, forcelimited=False)
        if axis.friction > 0.0:
            from sim.robots.drive import COULOMB_SPEED

            F = float(axis.friction)
            world.actuator.add("general", name=f"friction_{name}", joint=name,
                               gaintype="fixed", gainprm=[0.0], biastype="affine",
                               biasprm=[0.0, 0.0, -F / COULOMB_SPEED], ctrllimited=False,
                               forcelimited=True, forcerange=[-F, F])
        parent = body
    M = spec.mount
    mount = parent.add("body", name=pm.mount_body, pos=M[:3, 3], quat=quat_from_matrix(M[:3, :3]))
    mount.add("site", name=pm.mount_body, size=[0.01], group=4)
    return mount


def tune_gains(world: mjcf.RootElement, mechanisms: tuple[PlacedMechanism, ...],
               model: Any, home_qpos: Any) -> None:
    """Set each mechanism axis's servo gains from its inertia at home (module docstring).

    Args:
        world: The composed world.
        mechanisms: Its mechanisms.
        model: The world compiled once (``mujoco.MjModel``).
        home_qpos: Its ``qpos`` at home (the home keyframe's), (nq,).
    """
    import mujoco

    data = mujoco.MjData(model)
    data.qpos[:] = home_qpos
    mujoco.mj_forward(model, data)
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, M)
    w = 2.0 * np.pi * SERVO_HZ
    for pm in mechanisms:
        for name in pm.joint_names:
            dof = model.jnt_dofadr[model.joint(name).id]
            inertia = float(M[dof, dof])
            act = world.find("actuator", name)
            act.kp = inertia * w * w
            act.kv = 2.0 * inertia * w


__all__ = ["MOUNT", "SERVO_HZ", "PlacedMechanism", "add_mechanism", "tune_gains"]
