"""The samples of a motion that collisions are checked on (:class:`MotionSamples`): a run's
recorded motion (:func:`samples_from_arrays`) or a scenario's reference motion
(:func:`samples_from_motion`), with each other robot's work on the same samples
(:func:`lane_samples`), and what each phase welds (:func:`phase_seams`, :func:`phase_weaves`);
which robots' phases a collision's sample is in (:func:`robots_named`, :func:`collision_phase`).

Owns the sampling; the check model and :class:`MotionSamples` are
:mod:`sim.simulation.collision_model`'s, the search :mod:`sim.simulation.collisions`'.
May import: the check model and the declarations of what may touch.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.simulation.allowed_contacts import weave_reach
from sim.simulation.collision_model import LEAD, LaneSamples, MotionSamples, mujoco_module
from sim.simulation.compile import BuiltCell


def samples_from_arrays(arrays: Any, motion: Any = None) -> MotionSamples:
    """The recorded motion of a run (``t``, ``qpos``, ``phase``, ``arc_on``, ``suction``; each
    other robot's ``<name>_arc_on``, its phases from ``motion``'s lanes when given:
    :func:`lane_samples`)."""
    t = np.asarray(arrays["t"], dtype=float)
    names = ([name for name, _ in motion.lanes] if motion is not None else
             [k.removesuffix("_arc_on") for k in arrays if k.endswith("_arc_on")])
    lanes = {}
    for name in names:
        lane = dict(motion.lanes)[name] if motion is not None else None
        arc = (np.asarray(arrays[f"{name}_arc_on"]).astype(bool) if f"{name}_arc_on" in arrays
               else None)
        lanes[name] = lane_samples(t, lane, arc)
    return MotionSamples(t, np.asarray(arrays["qpos"], dtype=float),
                         np.asarray(arrays["phase"]).astype(int),
                         np.asarray(arrays["arc_on"]).astype(bool),
                         np.asarray(arrays["suction"]).astype(bool), lanes)


def lane_samples(t: NDArray[np.float64], lane: Any = None,
                 arc_on: NDArray[np.bool_] | None = None) -> LaneSamples:
    """Another robot's work at times ``t``: its phases, their seams and weaves from its
    motion (``lane``, a :class:`sim.simulation.motion.Motion` of ``Motion.lanes``; None: one
    phase ``cycle`` following no seam), its arc from ``arc_on`` (None: from the motion, off
    without one)."""
    if lane is None:
        return LaneSamples(np.zeros(t.size, int),
                           np.zeros(t.size, bool) if arc_on is None else arc_on,
                           ["cycle"], [None], [0.0])
    return LaneSamples(np.asarray(lane.phase_index(t)).astype(int),
                       lane.tool_state(t, "arc") if arc_on is None else arc_on,
                       [pm.name for pm in lane.phases], phase_seams(lane), phase_weaves(lane))


def samples_from_motion(built: BuiltCell, motion: Any, dt: float) -> MotionSamples:
    """The reference motion sampled every ``dt`` s, parts where the cell puts them (its
    ``home`` keyframe): what ``cellsim check`` checks, without dynamics."""
    n = int(np.floor(motion.duration / dt + 1e-9)) + 1
    t = motion.t0 + dt * np.arange(n)
    if t[-1] < motion.t1 - 1e-12:
        t = np.append(t, motion.t1)
    mujoco = mujoco_module()
    model = built.model
    key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "home")
    base = model.key_qpos[key] if key >= 0 else model.qpos0
    qpos = np.tile(base, (t.size, 1))
    qpos[:, built.robot_qpos] = motion.at(t).q
    return MotionSamples(t, qpos, np.asarray(motion.phase_index(t)).astype(int),
                         motion.tool_state(t, "arc"), motion.tool_state(t, "suction"),
                         {name: lane_samples(t, lane) for name, lane in motion.lanes})


def phase_seams(motion: Any) -> list[str | None]:
    """The seam each phase of a motion follows (None where it follows none)."""
    return [None if pm.seam is None else pm.seam.name for pm in motion.phases]


def phase_weaves(motion: Any) -> list[float]:
    """Each phase's weave reach, m (:func:`weave_reach`; 0 where it does not weave)."""
    return [weave_reach(getattr(pm.phase, "weave", None)) for pm in motion.phases]


def robots_named(cm: Any, samples: MotionSamples, phase_names: Any, a: int, b: int,
                 i: int) -> dict[str, Any]:
    """``robots``: the robot of each geom of a pair (None for the cell or a part; ``cm``: the
    check model), and ``robot_phases``: each of them's phase at sample ``i``."""
    robots = [cm.geoms[a].robot, cm.geoms[b].robot]
    phases = {}
    for r in robots:
        if r == LEAD:
            phases[r] = phase_names[int(samples.phase[i])]
        elif r is not None:
            lane = samples.lane(r)
            phases[r] = lane.phase_names[int(lane.phase[i])]
    return {"robots": robots, "robot_phases": phases}


def collision_phase(entry: Any) -> str:
    """The phase a collision happens in, for a line or a table: its ``phase`` (the first
    robot's); in a cell with several robots, the phase of each robot it involves, another
    robot's named (``"park, r2: clear"``; ``"r2: clear"`` for another robot against the
    cell), as the clearance entries name them."""
    phases = entry.get("robot_phases")
    if not phases:
        return str(entry["phase"])
    return ", ".join(p if r == LEAD else f"{r}: {p}" for r, p in phases.items())
