"""Joint limits read from a compiled MuJoCo model: the actuators' force range per joint and
the joints' armature (the drive inertia the simulated torques already hold).

Owns what sizing takes from the model; the friction actuators cellsim adds per joint are left
out (they are friction, not drive).
May import: :mod:`sim.errors` and :mod:`sim.cells` (the friction actuators' prefix, when
called).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.errors import UnknownNameError


def forcerange_from_model(model: Any, joint_names: Sequence[str]) -> NDArray[np.float64]:
    """Joint torque limits from a compiled ``mujoco.MjModel``.

    The limit of a joint is the sum over the actuators driving it (transmission type joint) of
    ``gear * forcerange`` (when ``forcelimited``), intersected with the joint's own
    ``actuatorfrcrange`` (when ``actuatorfrclimited``). Unlimited sides are +-inf.

    Args:
        model: The compiled model.
        joint_names: Joint names, in the order wanted.

    Returns:
        ``(lo, hi)`` per joint, N m, shape (n_joints, 2).

    Raises:
        UnknownNameError: A joint name is not in the model.
    """
    return joint_forcerange(model, _joint_ids(model, joint_names))


def _joint_ids(model: Any, joint_names: Sequence[str]) -> list[int]:
    import mujoco

    valid = [model.joint(i).name for i in range(model.njnt)]
    ids = []
    for name in joint_names:
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        if jid < 0:
            raise UnknownNameError("joint", name, valid)
        ids.append(int(jid))
    return ids


def joint_forcerange(model: Any, joint_ids: Sequence[int]) -> NDArray[np.float64]:
    """:func:`forcerange_from_model` for joints given by id (resolved once by the caller). The
    joints' Coulomb friction actuators (cellsim's ``friction_<joint>``) are friction, not drive:
    they are left out."""
    import mujoco  # compiled-model helpers load MuJoCo (and the cell composer) when called

    from sim.cells.compose import FRICTION_PREFIX

    out = np.empty((len(joint_ids), 2))
    for k, jid in enumerate(joint_ids):
        lo, hi, driven = 0.0, 0.0, False
        for a in range(model.nu):
            if model.actuator_trntype[a] != mujoco.mjtTrn.mjTRN_JOINT or model.actuator_trnid[a, 0] != jid:
                continue
            if model.actuator(a).name.rsplit("/", 1)[-1].startswith(FRICTION_PREFIX):
                continue
            driven = True
            if model.actuator_forcelimited[a]:
                g = float(model.actuator_gear[a, 0])
                ends = sorted((g * model.actuator_forcerange[a, 0], g * model.actuator_forcerange[a, 1]))
                lo, hi = lo + ends[0], hi + ends[1]
            else:
                lo, hi = -np.inf, np.inf
        if not driven:
            lo, hi = -np.inf, np.inf
        if model.jnt_actfrclimited[jid]:
            lo = max(lo, float(model.jnt_actfrcrange[jid, 0]))
            hi = min(hi, float(model.jnt_actfrcrange[jid, 1]))
        out[k] = lo, hi
    return out


def armature_from_model(model: Any, joint_names: Sequence[str]) -> NDArray[np.float64]:
    """``dof_armature`` of each (hinge/slide) joint, kg m^2, shape (n_joints,)."""
    return joint_armature(model, _joint_ids(model, joint_names))


def joint_armature(model: Any, joint_ids: Sequence[int]) -> NDArray[np.float64]:
    """:func:`armature_from_model` for joints given by id (resolved once by the caller)."""
    return np.array([float(model.dof_armature[model.jnt_dofadr[j]]) for j in joint_ids])
