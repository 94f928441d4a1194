"""pinocchio's inverse dynamics on a run's own model: the second engine that the joint torques
cellsim records (``tau_id``) are checked against (issue 26's audit: pinocchio on each run's
model).

pinocchio's MJCF parser does not derive a body's inertia from its geoms (MuJoCo does: the tools
are built so), wants keyframes sized for its own robot-only model, and starts its model at the
robot's base (the placement of the fixed bodies above it, e.g. the ceiling mount's half turn, is
dropped): :func:`pinocchio_model` writes the model out with explicit inertials and no keyframes
and gives pinocchio the gravity in the base frame.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from sim.robots.registry import coulomb


def pinocchio_model(xml_path: Path, tmp_path: Path) -> tuple[Any, Any]:
    """``(pinocchio, model)`` of the MJCF at ``xml_path`` (written again under ``tmp_path``)."""
    import pinocchio as pin

    spec = mujoco.MjSpec.from_file(str(xml_path))
    compiled = spec.compile()
    for body in spec.bodies[1:]:
        i = compiled.body(body.name).id
        body.explicitinertial = True
        body.mass = compiled.body_mass[i]
        body.ipos = compiled.body_ipos[i]
        body.iquat = compiled.body_iquat[i]
        body.inertia = compiled.body_inertia[i]
    text = re.sub(r"<keyframe>.*?</keyframe>", "", spec.to_xml(), flags=re.DOTALL)
    path = tmp_path / "model_for_pinocchio.xml"
    path.write_text(text)
    model = pin.buildModelFromMJCF(str(path))
    data = mujoco.MjData(compiled)
    mujoco.mj_kinematics(compiled, data)
    R_base = data.xmat[compiled.body("robot/base").id].reshape(3, 3)
    model.gravity.linear = R_base.T @ compiled.opt.gravity
    return pin, model


def tau_id_error(xml_path: Path, joints: list[str], arrays: dict[str, Any], tmp_path: Path,
                 samples: int = 3000) -> float:
    """The largest difference between the recorded ``tau_id`` and pinocchio's RNEA on the
    reference (+ armature qdd when pinocchio leaves it out, + damping qd + Coulomb friction),
    over about ``samples`` samples and the joints moving faster than 1e-2 rad/s there, as a
    fraction of each joint's peak ``tau_id``."""
    pin, model = pinocchio_model(xml_path, tmp_path)
    mj = mujoco.MjModel.from_xml_path(str(xml_path))
    names = [f"robot/{j}" for j in joints]
    assert [model.names[i] for i in range(1, model.njoints)] == names
    dof = np.array([mj.jnt_dofadr[mj.joint(j).id] for j in names])
    data = model.createData()
    armature = mj.dof_armature[dof]
    with_armature = np.allclose(np.asarray(model.armature), armature)
    friction = np.array([mj.actuator_forcerange[mj.actuator(f"robot/friction_{j}").id, 1]
                         for j in joints])
    tau_id = np.asarray(arrays["tau_id"])
    t = np.asarray(arrays["t"])
    step = max(1, t.size // samples)
    peak = np.abs(tau_id).max(axis=0)
    worst = 0.0
    for k in range(0, t.size, step):
        q, qd, qdd = (np.asarray(arrays[key][k]) for key in ("q_ref", "qd_ref", "qdd_ref"))
        tau = np.array(pin.rnea(model, data, q, qd, qdd))
        if not with_armature:
            tau = tau + armature * qdd
        tau += mj.dof_damping[dof] * qd + coulomb(friction, qd)
        moving = np.abs(qd) > 1e-2
        if moving.any():
            worst = max(worst, float((np.abs(tau - tau_id[k])[moving] / peak[moving]).max()))
    return worst
