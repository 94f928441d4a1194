"""``cellsim check``: a scenario's reference motion checked without dynamics, in seconds.

:func:`check_scenario` builds the cell, plans every phase (inverse kinematics for the poses and
the Cartesian paths) and checks the reference motion for:

* ``payload``: a turntable, positioner or track carrying more than its rating (a static
  load: the objects mounted on it, or the robot on a track, from the compiled cell);
* ``reach``: a target or a path out of reach, or reachable only outside the joint ranges (the
  planning stops there: nothing after it can be checked);
* ``limit``: a joint past its range, speed or acceleration limit (:func:`limit_violations`);
* ``singular``: a Cartesian phase passing near a singularity of the arm (the family's explicit
  factors of ``det J``, :func:`sim.robots.kinematics.jacobian.singularity_measures`, below
  :data:`SINGULAR_LIMITS`), where the joint speeds a straight or circular tool path asks for
  grow without bound (a joint move through ``theta5 = 0`` is harmless and not reported);
* ``collision``: a collision of the robot with itself, of the tool or the arm with the cell,
  of two robots of the cell with each other (their bodies named ``robot/...`` and
  ``r2/...``) (:mod:`sim.simulation.collisions`, every :data:`CHECK_DT_S`; parts stay where
  the cell puts them: held parts are checked by ``cellsim run``, which records where they go).

Each finding is one line naming the phase, the time and the value.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from sim.errors import LimitError, ReachError
from sim.scenario import Scenario
from sim.simulation.collisions import (
    check_motion,
    collision_phase,
    phase_seams,
    phase_weaves,
    samples_from_motion,
)
from sim.simulation.compile import BuiltCell, build
from sim.simulation.motion import Motion, build_motion, check_size, limit_violations

#: Sampling period of the reference motion, s (``cellsim run`` checks every recorded sample).
CHECK_DT_S = 0.001
#: A pass is singular where a factor of det J falls below its limit: ``wrist`` |sin theta5|
#: (5 deg), ``elbow`` (dimensionless, about 1 deg of the elbow), ``shoulder`` (the wrist
#: centre's distance from the J1 axis, m).
SINGULAR_LIMITS = {"wrist": float(np.sin(np.radians(5.0))), "elbow": 0.02, "shoulder": 0.02}


@dataclass
class Finding:
    """One thing the reference motion does that a real cell cannot."""

    kind: str
    line: str


@dataclass
class CheckResult:
    """What :func:`check_scenario` found, and how long each step took (s)."""

    findings: list[Finding] = field(default_factory=list)
    timings: dict[str, float] = field(default_factory=dict)
    collisions: list[dict] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return not self.findings


def check_scenario(scenario: Scenario, *, dt: float = CHECK_DT_S) -> CheckResult:
    """Check a scenario's reference motion (module docstring)."""
    res = CheckResult()
    t0 = time.perf_counter()
    built = build(scenario)
    res.timings["build_s"] = time.perf_counter() - t0
    for pm in built.cell.mechanisms:  # a static load over the rating needs no motion
        carried = float(built.model.body(pm.mount_body).subtreemass[0])
        if pm.spec.payload_kg > 0 and carried > pm.spec.payload_kg * (1 + 1e-9):
            res.findings.append(Finding("payload", (
                f"{pm.spec.kind} {pm.name!r} ({pm.spec.name}) carries {carried:.4g} kg, over "
                f"its rated {pm.spec.payload_kg:g} kg")))
    t0 = time.perf_counter()
    try:
        motion = build_motion(scenario, built.context)
    except LimitError as exc:  # a later phase could not start where this one left a joint
        res.findings += [Finding("limit", line) for line in exc.lines]
        return res
    except ReachError as exc:
        res.findings.append(Finding("reach", str(exc)))
        return res
    res.timings["plan_s"] = time.perf_counter() - t0
    # bounded as `cellsim run` is (its step count and shortest phase), before sampling it
    check_size(scenario, motion, float(built.model.opt.timestep))
    res.findings += [Finding("limit", line) for line in limit_violations(scenario, motion)]
    t0 = time.perf_counter()
    res.findings += _singular_passes(built, motion, dt=0.01)
    report = check_motion(built, samples_from_motion(built, motion, dt),
                          [pm.name for pm in motion.phases], phase_seams(motion),
                          with_clearance=False, weaves=phase_weaves(motion))
    res.timings["check_s"] = time.perf_counter() - t0
    res.collisions = report.collisions
    for c in report.collisions:
        res.findings.append(Finding("collision", (
            f"{collision_phase(c)}: {c['kind']} collision {c['bodies'][0]} / {c['bodies'][1]} from "
            f"{c['t0']:.3f} to {c['t1']:.3f} s, {c['depth_mm']:.1f} mm deep at "
            f"{c['t_worst']:.3f} s ({c['geoms'][0]}, {c['geoms'][1]})")))
    return res


def _singular_passes(built: BuiltCell, motion: Motion, dt: float) -> list[Finding]:
    from sim.core.intervals import true_runs
    from sim.robots.kinematics.jacobian import singularity_measures

    t = np.arange(motion.t0, motion.t1 + 1e-12, dt)
    kin = built.context.kinematics
    m = singularity_measures(kin, motion.at(t).q[:, :kin.n_joints])  # the arm's joints
    phase = motion.phase_index(t)
    cartesian = np.array([pm.cartesian is not None for pm in motion.phases])[phase]
    out = []
    for factor, limit in SINGULAR_LIMITS.items():
        if factor not in m:
            continue
        v = np.abs(m[factor])
        for i0, stop in true_runs((v < limit) & cartesian):
            i = i0 + int(np.argmin(v[i0:stop]))
            out.append(Finding("singular", (
                f"{motion.phases[int(phase[i0])].name}: {factor} singularity from {t[i0]:.3f} to "
                f"{t[stop - 1]:.3f} s, |{factor}| down to {v[i]:.4g} (limit {limit:.4g}) at "
                f"{t[i]:.3f} s")))
    return out
