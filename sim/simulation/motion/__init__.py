"""The reference motion of a scenario: every phase planned and placed on one clock.

Joint phases are planned with their 4-3-4 or 5-4-6 polynomial; hold phases keep the pose;
Cartesian phases (``linear``, ``circular``) are interpolated with ADNIA (seed 003) at the
phase's sampling period, turned into joint via points by the robot's analytic inverse
kinematics (branch-continuous), and joined by the phase's polynomial, so that position,
velocity and acceleration stay continuous (as seed 001 phase II does).

Cartesian targets are given in the robot's frame 0 (the seeds' base frame); cell seams are
given in the world frame and converted with the cell's ``world_from_frame0``.

One concept per module, each importing only those listed before it:

* :mod:`~sim.simulation.motion.timeline`: the motion's data on one clock (:class:`Motion`,
  :class:`PhaseMotion`, :class:`HoldTrajectory`);
* :mod:`~sim.simulation.motion.programmed`: a Cartesian phase as programmed TP moves;
* :mod:`~sim.simulation.motion.context`: what Cartesian phases need from the cell
  (:class:`CartesianContext`);
* :mod:`~sim.simulation.motion.seams`: seams by name, seam targets, 5-axis torch postures;
* :mod:`~sim.simulation.motion.checks`: size, joint limits, continuity, end configuration;
* :mod:`~sim.simulation.motion.joint`: joint phases (pose targets, speed shares, blends);
* :mod:`~sim.simulation.motion.sampling`: a Cartesian move's samples and their inverse
  kinematics;
* :mod:`~sim.simulation.motion.cartesian`: one Cartesian phase (its ADNIA move, its plan);
* :mod:`~sim.simulation.motion.blending`: blended Cartesian phases and polyline seams;
* :mod:`~sim.simulation.motion.build`: :func:`build_motion`, every phase on one clock.

This package re-exports the public names callers import from ``sim.simulation.motion``.
"""

from sim.simulation.motion.blending import (
    CORNER_LIMIT_SHARE,
    MAX_BLEND_TURN,
    MAX_SAMPLE_STEP,
    MIN_BLEND,
    MIN_CORNER_SPEED_SHARE,
    POLYLINE_BLEND,
    ROLL_CANDIDATES_DEG,
    WRIST_CLEARANCE,
)
from sim.simulation.motion.build import build_motion
from sim.simulation.motion.cartesian import default_ramp
from sim.simulation.motion.checks import (
    CONFIG_TOLERANCE_DEG,
    MAX_STEPS,
    check_motion_limits,
    check_size,
    limit_violations,
)
from sim.simulation.motion.context import CartesianContext
from sim.simulation.motion.programmed import (
    CNT_SHARE,
    ZONE_POINT_CNT,
    ZONE_POINTS,
    ProgrammedMove,
)
from sim.simulation.motion.sampling import (
    BRANCH_JUMP_DEG,
    DEG_PER_CORNER_SAMPLE,
    JOINT_REFINEMENTS,
    MAX_JOINT_STEP_DEG,
    MAX_PHASE_SAMPLES,
    MAX_TURN_PER_SAMPLE_DEG,
    SAMPLES_PER_BLEND,
    SAMPLES_PER_WEAVE_CYCLE,
)
from sim.simulation.motion.timeline import HoldTrajectory, Motion, PhaseMotion

__all__ = [
    "BRANCH_JUMP_DEG",
    "CNT_SHARE",
    "CONFIG_TOLERANCE_DEG",
    "CORNER_LIMIT_SHARE",
    "DEG_PER_CORNER_SAMPLE",
    "JOINT_REFINEMENTS",
    "MAX_BLEND_TURN",
    "MAX_JOINT_STEP_DEG",
    "MAX_PHASE_SAMPLES",
    "MAX_SAMPLE_STEP",
    "MAX_STEPS",
    "MAX_TURN_PER_SAMPLE_DEG",
    "MIN_BLEND",
    "MIN_CORNER_SPEED_SHARE",
    "POLYLINE_BLEND",
    "ROLL_CANDIDATES_DEG",
    "SAMPLES_PER_BLEND",
    "SAMPLES_PER_WEAVE_CYCLE",
    "WRIST_CLEARANCE",
    "ZONE_POINTS",
    "ZONE_POINT_CNT",
    "CartesianContext",
    "HoldTrajectory",
    "Motion",
    "PhaseMotion",
    "ProgrammedMove",
    "build_motion",
    "check_motion_limits",
    "check_size",
    "default_ramp",
    "limit_violations",
]
