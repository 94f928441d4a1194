"""Joint acceleration limits derived from the drive train (no maker publishes them).

For joint ``i`` the drive's peak torque at the joint is ``T_i = peak motor torque x ratio x
efficiency`` (the actuator's ``forcerange``). Over configurations spread through the joint
ranges, with the rated payload as a point mass at the tcp, the acceleration the drive can give
the joint alone from rest against gravity and Coulomb friction ``F_i`` is
``(T_i - F_i - |g_i(q)|) / M_ii(q)``, with ``M_ii`` the joint's inertia (links beyond it,
payload and the reflected rotor inertia, the armature). The limit is the smallest of these.
It is a per-joint figure: velocity terms (zero at rest, where a move starts and ends) and the
coupling between joints accelerating together are left out, which the simulation's
saturation check and the sizing report cover.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from sim.errors import HoldError
from sim.robots.spec import RobotSpec, joint_ranges

#: Configurations sampled per robot (uniform in the joint ranges, fixed seed).
SAMPLES = 4000


def derive_accel_limits(spec: RobotSpec, payload_kg: float, samples: int = SAMPLES,
                        seed: int = 0) -> NDArray[np.float64]:
    """The acceleration limit of every joint (module docstring), rad/s^2, shape (n,).

    Raises:
        HoldError: A joint's drive cannot hold the arm against gravity somewhere in the
            ranges (no positive limit exists); ``needs`` has the torque each such joint holds.
    """
    import mujoco
    from dm_control import mjcf

    root = mjcf.from_path(str(spec.robot_path))
    tcp = root.find("site", "tcp")
    if payload_kg > 0.0:
        body = tcp.parent.add("body", name="rated_payload", pos=tcp.pos)
        body.add("inertial", pos=[0.0, 0.0, 0.0], mass=payload_kg, diaginertia=[1e-6] * 3)
    model = mujoco.MjModel.from_xml_string(root.to_xml_string(), root.get_assets())
    data = mujoco.MjData(model)
    jids = [model.joint(j).id for j in spec.joints]
    qadr = np.array([model.jnt_qposadr[j] for j in jids])
    dadr = np.array([model.jnt_dofadr[j] for j in jids])
    peak = np.array([d.peak_torque * d.gear_ratio * d.efficiency for d in spec.drives])
    friction = model.dof_frictionloss[dadr]
    rng = joint_ranges(spec)
    Q = np.random.default_rng(seed).uniform(rng[:, 0], rng[:, 1], size=(samples, len(jids)))
    M = np.zeros((model.nv, model.nv))
    worst = np.full(len(jids), np.inf)
    need = np.zeros(len(jids))  # the largest gravity + friction torque held, N m
    need_q = np.zeros((len(jids), len(jids)))
    for q in Q:
        data.qpos[:] = model.qpos0
        data.qpos[qadr] = q
        data.qvel[:] = 0.0
        mujoco.mj_forward(model, data)
        mujoco.mj_fullM(model, data, M)
        g = data.qfrc_bias[dadr]
        a = (peak - friction - np.abs(g)) / M[dadr, dadr]
        worst = np.minimum(worst, a)
        more = friction + np.abs(g) > need
        need = np.where(more, friction + np.abs(g), need)
        need_q[more] = q
    if np.any(worst <= 0.0):
        parts = []
        for k, j in enumerate(spec.joints):
            if worst[k] > 0.0:
                continue
            d = spec.drives[k]
            parts.append(
                f"{j} needs up to {need[k]:.4g} N m to hold it (gravity and friction, at "
                f"[{', '.join(f'{v:.0f}' for v in np.degrees(need_q[k]))}] deg) where its drive "
                f"gives {peak[k]:.4g} N m ({d.peak_torque:g} N m peak x {d.gear_ratio:g} x "
                f"{d.efficiency:g}): a motor peak of at least "
                f"{need[k] / (d.gear_ratio * d.efficiency):.4g} N m at this ratio and efficiency")
        raise HoldError(f"robot {spec.name!r} with {payload_kg:g} kg: the drives cannot "
                        "hold the arm against gravity everywhere in range: " + "; ".join(parts),
                        {j: float(need[k]) for k, j in enumerate(spec.joints)
                         if worst[k] <= 0.0})
    return worst
