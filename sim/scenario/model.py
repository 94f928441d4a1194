"""A validated scenario in SI units: its phases, tool actions, robot, cell and tool objects."""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from sim.errors import ScenarioError, UsageError
from sim.robots.registry import Drive, RobotSpec
from sim.scenario.schema import (
    MAX_PAYLOAD_KG,
    ExpectSpec,
    SimulationSpec,
    SizingSpec,
    VideoSpec,
)

if TYPE_CHECKING:
    from sim.cells import CellSpec
    from sim.cells.seam import Seam
    from sim.cells.tools import ToolSpec


@dataclass(frozen=True)
class JointPhase:
    """A validated joint-space phase in SI units.

    Attributes:
        index: Position of the phase in the scenario (0-based).
        name: Phase name.
        planner: ``"434"`` or ``"546"``.
        times: Absolute knot times, s, shape (m+1,); ``None`` when the phase was given by
            segment durations (it then starts whenever the previous phase ends).
        durations: Segment durations, s, shape (m,).
        q: Knot values, rad, shape (m+1, n_joints); with ``durations_s`` the first row is
            ``NaN`` until the previous phase's end fills it in (see :meth:`with_start`).
        boundary: Planner keywords (``v0``, ``vf``, ``a0``, ``af``, ``j0``, ``jf``) with arrays
            of shape (n_joints,) in rad/s^k; absent keys default to 0 in the planner.
        blend: Blend radius into the next joint phase, rad (0: stop at the last knot).
        blend_fraction: Or the blend radius as a share of half the shorter chord at the
            corner (a TP program's CNT / 100).
        speed_pct: Timed by speed (a TP program's ``J ... x%``): the duration makes the peak
            speed of the joint that takes longest ``speed_pct`` times its limit (the knot times
            are then set when the phase is planned).
        axes: The external axes' values at the phase's end, rad or m, by axis name
            (``positioner_tilt``); the others hold. The knots are the robot's (``q``); the axes
            move with them on the phase's one time law (:mod:`sim.simulation.motion.axes`).
        downhand: With a seam pose target: the positioner carrying the seam ends where the
            seam's start is welded downhand.
        origin: Where a TP program's move is written (``prog.ls: line 12 (J P[3])``); empty
            for a scenario's own phase (:func:`phase_label`).
    """

    index: int
    name: str
    planner: str
    times: NDArray[np.float64] | None
    durations: NDArray[np.float64]
    q: NDArray[np.float64]
    boundary: dict[str, NDArray[np.float64]] = field(default_factory=dict)
    kind: str = "joint"
    target: "PoseTarget | None" = None
    blend: float = 0.0
    blend_fraction: float = 0.0
    speed_pct: float | None = None
    axes: dict[str, float] = field(default_factory=dict)
    downhand: bool = False
    origin: str = ""

    @property
    def t0(self) -> float:
        if self.times is None:
            raise UsageError(f"phase {self.name} has relative times")
        return float(self.times[0])

    @property
    def t1(self) -> float:
        if self.times is None:
            raise UsageError(f"phase {self.name} has relative times")
        return float(self.times[-1])

    @property
    def starts_from_previous(self) -> bool:
        return self.times is None

    def with_start(self, t0: float, q0: NDArray[np.float64]) -> "JointPhase":
        """This phase placed at ``t0`` and, if it starts from the previous phase, from ``q0``."""
        import dataclasses

        q = self.q.copy()
        if self.starts_from_previous:
            q[0] = q0
        times = (self.times if self.times is not None
                 else t0 + np.concatenate([[0.0], np.cumsum(self.durations)]))
        placed = dataclasses.replace(self, times=times, q=q)
        return placed if self.target is not None else placed.with_end(q[-1])

    def with_end(self, q_end: NDArray[np.float64]) -> "JointPhase":
        """This phase ending at ``q_end`` (its pose target solved); an automatic via point
        (NaN row) becomes the joint-space midpoint of start and end."""
        import dataclasses

        q = self.q.copy()
        q[-1] = q_end
        for r in range(1, q.shape[0] - 1):
            if np.isnan(q[r]).all():
                q[r] = 0.5 * (q[0] + q_end)
        return dataclasses.replace(self, q=q)


@dataclass(frozen=True)
class PoseTarget:
    """Where a joint phase ends, in Cartesian terms (solved by inverse kinematics).

    Attributes:
        position: tcp position in ``frame``, m, (3,), or ``None`` with ``seam``.
        rotation: tcp orientation in ``frame``, (3, 3); ``None`` keeps the previous one.
        seam: A cell seam whose start (and torch posture) is the target.
        seam_end: ``"start"`` or ``"end"``: which end of ``seam`` (``retract_mm`` gives the
            end).
        offset: Distance back from that end of the seam along its torch axis, m
            (``approach_mm`` / ``retract_mm``).
        frame: Frame of ``position`` and ``rotation``: ``frame0`` (the robot's), ``world`` or a
            cell object's name.
        config: A TP program's configuration ``(flip, up, front, turn4, turn5, turn6)``: the
            IK branch to take (:mod:`sim.scenario.program`); None: the nearest.
        flange: The pose is the flange's (a TP program's UT 0), not the tcp's.
    """

    position: NDArray[np.float64] | None = None
    rotation: NDArray[np.float64] | None = None
    seam: str | None = None
    frame: str = "frame0"
    config: tuple | None = None
    flange: bool = False
    seam_end: str = "start"
    offset: float = 0.0


@dataclass(frozen=True)
class CartesianPhase:
    """A validated Cartesian phase (``linear`` or ``circular``), lengths in metres, points,
    axis and Euler angles in ``frame`` (``frame0``, ``world`` or a cell object).

    Attributes:
        kind: ``"linear"`` or ``"circular"``.
        seam: Name of a cell seam to follow, or ``None``.
        to: End point in frame0, m, shape (3,), or ``None`` when ``seam`` gives it.
        via: Circular only: a point on the arc, frame0, m.
        center, axis, sweep: Circular only: centre (m), axis (unit), sweep (rad).
        speed: Travel speed, m/s. sample_period: ADNIA sampling period, s. ramp: ramp time, s.
        orientation: ``keep``, ``follow``, ``seam`` or ``euler``; ``euler``: R = Rz Ry Rx (rad).
        blend: Corner zone radius into the next Cartesian phase, m (0: stop at the end).
        weave: A :class:`planners.weave.Weave` across the path, or ``None``.
        blend_fraction: Or the blend as a share of 0.45 x the shorter of the two moves (a TP
            program's CNT / 100).
        move_time: The move's time, s (a TP program's ``sec`` speed): the speed is then its
            length over that time.
        flange: ``to``/``via``/``euler_zyx`` are flange poses (a TP program's UT 0).
        via_euler_zyx: The via point's own orientation (a TP program's circular move; used to
            turn a flange via point into the tcp's), rad.
        target: A linear move's end given by a seam (``to_seam``, with ``approach_mm`` or
            ``retract_mm``): a :class:`PoseTarget` with ``seam``; ``to`` is then None.
        config: A TP program's move: the FANUC configuration its position names (flip,
            up, front, turn numbers; :func:`sim.scenario.program.config_of`), which the move's
            end must have: a linear or circular move cannot change it.
        standoff: The pass's own stand-off along ``seam``, m (its ``ctwd_mm`` less the torch's
            nominal stick-out, :mod:`sim.cells.seam`); None: the seam's
            (:meth:`seam_as_welded`).
        downhand: Along ``seam``: the positioner carrying it turns it so that its local normal
            points up at the tool point (coordinated motion, :mod:`sim.simulation.motion.axes`).
        follow: Along ``seam``: the track (a mechanism's name) that carries the robot with
            the tool point.
        axes: External axes' values at the move's end, rad or m, by axis name (a TP program's
            coordinated move, ``COORD``): they move in proportion to the path travelled, and
            the path and the orientation are relative to ``frame`` (carried by its mechanism).
        time_scale: How many times faster than written the phase runs
            (:meth:`Scenario.scaled`): the default ramps' least duration is divided by it, as
            the written times are.
        origin: As :attr:`JointPhase.origin`.
    """

    index: int
    name: str
    kind: str
    planner: str
    speed: float
    sample_period: float
    ramp: float | None
    orientation: str
    seam: str | None = None
    to: NDArray[np.float64] | None = None
    via: NDArray[np.float64] | None = None
    center: NDArray[np.float64] | None = None
    axis: NDArray[np.float64] | None = None
    sweep: float | None = None
    euler_zyx: NDArray[np.float64] | None = None
    frame: str = "frame0"
    blend: float = 0.0
    weave: Any = None
    blend_fraction: float = 0.0
    move_time: float | None = None
    flange: bool = False
    via_euler_zyx: NDArray[np.float64] | None = None
    target: "PoseTarget | None" = None
    standoff: float | None = None
    config: tuple | None = None
    downhand: bool = False
    follow: str | None = None
    axes: dict[str, float] = field(default_factory=dict)
    time_scale: float = 1.0
    origin: str = ""

    def seam_as_welded(self, seam: Seam) -> Seam:
        """The seam this phase welds: ``seam`` (the cell's seam named ``self.seam``) with the
        phase's own stand-off where it gives ``ctwd_mm``, else as it is. A polyline's
        :meth:`~sim.cells.seam.Seam.segments` carry that stand-off too."""
        if self.standoff is None or self.standoff == seam.standoff_m:
            return seam
        import dataclasses

        return dataclasses.replace(seam, standoff_m=self.standoff)


@dataclass(frozen=True)
class HoldPhase:
    """The robot holds the pose where the previous phase ended, for ``duration`` s
    (``origin``: as :attr:`JointPhase.origin`, a TP program's WAIT)."""

    index: int
    name: str
    duration: float
    kind: str = "hold"
    origin: str = ""


@dataclass(frozen=True)
class Action:
    """A tool action; ``time`` absolute (s) or ``phase``/``at`` resolved when the run is timed."""

    action: str
    time: float | None
    phase: str | None
    at: str


Phase = JointPhase | CartesianPhase | HoldPhase


def phase_label(where: str, phase: Any) -> str:
    """How a message names a phase of the scenario file ``where``: ``where: phases[2]
    (weld)``; a TP program's move by its program line, ``where: prog.ls: line 12 (C P[5]
    P[6]) (line012_C)``."""
    origin = getattr(phase, "origin", "")
    if origin:
        return f"{where}: {origin} ({phase.name})"
    return f"{where}: phases[{phase.index}] ({phase.name})"


@dataclass(frozen=True)
class RobotWork:
    """The work of one of a cell's other robots (``[robots.<name>]``).

    Attributes:
        name: The robot's name in the cell.
        robot: Its registry entry.
        tool: Its tool, or None.
        phases: Its phases in order (empty: it stays at its home all cycle).
        actions: Its tool actions in file order.
        program_warnings: As :attr:`Scenario.program_warnings`, for its TP program.
    """

    name: str
    robot: RobotSpec
    tool: ToolSpec | None = None
    phases: tuple[Phase, ...] = ()
    actions: tuple[Action, ...] = ()
    program_warnings: tuple[str, ...] = ()


@dataclass(frozen=True)
class Scenario:
    """A validated scenario (SI units).

    Attributes:
        name: Scenario name.
        description: Free text.
        robot: The robot's registry entry.
        phases: Phases in order.
        source: File the scenario came from.
        text: The file's text (copied into run folders, hashed into manifests).
        cell: The cell the robot works in (``None``: the robot's bare scene).
        tool: The tool it carries, resolved (the scenario's, else the cell's default), or None.
        mount, payload_kg: Robot mount (``"floor"``/``"ceiling"``) and lumped payload, kg.
        simulation, video: Settings tables (pydantic models, defaults filled in).
        drives: Drive-train overrides by joint name: {field: value}, SI units.
        sizing: Actuator-selection settings (``[sizing]``; ``catalog`` relative to ``source``).
        actions: Tool actions in file order.
        program_warnings: For a scenario running a TP program: what the program holds that is
            not simulated, one line each with its line number.
        expect: What a run is expected to give (``[expect]``: verdict, failed checks,
            ``cellsim check`` findings, reason); it changes no verdict.
        partners: The work of the cell's other robots, in the cell's order (every one of them:
            one the file gives no work stays at home).
    """

    name: str
    description: str
    robot: RobotSpec
    phases: tuple[Phase, ...]
    source: Path
    text: str
    cell: CellSpec | None = None
    tool: ToolSpec | None = None
    mount: str = "floor"
    payload_kg: float = 0.0
    simulation: SimulationSpec = SimulationSpec()
    video: VideoSpec = VideoSpec()
    drives: dict[str, dict[str, float]] = field(default_factory=dict)
    actions: tuple[Action, ...] = ()
    sizing: SizingSpec = SizingSpec()
    program_warnings: tuple[str, ...] = ()
    expect: ExpectSpec = ExpectSpec()
    partners: tuple[RobotWork, ...] = ()

    @property
    def sha256(self) -> str:
        return hashlib.sha256(self.text.encode()).hexdigest()

    @property
    def drive_train(self) -> tuple[Drive, ...]:
        """The drive each joint really has: the robot's (its defaults, or its robot folder's
        ``[[drives]]``) with this scenario's ``[drives.jN]`` applied; ``()`` for a robot
        without drive data. The compiled model's ``forcerange`` and ``armature``, the
        simulation's torque-speed limit and sizing all take it from here
        (:func:`sim.robots.drives.apply_overrides`).

        Raises:
            ScenarioError: A bad override value (one line naming ``drives.<joint>.<key>``).
        """
        from sim.robots.drives import apply_overrides

        system = self.system
        try:
            return apply_overrides(system.drives, self.drives, system.joints)
        except ScenarioError as exc:  # a bad value: the file's name first
            raise ScenarioError(f"{self.source.name}: {exc}") from None

    @property
    def system(self) -> RobotSpec:
        """The cell's driven joints: the robot's, then its mechanisms' axes
        (:meth:`RobotSpec.with_axes`: names, limits, drives); the robot itself in a cell
        without mechanisms."""
        mechanisms = () if self.cell is None else self.cell.mechanisms
        return self.robot.with_axes([(n, a) for pm in mechanisms
                                     for n, a in zip(pm.joint_names, pm.spec.axes, strict=True)]
                                    ).with_partners([(w.name, w.robot) for w in self.partners])

    def partner_scenario(self, work: RobotWork) -> Scenario:
        """One of the other robots' work as a scenario of its own (no cell: its motion is
        planned with its own :class:`~sim.simulation.motion.CartesianContext`)."""
        import dataclasses

        return dataclasses.replace(
            self, name=f"{self.name}.{work.name}", robot=work.robot, tool=work.tool,
            phases=work.phases, actions=work.actions, program_warnings=work.program_warnings,
            cell=None, drives={}, payload_kg=0.0, partners=())

    def scaled(self, speed_scale: float = 1.0, payload_kg: float | None = None) -> "Scenario":
        """This scenario run ``speed_scale`` times faster, optionally with another payload.

        Knot times, segment durations, hold durations and action times are divided by
        ``speed_scale``; Cartesian speeds, weave frequencies and a TP program's joint-move
        speed percentages are multiplied by it (sampling
        periods, ramps, the default ramps' least duration, weave dwells and a TP program's move
        times divided), and boundary velocities, accelerations and jerks scale by its 1st, 2nd
        and 3rd power, so the joint paths are the same, traversed faster: the cycle time is
        divided by ``speed_scale`` (but where a blended corner is slowed to keep the joints
        within their limits). Without gravity, friction and damping, joint torques then scale
        exactly as ``speed_scale**2``.

        Raises:
            ScenarioError: ``speed_scale`` not positive, or ``payload_kg`` outside 0 ..
                :data:`~sim.scenario.schema.MAX_PAYLOAD_KG`.
        """
        import dataclasses

        from sim.core.arguments import number_argument

        s = number_argument(speed_scale, "speed_scale", error=ScenarioError)
        if not (np.isfinite(s) and s > 0):
            raise ScenarioError(f"speed_scale: must be a positive number, got {speed_scale!r}")
        if payload_kg is not None:
            payload_kg = number_argument(payload_kg, "payload_kg", error=ScenarioError)
            if not (np.isfinite(payload_kg) and 0 <= payload_kg <= MAX_PAYLOAD_KG):
                raise ScenarioError(f"payload_kg: must be 0 to {MAX_PAYLOAD_KG:g} kg, got "
                                    f"{payload_kg!r}")
        phases, actions = _scaled(self.phases, self.actions, s)
        partners = []
        for w in self.partners:  # the other robots' work runs faster too
            ph, ac = _scaled(w.phases, w.actions, s)
            partners.append(dataclasses.replace(w, phases=ph, actions=ac))
        return dataclasses.replace(
            self, phases=phases, actions=actions, partners=tuple(partners),
            payload_kg=self.payload_kg if payload_kg is None else float(payload_kg))

    @property
    def fixed_timing(self) -> bool:
        """True when every phase is a joint phase with absolute times (no timing to resolve)."""
        return all(isinstance(p, JointPhase) and p.times is not None for p in self.phases)

    @property
    def duration(self) -> float:
        """Total duration, s (joint phases with absolute times only; see ``sim.simulation.motion``)."""
        first, last = self.phases[0], self.phases[-1]
        if not (isinstance(first, JointPhase) and isinstance(last, JointPhase)
                and first.times is not None and last.times is not None):
            raise UsageError("duration depends on Cartesian planning; plan the motion first")
        return last.t1 - first.t0


def _scaled(phases: tuple[Phase, ...], actions: tuple[Action, ...], s: float
            ) -> tuple[tuple[Phase, ...], tuple[Action, ...]]:
    """Phases and actions ``s`` times faster (:meth:`Scenario.scaled`)."""
    import dataclasses

    order = {"v": 1, "a": 2, "j": 3}
    out: list[Phase] = []
    for p in phases:
        if isinstance(p, JointPhase):
            out.append(dataclasses.replace(
                p, times=None if p.times is None else p.times / s,
                durations=p.durations / s,
                speed_pct=None if p.speed_pct is None else p.speed_pct * s,
                boundary={k: v * s ** order[k[0]] for k, v in p.boundary.items()}))
        elif isinstance(p, CartesianPhase):
            weave = p.weave if p.weave is None else dataclasses.replace(
                p.weave, frequency=p.weave.frequency * s, dwell=p.weave.dwell / s)
            out.append(dataclasses.replace(
                p, speed=p.speed * s, sample_period=p.sample_period / s,
                ramp=None if p.ramp is None else p.ramp / s,
                move_time=None if p.move_time is None else p.move_time / s,
                weave=weave, time_scale=p.time_scale * s))
        else:
            out.append(dataclasses.replace(p, duration=p.duration / s))
    return tuple(out), tuple(dataclasses.replace(a, time=None if a.time is None else a.time / s)
                             for a in actions)

