"""The run's verdict: the checks a physically possible run passes, and pass or fail.

A simulation that tracks badly, saturates a drive, drives a joint past its speed or
acceleration limit, or oversteps a sizing limit is a result to report, not a pass. Each check
is per joint:

* ``tracking``: the largest joint tracking error, deg, against the scenario's
  ``simulation.tracking_tolerance_deg``;
* ``saturation``: the worst excess of the servo's demand over the drive's limit, N m, against
  0 (any saturation fails; the intervals are in ``summary["saturation"]``);
* ``speed``: the largest simulated joint speed, deg/s, against the robot's speed limit;
* ``acceleration``: the largest reference joint acceleration, deg/s^2, against the robot's
  acceleration limit (derived from its drive train, :mod:`sim.robots.accel_limits`);
* the sizing checks (:mod:`sim.analysis.sizing`: joint torque, motor RMS and peak torque,
  motor speed, torque-speed envelope), the joint speed excepted (it is ``speed`` above).

``summary.json`` holds ``"checks"`` (each ``name``, ``joint``, ``value``, ``limit``, ``unit``,
``pass``) and ``"verdict"``: ``"pass"`` when every check passed, else ``"fail"``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.analysis.sizing import SizingResult
from sim.robots.registry import RobotSpec


@dataclass(frozen=True)
class RunCheck:
    """One check of one joint: ``value`` against ``limit`` (both in ``unit``)."""

    name: str
    joint: str
    value: float
    limit: float
    unit: str
    passed: bool

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "joint": self.joint, "value": self.value,
                "limit": self.limit, "unit": self.unit, "pass": self.passed}


def run_checks(arrays: Mapping[str, NDArray[Any]], summary: Mapping[str, Any], spec: RobotSpec,
               tracking_tolerance_deg: float, sizing: SizingResult | None = None
               ) -> list[RunCheck]:
    """Every check of a run (module docstring), joint by joint."""
    checks: list[RunCheck] = []
    track = np.degrees(np.max(np.abs(np.asarray(arrays["q"]) - arrays["q_ref"]), axis=0))
    speed = np.degrees(np.max(np.abs(np.asarray(arrays["qd"])), axis=0))
    accel = np.degrees(np.max(np.abs(np.asarray(arrays["qdd_ref"])), axis=0))
    excess = {j: 0.0 for j in spec.joints}
    for s in summary.get("saturation", ()):
        excess[s["joint"]] = max(excess[s["joint"]], float(s["worst_excess_nm"]))
    for k, joint in enumerate(spec.joints):
        checks.append(RunCheck("tracking", joint, float(track[k]), float(tracking_tolerance_deg),
                               "deg", bool(track[k] <= tracking_tolerance_deg)))
        checks.append(RunCheck("saturation", joint, excess[joint], 0.0, "N m",
                               excess[joint] <= 0.0))
        vmax = float(np.degrees(spec.max_speed[k]))
        checks.append(RunCheck("speed", joint, float(speed[k]), vmax, "deg/s",
                               bool(speed[k] <= vmax * (1 + 1e-9))))
        if spec.max_accel:
            amax = float(np.degrees(spec.max_accel[k]))
            checks.append(RunCheck("acceleration", joint, float(accel[k]), amax, "deg/s^2",
                                   bool(accel[k] <= amax * (1 + 1e-9))))
    if sizing is not None:
        for j in sizing.joints:
            for c in j.checks:
                if c.key == "joint_speed" or not np.isfinite(c.limit):
                    continue
                checks.append(RunCheck(c.key, j.joint, float(c.used), float(c.limit), c.unit,
                                       bool(c.passed)))
    return checks


def verdict(checks: Sequence[RunCheck]) -> str:
    """``"pass"`` when every check passed, else ``"fail"``."""
    return "pass" if all(c.passed for c in checks) else "fail"
