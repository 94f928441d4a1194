"""The drives' motor torque limit inside the simulation: every rollout chunk checked with the
motor torque sizing computes, against the peak torque-speed curve at the motor's own speed, and
a chunk in which a motor went past its peak run again a step at a time with that drive held at
exactly its peak.

Owns the per-step solve for the held joint torques (:class:`MotorLimit`); the simulation loop
that calls it is :func:`sim.simulation.simulate.simulate`.
May import: :mod:`sim.errors`, :mod:`sim.robots.registry` (the :class:`Drive`) and the compiled
cell.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.errors import SimulationError
from sim.robots.registry import Drive
from sim.simulation.compile import BuiltCell

#: Tolerance of the motors' peak torque, in peak torques (the per-step solve stops inside
#: half of it).
MOTOR_TOL = 1e-9
#: Iterations of the per-step solve for the held joint torques (each one a step).
MOTOR_ITERATIONS = 12
#: Largest motor torque error left after them that is accepted, in peak torques.
MOTOR_SETTLE_TOL = 1e-4


class MotorLimit:
    """The drives' motor torque limit, computed as sizing computes it
    (:meth:`sim.robots.registry.Drive.motor_torque`: the gear's efficiency on the load torque,
    the rotor's inertia on the motor side) against the peak torque-speed curve at the motor's
    own speed.

    The actuator's ``forcerange`` (``peak x ratio x efficiency``) is where the motor gives its
    peak while the load does not accelerate; with the rotor's inertia outside the gear's
    losses the motor's torque at that joint torque depends on the step's acceleration. So
    every chunk is checked after it ran (:meth:`exceeded`), and a chunk in which a motor went
    past its peak runs again a step at a time (:meth:`exact_steps`): a drive past it is held
    at the joint torque where its motor gives exactly its peak at that step's acceleration
    (an actuator whose force range is that one value: MuJoCo applies it exactly, with no
    implicit velocity term), found by a fixed-point iteration on the step.
    """

    def __init__(self, built: BuiltCell, drives: Sequence[Drive], qvel_slice: slice) -> None:
        model = built.model
        self.built = built
        self.drives = tuple(drives)
        self.dof = np.asarray(built.robot_dof)
        self.act = np.asarray(built.robot_act)
        self.armature = model.dof_armature[self.dof].copy()
        self.kv = -model.actuator_biasprm[self.act, 2]
        self.h = float(model.opt.timestep)
        self.qvel = qvel_slice
        # an actuator without a force limit has no drive limit to hold (a test's stiff servo)
        self.limited = model.actuator_forcelimited[self.act].astype(bool)
        nj = len(self.drives)
        self.tau_cols = [built.sensor_slices[f"tau{i}"] for i in range(nj)]

    def _torques(self, qd0: NDArray[np.float64], qd1: NDArray[np.float64],
                 tau_act: NDArray[np.float64], lim: NDArray[np.float64]
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Per step (rows): the joint torque applied (as recorded), the acceleration, and how
        far the motor torque is past the motor's peak at its speed, in peak torques (> 0 past
        it)."""
        qdd = (qd1 - qd0) / self.h
        clamped = np.abs(tau_act) >= lim * (1 - 1e-9)
        tau = np.where(clamped, tau_act, tau_act - self.h * self.kv * qdd)
        ratio = np.empty_like(tau)
        for j, d in enumerate(self.drives):
            tm = d.motor_torque(tau[:, j], qd0[:, j], qdd[:, j], self.armature[j])
            avail = d.peak_torque_at(qd0[:, j] * d.gear_ratio * 60.0 / (2.0 * np.pi))
            ratio[:, j] = (np.abs(tm) - avail) / d.peak_torque if self.limited[j] else -np.inf
        return tau, qdd, ratio

    def _rows(self, state: NDArray[np.float64], st: NDArray[np.float64],
              sd: NDArray[np.float64]):
        qd = np.vstack([state[self.qvel][self.dof], st[:, self.qvel][:, self.dof]])
        tau_act = np.column_stack([sd[:, c] for c in self.tau_cols])
        return qd[:-1], qd[1:], tau_act

    def exceeded(self, state: NDArray[np.float64], st: NDArray[np.float64],
                 sd: NDArray[np.float64]) -> bool:
        """A motor went past its peak at its own speed somewhere in the chunk."""
        qd0, qd1, tau_act = self._rows(state, st, sd)
        lim = self.built.model.actuator_forcerange[self.act, 1]
        _, _, ratio = self._torques(qd0, qd1, tau_act, lim)
        return bool(np.any(ratio > MOTOR_TOL))

    def exact_steps(self, scratch: Any, state: NDArray[np.float64],
                    controls: NDArray[np.float64], warmstart: NDArray[np.float64],
                    lim: NDArray[np.float64], control_spec: Any
                    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """The chunk a step at a time (see the class): its states and sensor rows, and per
        step and joint the joint torque a drive was held at (NaN where none was)."""
        from mujoco import rollout

        model = self.built.model
        rng = model.actuator_forcerange
        n, nj = len(controls), len(self.drives)
        st_out = np.empty((n, state.size))
        sd_out = np.empty((n, model.nsensordata))
        held = np.full((n, nj), np.nan)
        s, ws = state, warmstart
        for i in range(n):
            rng[self.act] = np.column_stack([-lim, lim])
            fixed = np.zeros(nj, dtype=bool)
            force = np.zeros(nj)
            target = np.zeros(nj)
            prev = np.full((nj, 2), np.nan)  # the last pass's (held torque, motor torque)
            for _ in range(MOTOR_ITERATIONS):
                st, sd = rollout.rollout(model, scratch, s, controls[i:i + 1][None],
                                         control_spec=control_spec, initial_warmstart=ws)
                st, sd = st[0], sd[0]
                qd0, qd1, tau_act = self._rows(s, st, sd)
                cur = np.where(fixed, np.abs(force), lim)
                tau, qdd, ratio = self._torques(qd0, qd1, tau_act, cur)
                tm = np.array([float(d.motor_torque(tau[0, j], qd0[0, j], qdd[0, j],
                                                    self.armature[j]))
                               for j, d in enumerate(self.drives)])
                avail = np.array([float(d.peak_torque_at(qd0[0, j] * d.gear_ratio * 60.0
                                                         / (2.0 * np.pi)))
                                  for j, d in enumerate(self.drives)])
                peak = np.array([d.peak_torque for d in self.drives])
                new = ~fixed & (ratio[0] > MOTOR_TOL)
                target[new] = np.sign(tm[new]) * avail[new]
                off = fixed & (np.abs(tm - target) > 0.5 * MOTOR_TOL * peak)
                if not new.any() and not off.any():
                    break
                # hold each drive past its peak at the joint torque where its motor gives its
                # peak: the motor torque grows with the held torque (piecewise linearly: the
                # step's acceleration follows it), so a secant step from the last two passes,
                # the first one from the formula's inverse at this pass's acceleration
                for j in np.nonzero(new | off)[0]:
                    d = self.drives[j]
                    if new[j]:
                        f = float(d.joint_torque_for(target[j], qd0[0, j], qdd[0, j],
                                                     self.armature[j]))
                    else:
                        f0, t0 = prev[j]
                        slope = (tm[j] - t0) / (force[j] - f0) if np.isfinite(f0) and \
                            force[j] != f0 else 0.0
                        if not slope > 0:  # the gear's slope where the load is driven
                            slope = 1.0 / (d.gear_ratio * d.efficiency)
                        f = force[j] + (target[j] - tm[j]) / slope
                    prev[j] = (force[j], tm[j]) if fixed[j] else (np.nan, np.nan)
                    force[j] = f
                    rng[self.act[j]] = (f, f)
                fixed |= new
            else:
                # a motor past its top speed (an arm falling under a load its drives cannot
                # hold) has 0 N m to give: the secant approaches it slowly; a residual within
                # MOTOR_SETTLE_TOL is far inside what sizing resolves, and the step is kept
                left = np.abs(tm - target) / peak
                if new.any() or np.any(left[off] > MOTOR_SETTLE_TOL):
                    raise SimulationError(
                        f"the drives' motor torque limit did not settle in {MOTOR_ITERATIONS} "
                        f"passes at t = {s[0]:.4f} s (joints "
                        f"{', '.join(str(j + 1) for j in np.nonzero(new | off)[0])}, "
                        f"{np.max(left[new | off]):.2g} of the peak torque off); try a "
                        "smaller simulation.timestep_s")
            held[i, fixed] = np.abs(force[fixed])
            st_out[i], sd_out[i] = st[-1], sd[-1]
            s, ws = st[-1], scratch.qacc_warmstart.copy()
        rng[self.act] = np.column_stack([-lim, lim])
        return st_out, sd_out, held
