"""Drive physics of one joint: the motor + gearbox :class:`Drive` (its torque-speed curve, the
motor torque a joint torque needs and back, the reflected rotor inertia) and the Coulomb friction
law the simulation and the inverse dynamics share.

The one place these formulas live: the simulation's drive limit, the model's actuator
``forcerange``/``armature``, the acceleration limits and sizing all call them. A scenario's
``[drives.jN]`` overrides are :mod:`sim.robots.drives`.

May import: numpy only (no other cellsim module).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

#: Joint speed (rad/s) from which a joint's Coulomb friction is its ``frictionloss`` in full;
#: below it the friction torque ramps linearly through zero: ``F * clip(qd / COULOMB_SPEED, -1,
#: 1)``, a smooth odd law that is ``F sign(qd)`` wherever ``|qd| >= 1e-3 rad/s``. The simulation
#: applies this law (:mod:`sim.cells.compose`: one friction actuator per joint) and the inverse
#: dynamics adds it, so both see the same friction.
COULOMB_SPEED = 1e-3


def coulomb(frictionloss: ArrayLike, qd: ArrayLike) -> NDArray[np.float64]:
    """Coulomb friction torque opposing nothing, ``F * clip(qd / COULOMB_SPEED, -1, 1)``, N m
    (the torque a drive spends on friction; shapes broadcast, ``F`` per joint)."""
    return np.asarray(frictionloss, dtype=float) * np.clip(
        np.asarray(qd, dtype=float) / COULOMB_SPEED, -1.0, 1.0)


#: Motor speed, as a fraction of its maximum, up to which the peak torque is available (the
#: generic peak curve of :meth:`Drive.peak_torque_at`).
PEAK_KNEE_FRACTION = 0.7
#: rad/s -> rpm.
RPM_PER_RAD_S = 60.0 / (2.0 * np.pi)


@dataclass(frozen=True)
class Drive:
    """Drive train of one joint (motor + gearbox), motor-side quantities.

    Attributes:
        gear_ratio: Motor turns per joint turn (> 0).
        efficiency: Gear efficiency, 0 < eta <= 1.
        rotor_inertia: Motor rotor inertia (plus input-side gear inertia), kg m^2, motor side.
        rated_torque: Motor continuous (rated) torque, N m, motor side.
        peak_torque: Motor peak torque, N m, motor side.
        max_speed_rpm: Motor maximum speed, rpm.
    """

    gear_ratio: float
    efficiency: float
    rotor_inertia: float
    rated_torque: float
    peak_torque: float
    max_speed_rpm: float

    def peak_torque_at(self, speed_rpm: ArrayLike,
                       knee_fraction: float = PEAK_KNEE_FRACTION) -> NDArray[np.float64]:
        """Peak (intermittent) motor torque available at ``|speed_rpm|``, N m, motor side.

        A generic S1/peak shape: the peak torque up to ``knee_fraction * max_speed_rpm``, then
        a straight voltage-limit slope down to the rated torque at ``max_speed_rpm``; zero above
        ``max_speed_rpm``.
        """
        n = np.abs(np.asarray(speed_rpm, dtype=float))
        n_max = float(self.max_speed_rpm)
        n_k = knee_fraction * n_max
        slope = (self.peak_torque - self.rated_torque) / max(n_max - n_k, 1e-300)
        out = np.where(n <= n_k, self.peak_torque, self.peak_torque - slope * (n - n_k))
        return np.where(n <= n_max, out, 0.0)

    def joint_peak_torque_at(self, joint_speed: ArrayLike) -> NDArray[np.float64]:
        """The drive's peak torque at the joint, ``peak_torque_at(motor speed) x ratio x
        efficiency``, N m, at joint speed(s) ``joint_speed`` (rad/s)."""
        rpm = np.asarray(joint_speed, dtype=float) * self.gear_ratio * RPM_PER_RAD_S
        return self.peak_torque_at(rpm) * self.gear_ratio * self.efficiency

    def motor_torque(self, tau_joint: ArrayLike, qd: ArrayLike, qdd: ArrayLike,
                     armature: float | ArrayLike = 0.0) -> NDArray[np.float64]:
        """The motor torque that gives joint torque ``tau_joint`` (N m, with the joint-side
        inertia ``armature * qdd`` in it) at joint speed ``qd`` and acceleration ``qdd``, N m,
        motor side: the gear's efficiency on the load torque only, in the direction power
        flows, and the rotor's inertia on the motor side::

            tau_load = tau_joint - armature qdd
            tau_m    = tau_load / (N eta) + J_r N qdd   where tau_load qd >= 0 (the motor drives)
            tau_m    = tau_load eta / N   + J_r N qdd   where the load drives back

        At standstill, ``|qd| <`` :data:`COULOMB_SPEED` (where the friction law ramps through
        zero), the motor drives (the larger torque): a servo holding a joint still sees a
        speed that only wobbles about zero, and the gear's direction of power flow must not
        flip with it from one sample to the next.

        The one formula of cellsim: the simulation's drive limit and sizing both use it."""
        tau_joint = np.asarray(tau_joint, dtype=float)
        qd = np.asarray(qd, dtype=float)
        qdd = np.asarray(qdd, dtype=float)
        n, eta = self.gear_ratio, self.efficiency
        load = tau_joint - np.asarray(armature, dtype=float) * qdd
        drives = (load * qd >= 0.0) | (np.abs(qd) < COULOMB_SPEED)
        through_gear = np.where(drives, load / (n * eta), load * eta / n)
        return through_gear + self.rotor_inertia * n * qdd

    def joint_torque_for(self, tau_motor: ArrayLike, qd: ArrayLike, qdd: ArrayLike,
                         armature: float | ArrayLike = 0.0) -> NDArray[np.float64]:
        """The joint torque at which :meth:`motor_torque` is ``tau_motor`` (its inverse at
        given ``qd`` and ``qdd``), N m."""
        tau_motor = np.asarray(tau_motor, dtype=float)
        qd = np.asarray(qd, dtype=float)
        qdd = np.asarray(qdd, dtype=float)
        n, eta = self.gear_ratio, self.efficiency
        through_gear = tau_motor - self.rotor_inertia * n * qdd
        # tau_load has the sign of through_gear; standstill as in motor_torque
        drives = (through_gear * qd >= 0.0) | (np.abs(qd) < COULOMB_SPEED)
        load = np.where(drives, through_gear * n * eta, through_gear * n / eta)
        return load + np.asarray(armature, dtype=float) * qdd

    @property
    def reflected_inertia(self) -> float:
        """Rotor inertia seen at the joint, ``rotor_inertia * gear_ratio**2``, kg m^2."""
        return self.rotor_inertia * self.gear_ratio**2


__all__ = ["COULOMB_SPEED", "PEAK_KNEE_FRACTION", "RPM_PER_RAD_S", "Drive", "coulomb"]
