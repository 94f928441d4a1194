"""Phases in a cell with external axes (turntables, positioners, tracks): the robot's joints
and the mechanisms' axes on one clock.

The motion's joint vector is the robot's joints, then the axes (``cell.joint_names``). Owns:

* :func:`posed`: the cell with its axes at given values (the robot's frame 0 carried by a track,
  seams and object frames carried by a positioner or turntable): every phase that holds its
  axes is planned for the robot alone in this cell, as in a cell without mechanisms, and its
  trajectory gets the held axes (:class:`HeldAxes`);
* :func:`joint_with_axes`: a joint phase whose ``axes`` move with the robot's knots on the
  phase's one polynomial (intermediate knots interpolated in time), its pose target solved in
  the cell posed at the phase's end axes (``downhand``: the positioner's end solved from the
  seam's start);
* :func:`plan_coordinated`: a weld along a seam while the axes move (``downhand``: the
  positioner carrying the seam turns it so that its local normal points up at the tool point;
  ``follow``: a track carries the robot with the tool point). The tool path and orientation law
  are planned relative to the part, as for a fixed part; at each sample the target is carried
  by the part's and the robot base's motion (:func:`moving_frame`), so the travel speed and the
  torch angles hold relative to the part.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.errors import ScenarioError
from sim.scenario import CartesianPhase, JointPhase, plan_phase
from sim.simulation.motion.context import CartesianContext
from sim.simulation.motion.timeline import PhaseMotion

#: Seam samples of a coordinated weld's axes law (interpolated with a cubic spline in arc
#: length between them).
LAW_SAMPLES = 721
#: How far from the downhand pose at the seam's start the axes may be when the weld starts, rad.
START_TOLERANCE_RAD = np.radians(0.05)
#: The seam's normal may be at most this far from vertical where the positioner can turn it up.
DOWNHAND_RESIDUAL_DEG = 0.5


# ---------------------------------------------------------------------------- the cell posed
def axis_slices(ctx: CartesianContext) -> dict[str, slice]:
    """Where each mechanism's axes sit in the axes' part of the joint vector."""
    out, k = {}, 0
    for pm in ctx.mechanisms:
        out[pm.name] = slice(k, k + pm.spec.n_axes)
        k += pm.spec.n_axes
    return out


def _mech(ctx: CartesianContext, name: str) -> Any:
    return next(pm for pm in ctx.mechanisms if pm.name == name)


def displacement(ctx: CartesianContext, name: str | None, qe: NDArray[np.float64]
                 ) -> NDArray[np.float64]:
    """The world motion from home of what mechanism ``name`` carries at axes ``qe`` (all the
    cell's axes, (..., n_axes)); identity for ``None``. (..., 4, 4)."""
    qe = np.asarray(qe, dtype=float)
    if name is None:
        return np.broadcast_to(np.eye(4), (*qe.shape[:-1], 4, 4)).copy()
    return _mech(ctx, name).displacement(qe[..., axis_slices(ctx)[name]])


def world_from_frame0(ctx: CartesianContext, qe: NDArray[np.float64]) -> NDArray[np.float64]:
    """The robot's frame 0 in the world at axes ``qe`` (a track carries it), (..., 4, 4)."""
    return displacement(ctx, ctx.robot_on, qe) @ ctx.world_from_frame0


def posed(ctx: CartesianContext, qe: NDArray[np.float64]) -> CartesianContext:
    """The cell with its axes at ``qe``: frame 0, the seams and the object frames moved."""
    W = world_from_frame0(ctx, qe)
    seams = {}
    for name, seam in ctx.seams.items():
        mech = ctx.seam_mechanism.get(name)
        moved = seam if mech is None else seam.transformed(displacement(ctx, mech, qe))
        seams[name] = dataclasses.replace(moved, world_from_frame0=W)
    frames = {name: displacement(ctx, ctx.frame_mechanism.get(name), qe) @ F
              for name, F in ctx.frames.items()}
    return dataclasses.replace(ctx, world_from_frame0=W, seams=seams, frames=frames,
                               mechanisms=(), moving=ctx)


class HeldAxes:
    """A robot trajectory with the axes held at ``qe``: the joint vector's trajectory."""

    def __init__(self, robot: Any, qe: NDArray[np.float64]) -> None:
        self.robot = robot
        self.qe = np.asarray(qe, dtype=float).copy()
        self.planner = getattr(robot, "planner", "")
        self.knots = getattr(robot, "knots", None)
        self.start = float(getattr(robot, "start", self.knots[0] if self.knots is not None
                                   else 0.0))

    @property
    def duration(self) -> float:
        return float(self.robot.duration)

    @property
    def n_joints(self) -> int:
        return int(self.robot.n_joints) + self.qe.size

    def sample(self, dt: float) -> tuple[NDArray[np.float64], Any]:
        t, _ = self.robot.sample(dt)
        return t, self.at(t)

    # the robot's piecewise polynomial with the held axes as constant ones (``cellsim plan``)
    def segment_variable(self, s: int) -> str:
        return str(self.robot.segment_variable(s))

    def _with_constants(self, coefficients: Any) -> list[list[NDArray[np.float64]]]:
        out = []
        for segment in coefficients:
            seg = [np.asarray(c, dtype=float) for c in segment]
            k = len(seg[0]) if seg else 1
            held = []
            for value in self.qe:
                c = np.zeros(k)
                c[0] = value
                held.append(c)
            out.append(seg + held)
        return out

    @property
    def normalized_coefficients(self) -> list[list[NDArray[np.float64]]]:
        return self._with_constants(self.robot.normalized_coefficients)

    @property
    def real_coefficients(self) -> list[list[NDArray[np.float64]]]:
        return self._with_constants(self.robot.real_coefficients)

    def at(self, t: Any) -> Any:
        st = self.robot.at(t)
        shape = np.shape(st.q)[:-1] + (self.qe.size,)
        held = np.broadcast_to(self.qe, shape)
        z = np.zeros(shape)
        return type(st)(np.concatenate([st.q, held], axis=-1),
                        np.concatenate([st.qd, z], axis=-1),
                        np.concatenate([st.qdd, z], axis=-1),
                        np.concatenate([st.qddd, z], axis=-1))


def held(pm: PhaseMotion, qe: NDArray[np.float64]) -> PhaseMotion:
    """A phase planned for the robot alone, with the axes held at ``qe``."""
    return dataclasses.replace(pm, trajectory=HeldAxes(pm.trajectory, qe))


# ---------------------------------------------------------------------------- downhand
def _downhand_mechanism(ctx: CartesianContext, seam: str, label: str) -> Any:
    name = ctx.seam_mechanism.get(seam)
    if name is None:
        raise ScenarioError(f"{label}.downhand: seam {seam!r} lies on no positioner or "
                            "turntable (its object has no `on`)")
    pm = _mech(ctx, name)
    if pm.spec.kind == "track":
        raise ScenarioError(f"{label}.downhand: seam {seam!r} is carried by track {name!r}; a "
                            "positioner or turntable turns a seam downhand")
    return pm


def _downhand_law(ctx: CartesianContext, seam: Any, mech: Any, qe0: NDArray[np.float64],
                  s: NDArray[np.float64], label: str) -> NDArray[np.float64]:
    """The mechanism's axes (N, its n_axes) that turn ``seam`` (at home) so that its normal
    at arc lengths ``s`` points up, branch-continuous from ``qe0``'s part."""
    from sim.robots.mechanisms.kinematics import orient_path

    R_home = mech.mount_in_world(mech.home)[:3, :3]
    normals = np.array([seam.weld_normal(float(x)) for x in s]) @ R_home  # in the mount frame
    up = mech.pose[:3, :3].T @ np.array([0.0, 0.0, 1.0])  # world up in the mechanism's base
    q_start = qe0[axis_slices(ctx)[mech.name]]
    try:
        q = orient_path(mech.spec, normals, up, q_start)
    except Exception as exc:  # a sim.errors error naming the sample
        raise ScenarioError(f"{label}.downhand: {exc}") from None
    tilt = np.array([np.degrees(np.arccos(np.clip(
        (mech.mount_in_world(qk)[:3, :3] @ v) @ np.array([0.0, 0.0, 1.0]), -1.0, 1.0)))
        for qk, v in zip(q, normals, strict=True)])
    bad = np.nonzero(tilt > DOWNHAND_RESIDUAL_DEG)[0]
    if bad.size:
        k = int(bad[0])
        raise ScenarioError(f"{label}.downhand: {mech.spec.kind} {mech.name!r} cannot turn seam "
                            f"{seam.name!r}'s normal up at {s[k] * 1e3:.1f} mm from its start "
                            f"(it stays {tilt[k]:.2f} deg from vertical)")
    return q


def downhand_start(ctx: CartesianContext, seam_name: str, qe: NDArray[np.float64], label: str
                   ) -> NDArray[np.float64]:
    """The axes ``qe`` with the positioner carrying ``seam_name`` where its start is welded
    downhand (a joint phase's ``downhand`` with ``to_seam``): of the positioner's solutions
    there (each branch, each turn of a revolute axis within its range) the one nearest ``qe``
    from which the whole seam can be welded downhand within the axes' ranges."""
    import itertools

    mech = _downhand_mechanism(ctx, seam_name, label)
    seam = ctx.seams[seam_name]
    sl = axis_slices(ctx)[mech.name]
    out = np.asarray(qe, dtype=float).copy()
    s = np.linspace(0.0, seam.length(), LAW_SAMPLES // 4)
    hints = [[out[sl][i]] + ([] if a.kind != "revolute" else
                             [a.range[0], 0.5 * (a.range[0] + a.range[1]), a.range[1]])
             for i, a in enumerate(mech.spec.axes)]
    best, best_d, last = None, np.inf, None
    for hint in itertools.product(*hints):
        trial = out.copy()
        trial[sl] = hint
        try:
            q0 = _downhand_law(ctx, seam, mech, trial, s[:1], label)[0]
            trial[sl] = q0
            _downhand_law(ctx, seam, mech, trial, s, label)  # the whole seam from there
        except ScenarioError as exc:
            last = exc
            continue
        d = float(np.linalg.norm(q0 - out[sl]))
        if d < best_d - 1e-9:
            best, best_d = q0, d
    if best is None:
        assert last is not None
        raise last
    out[sl] = best
    return out


# ---------------------------------------------------------------------------- joint phases
def joint_with_axes(placed: JointPhase, qe0: NDArray[np.float64], ctx: CartesianContext,
                    names: tuple[str, ...], label: str, solve: Any) -> JointPhase:
    """A placed joint phase of the robot (its ``q`` the robot's knots) as one of the joint
    vector: the axes from ``qe0`` to the phase's ``axes`` (the others held), the pose target
    solved in the cell posed at the end axes by ``solve(phase, q0, ctx, label)``."""
    qe_end = np.asarray(qe0, dtype=float).copy()
    for name, value in placed.axes.items():
        qe_end[names.index(name)] = value
    if placed.downhand:
        assert placed.target is not None and placed.target.seam is not None
        qe_end = downhand_start(ctx, placed.target.seam, qe_end, label)
    if placed.target is not None:
        placed = placed.with_end(solve(placed, placed.q[0], posed(ctx, qe_end), label))
    times = placed.times
    share = (times - times[0]) / (times[-1] - times[0])
    axes = qe0 + share[:, None] * (qe_end - qe0)
    k = qe0.size
    boundary = {key: np.concatenate([v, np.zeros(k)]) for key, v in placed.boundary.items()}
    return dataclasses.replace(placed, q=np.hstack([placed.q, axes]), boundary=boundary,
                               target=None)


# ---------------------------------------------------------------------------- coordinated welds
def moving_frame(ctx: CartesianContext, ctx0: CartesianContext, mech: str | None,
                 qe0: NDArray[np.float64], qe: NDArray[np.float64]) -> NDArray[np.float64]:
    """Frame 0 poses planned in the cell posed at ``qe0`` (``ctx0``) carried to axes ``qe``
    (N, n_axes): ``frame0(qe)^-1 D(qe) D(qe0)^-1 frame0(qe0)`` with ``D`` the motion of what
    mechanism ``mech`` carries (the target's part; None: a world-fixed target). (N, 4, 4)."""
    D = displacement(ctx, mech, qe) @ np.linalg.inv(displacement(ctx, mech, qe0))
    return np.linalg.inv(world_from_frame0(ctx, qe)) @ D @ ctx0.world_from_frame0


def hold_roll(poses: NDArray[np.float64], column: int, ref: NDArray[np.float64]
              ) -> NDArray[np.float64]:
    """Poses (N, 4, 4) turned about their torch axis (rotation column ``column``) so that the
    next column is ``ref`` made perpendicular to the axis: a torch is symmetric about its
    axis, and the part turning under it must not wind the wrist round with it."""
    a = poses[:, :3, column]
    b = ref[None, :] - np.einsum("ni,i->n", a, ref)[:, None] * a
    b /= np.linalg.norm(b, axis=1, keepdims=True)
    c = np.cross(a, b)
    out = poses.copy()
    out[:, :3, column] = a
    out[:, :3, (column + 1) % 3] = b
    out[:, :3, (column + 2) % 3] = c
    return out


def plan_coordinated(phase: CartesianPhase, t0: float, q0: NDArray[np.float64],
                     ctx: CartesianContext, label: str) -> PhaseMotion:
    """A weld along a seam with the axes moving (module docstring), or a move whose axes go
    to ``phase.axes`` (:func:`_plan_moving_frame`)."""
    from sim.simulation.motion.cartesian import _phase_cart

    if phase.weave is not None:
        raise ScenarioError(f"{label}.weave: not with coordinated motion (downhand, follow) yet")
    n = ctx.kinematics.n_joints
    qr0, qe0 = q0[:n], q0[n:]
    ctx0 = posed(ctx, qe0)
    kin = ctx.kinematics
    T0 = np.asarray(kin.fk(qr0), dtype=float)
    cart, seam = _phase_cart(phase, T0[:3, 3], T0[:3, :3], ctx0, label, moving=True)
    if seam is None:  # a coordinated move (COORD) in a frame: its axes move with the path
        return _plan_moving_frame(phase, t0, q0, ctx, ctx0, cart, label)
    mech = ctx.seam_mechanism.get(phase.seam)
    s_grid = np.linspace(0.0, seam.length(), LAW_SAMPLES)
    q_grid = np.broadcast_to(qe0, (LAW_SAMPLES, qe0.size)).copy()
    if phase.downhand:
        pm_d = _downhand_mechanism(ctx, phase.seam, label)
        home_seam = ctx.seams[phase.seam]
        sl = axis_slices(ctx)[pm_d.name]
        law = _downhand_law(ctx, phase.seam_as_welded(home_seam), pm_d, qe0, s_grid, label)
        gap = np.abs(law[0] - qe0[sl])
        if np.any(gap > START_TOLERANCE_RAD):
            want = ", ".join(f"{nm}_deg = {np.degrees(v):.4f}"
                             for nm, v in zip(pm_d.joint_names, law[0], strict=True))
            raise ScenarioError(f"{label}.downhand: {pm_d.spec.kind} {pm_d.name!r} is "
                                f"{np.degrees(gap.max()):.3f} deg from the downhand pose at seam "
                                f"{phase.seam!r}'s start; end the previous phase there (axes: "
                                f"{want}, or downhand = true with to_seam)")
        law = law - law[0] + qe0[sl]
        q_grid[:, sl] = law
    if phase.follow is not None:
        track = _mech(ctx, phase.follow)
        if ctx.robot_on != track.name:
            raise ScenarioError(f"{label}.follow: the robot does not stand on {track.name!r}")
        if track.spec.n_axes != 1 or track.spec.axes[0].kind != "prismatic":
            raise ScenarioError(f"{label}.follow: {track.name!r} is not a one-axis linear track")
        sl = axis_slices(ctx)[track.name]
        along = track.pose[:3, :3] @ track.spec.axes[0].axis  # travel direction in the world
        seam_w = ctx0.seams[phase.seam]
        pts = np.array([seam_w.point(float(x)) for x in s_grid])
        travel = qe0[sl.start] + (pts - pts[0]) @ along
        lo, hi = track.spec.axes[0].range
        out = np.nonzero((travel < lo - 1e-9) | (travel > hi + 1e-9))[0]
        if out.size:
            k = int(out[0])
            raise ScenarioError(f"{label}.follow: track {track.name!r} would have to travel to "
                                f"{travel[k] * 1e3:.1f} mm at {s_grid[k] * 1e3:.1f} mm along the "
                                f"seam, outside its range [{lo * 1e3:g}, {hi * 1e3:g}] mm")
        q_grid[:, sl.start] = travel
    from scipy.interpolate import CubicSpline

    spline = CubicSpline(s_grid, q_grid, axis=0)
    L = float(seam.length())

    def axes_at(x: NDArray[np.float64]) -> NDArray[np.float64]:
        # the tool path (the tool point's, off the seam by the stand-off: an arc of another
        # radius) and the seam share their parameter: the same share of each's length
        u = np.asarray(cart.at(x).path_length, dtype=float) / cart.length
        return spline(np.clip(u, 0.0, 1.0) * L)

    return _sampled(phase, t0, qr0, qe0, ctx, ctx0, cart, seam, mech, axes_at, label)


def _plan_moving_frame(phase: CartesianPhase, t0: float, q0: NDArray[np.float64],
                       ctx: CartesianContext, ctx0: CartesianContext, cart: Any, label: str
                       ) -> PhaseMotion:
    """A move whose external axes go to ``phase.axes`` in proportion to the path travelled,
    its path and orientation relative to ``phase.frame`` (a TP program's ``COORD``)."""
    n = ctx.kinematics.n_joints
    qr0, qe0 = q0[:n], q0[n:]
    names = [nm for pm in ctx.mechanisms for nm in pm.joint_names]
    qe1 = qe0.copy()
    for name, value in phase.axes.items():
        qe1[names.index(name)] = value
    mech = ctx.frame_mechanism.get(phase.frame)
    if mech is None and np.any(qe1 != qe0) and ctx.robot_on is None:
        raise ScenarioError(f"{label}.frame: a coordinated move's points are in the frame of "
                            f"a part a mechanism carries; {phase.frame!r} is fixed")

    def axes_at(x: NDArray[np.float64]) -> NDArray[np.float64]:
        u = np.clip(np.asarray(cart.at(x).path_length, dtype=float) / cart.length, 0.0, 1.0)
        return qe0 + u[:, None] * (qe1 - qe0)

    return _sampled(phase, t0, qr0, qe0, ctx, ctx0, cart, None, mech, axes_at, label)


def _sampled(phase: CartesianPhase, t0: float, qr0: NDArray[np.float64],
             qe0: NDArray[np.float64], ctx: CartesianContext, ctx0: CartesianContext, cart: Any,
             seam: Any, mech: str | None, axes_at: Any, label: str) -> PhaseMotion:
    """A coordinated move sampled: the targets carried by the axes' law ``axes_at(t)``, the
    robot's inverse kinematics along them, the axes' values beside its joints, one
    polynomial through both (:func:`plan_coordinated`)."""
    from sim.simulation.motion.programmed import _programmed
    from sim.simulation.motion.sampling import (
        Carried,
        _ik_knots_refined,
        _into_j1_plane,
        _poses,
        _sample_times,
        _turn_limited_period,
    )

    kin = ctx.kinematics
    T0 = np.asarray(kin.fk(qr0), dtype=float)
    column = int(kin.family.approach_column)
    ref = T0[:3, (column + 1) % 3]  # the roll about the torch axis the phase starts with

    five_axis = bool(kin.family.five_axis)

    def poses_at(x: NDArray[np.float64]) -> NDArray[np.float64]:
        M = moving_frame(ctx, ctx0, mech, qe0, axes_at(x))
        poses = M @ _poses(cart.at(x))
        if seam is not None:  # along a seam the torch's roll is the arm's to choose
            poses = hold_roll(poses, column, ref)
        # a 5-axis arm holds its torch in the vertical plane through J1: the axes' law (a
        # spline through exact samples) leaves it a few hundredths of a degree out of it
        return _into_j1_plane(poses) if five_axis else poses

    period = _turn_limited_period(cart, phase.sample_period, label, ctx.max_phase_s)
    ts = _sample_times(cart.duration, period, np.zeros(0), label, ctx.max_phase_s)
    carried = Carried(axes_at, lambda qe, poses: np.linalg.inv(
        moving_frame(ctx, ctx0, mech, qe0, qe)) @ poses, lambda x: _poses(cart.at(x)))
    ts, q_via = _ik_knots_refined(kin, ts, poses_at, qr0, label, ctx.robot,
                                  planner=phase.planner, carried=carried)
    q_full = np.hstack([q_via, axes_at(ts)])
    times = t0 + ts
    placed = JointPhase(index=phase.index, name=phase.name, planner=phase.planner, times=times,
                        durations=np.diff(times), q=q_full)
    traj = plan_phase(placed, "")
    return PhaseMotion(phase, float(times[0]), float(times[-1]), traj, cartesian=cart, seam=seam,
                       knot_times=times, programmed=_programmed(cart, phase.kind, cart.speed))


__all__ = ["HeldAxes", "axis_slices", "displacement", "downhand_start", "held",
           "joint_with_axes", "moving_frame", "plan_coordinated", "posed", "world_from_frame0"]
