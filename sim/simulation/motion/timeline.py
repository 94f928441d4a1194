"""The reference motion's data on one clock: the planned phases and the tool actions.

Owns :class:`Motion` (every phase on one clock, the reference joint state at any time, the
tool's on/off state), :class:`PhaseMotion` (one planned phase: its window, its joint
trajectory, and for Cartesian phases its tool trajectory, seam, programmed moves and corner
zones) and :class:`HoldTrajectory` (a hold phase's constant pose). Planning them is
:mod:`sim.simulation.motion.build`'s.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planners.base import JointState, sample_times
from sim.scenario import Phase


class HoldTrajectory:
    """Constant joint position over ``[start, start + duration]`` (zero derivatives)."""

    planner = "hold"

    def __init__(self, start: float, duration: float, q: ArrayLike) -> None:
        self.start = float(start)
        self.end = float(start + duration)
        self.q = np.asarray(q, dtype=float).copy()
        self.knots = np.array([self.start, self.end])

    @property
    def duration(self) -> float:
        return self.end - self.start

    @property
    def n_joints(self) -> int:
        return self.q.size

    def at(self, t: ArrayLike) -> JointState:
        t = np.asarray(t, dtype=float)
        shape = t.shape + (self.q.size,)
        z = np.zeros(shape)
        return JointState(np.broadcast_to(self.q, shape).copy(), z, z.copy(), z.copy())

    def sample(self, dt: float) -> tuple[NDArray[np.float64], JointState]:
        t = sample_times(self.start, self.end, dt)
        return t, self.at(t)


@dataclass
class PhaseMotion:
    """One planned phase on the scenario clock.

    Attributes:
        phase: The scenario phase.
        t0, t1: Start and end time, s.
        trajectory: Joint trajectory (``at(t)`` on the scenario clock).
        cartesian: For Cartesian phases, the ADNIA tool trajectory in frame 0 (its own clock
            starts at 0, i.e. at ``t0``); ``None`` otherwise.
        seam: The cell seam the phase follows, or ``None``.
        knot_times: Knot times of the joint polynomial, s.
        programmed: Cartesian phases: the moves as programmed, one per move (a polyline seam
            has one per segment): :class:`ProgrammedMove`.
        corner_zones: Phases along a seam: the stretches of the seam, as arc-length intervals
            ``(s0, s1)`` in m from the seam's start, where the torch turns from one leg's
            posture to the next (a polyline's blended corners); outside them the torch holds
            the seam's work and travel angles. Empty for a line, an arc or a circle.
    """

    phase: Phase
    t0: float
    t1: float
    trajectory: Any
    cartesian: Any = None
    seam: Any = None
    knot_times: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    programmed: list = field(default_factory=list)
    corner_zones: list[tuple[float, float]] = field(default_factory=list)

    @property
    def name(self) -> str:
        return self.phase.name

    @property
    def kind(self) -> str:
        return self.phase.kind


@dataclass
class Motion:
    """All phases of a scenario on one clock, plus the tool actions.

    Attributes:
        phases: Planned phases in order; ``phases[k].t1 == phases[k+1].t0``.
        actions: ``(time, action)`` pairs sorted by time (``arc_on``, ``suction_off``, ...).
        n_joints: Number of driven joints (the robot's and the cell's axes; with other robots,
            theirs too: see :attr:`lanes`).
        lanes: The cell's other robots' motions on the same clock, ``(name, motion)`` each, in
            the cell's order: their joints follow the first robot's (and the axes') in
            :meth:`at`; each holds its last pose once it ends. :attr:`phases` and
            :attr:`actions` are the first robot's.
    """

    phases: list[PhaseMotion]
    actions: list[tuple[float, str]]
    n_joints: int
    lanes: list[tuple[str, Motion]] = field(default_factory=list)

    @property
    def t0(self) -> float:
        return self.phases[0].t0

    @property
    def t1(self) -> float:
        """The cycle's end: the last of the robots' motions ends."""
        return max([self.phases[-1].t1] + [m.t1 for _, m in self.lanes])

    @property
    def duration(self) -> float:
        return self.t1 - self.t0

    @property
    def n_lead(self) -> int:
        """The first robot's and the axes' joints (the columns :attr:`phases` give)."""
        return self.n_joints - sum(m.n_joints for _, m in self.lanes)

    @property
    def boundaries(self) -> NDArray[np.float64]:
        return np.array([p.t0 for p in self.phases] + [self.phases[-1].t1])

    def phase_index(self, t: ArrayLike) -> NDArray[np.int64]:
        """Index of the phase each time belongs to (a boundary belongs to the later phase;
        past the first robot's last phase: that phase)."""
        idx = np.searchsorted(self.boundaries, np.asarray(t, dtype=float), side="right") - 1
        return np.clip(idx, 0, len(self.phases) - 1)

    def at(self, t: ArrayLike) -> JointState:
        """Reference joint state at time(s) ``t``, s; times past a robot's end hold its last
        pose."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        nl = self.n_lead
        out = [np.zeros((t.size, self.n_joints)) for _ in range(4)]
        idx = self.phase_index(t)
        for k, pm in enumerate(self.phases):
            sel = idx == k
            if not np.any(sel):
                continue
            ts = np.clip(t[sel], pm.t0, pm.t1)
            st = pm.trajectory.at(ts)
            for arr, val in zip(out, (st.q, st.qd, st.qdd, st.qddd)):
                arr[sel, :nl] = val
        past = t > self.phases[-1].t1
        for arr in out[1:]:
            arr[past, :nl] = 0.0
        col = nl
        for _, lane in self.lanes:
            st = lane.at(t)
            for arr, val in zip(out, (st.q, st.qd, st.qdd, st.qddd)):
                arr[:, col:col + lane.n_joints] = val
            col += lane.n_joints
        return JointState(*out)

    def tool_state(self, t: ArrayLike, tool: str) -> NDArray[np.bool_]:
        """Whether the arc (``tool="arc"``) or suction (``"suction"``) is on at each time."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        on = np.zeros(t.shape, dtype=bool)
        for time, action in self.actions:
            if action == f"{tool}_on":
                on[t >= time - 1e-12] = True
            elif action == f"{tool}_off":
                on[t >= time - 1e-12] = False
        return on

    def knot_times(self) -> NDArray[np.float64]:
        """All knot times of all phases (the other robots' too), sorted, s."""
        ts = np.concatenate([pm.knot_times for pm in self.phases]
                            + [m.knot_times() for _, m in self.lanes] or [np.zeros(0)])
        return np.unique(ts)
