"""Cartesian phases (``linear``, ``circular``): the phase's ADNIA move and its joint plan.

Owns :func:`_phase_cart` (the phase's points in frame 0, its speed or move time, its seam,
its orientation law, the ADNIA move), :func:`_along_seam` (the seam's torch frame at every
point), :func:`default_ramp` and :func:`_plan_cartesian` (one Cartesian phase on its own:
sampled, inverse kinematics, joined by the phase's polynomial). Blended phases are
:mod:`sim.simulation.motion.blending`'s.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planners.errors import MoveTooShortError, PlannerError
from sim.errors import ScenarioError
from sim.scenario import CartesianPhase, JointPhase, plan_phase
from sim.simulation.motion.context import CartesianContext
from sim.simulation.motion.programmed import _programmed
from sim.simulation.motion.sampling import (
    _ik_knots_refined,
    _poses,
    _sample_times,
    _smooth_weave,
    _turn_limited_period,
    _weave_period,
)
from sim.simulation.motion.seams import _check_five_axis_torch, _seam, _seam_pose
from sim.simulation.motion.timeline import PhaseMotion

#: Least duration of a default ramp, s (a phase run faster by :meth:`Scenario.scaled`: this
#: divided by its ``time_scale``).
RAMP_FLOOR_S = 0.3


def default_ramp(phase: CartesianPhase, p0: NDArray[np.float64], seam: Any,
                 ctx: CartesianContext) -> float:
    """Default duration of the smooth start and stop of a Cartesian move, s.

    Three sampling periods and at least :data:`RAMP_FLOOR_S` (divided by the phase's
    ``time_scale``), so the joint polynomial through the ADNIA via points resolves the ramp; at
    most half the move's duration at full speed.
    """
    if seam is not None:
        length = float(seam.length())
    elif phase.kind == "linear":
        length = float(np.linalg.norm(np.asarray(phase.to) - p0))
    elif phase.via is not None:
        length = float(np.linalg.norm(np.asarray(phase.via) - p0)
                       + np.linalg.norm(np.asarray(phase.to) - np.asarray(phase.via)))
    else:
        radius = float(np.linalg.norm(np.cross(p0 - phase.center, phase.axis)))
        length = abs(phase.sweep) * radius
    return min(max(3.0 * phase.sample_period, RAMP_FLOOR_S / phase.time_scale),
               0.5 * length / phase.speed)


def _phase_cart(phase: CartesianPhase, p0: NDArray[np.float64], R0: NDArray[np.float64],
                ctx: CartesianContext, label: str, *, corner: bool = False,
                roll: float | None = None, moving: bool = False) -> tuple[Any, Any]:
    """The phase's ADNIA move (``CartesianTrajectory``, frame 0) from the tool pose ``p0``,
    ``R0``, with its seam (or ``None``).

    A move along a seam with ``orientation = "seam"`` takes the seam's torch frame at every
    point (:class:`sim.simulation.seam_orientation.SeamOrientation`), keeping the roll about
    the torch axis it arrives with. ``corner``: the move is a polyline's next leg, entered
    through a corner that turns the torch (``R0`` is the previous leg's frame, not this leg's
    start); ``roll`` is then the first leg's roll, kept on every leg. ``moving``: the seam
    moves while it is welded (coordinated motion, :mod:`sim.simulation.motion.axes`): a 5-axis
    arm's torch plane is checked on the moving targets there, not on the seam at rest."""
    from planners import adnia

    F = ctx.frame0_from(phase.frame, label)  # the phase's points are in this frame

    def pt(v: Any) -> Any:
        return None if v is None else F[:3, :3] @ np.asarray(v, dtype=float) + F[:3, 3]

    to, via, center = pt(phase.to), pt(phase.via), pt(phase.center)
    axis = None if phase.axis is None else F[:3, :3] @ np.asarray(phase.axis, dtype=float)
    seam_end_pose = None
    if phase.target is not None:  # to_seam, with approach_mm / retract_mm
        seam_end_pose = _seam_pose(phase.target, ctx, label)
        to = seam_end_pose[:3, 3]
    if phase.flange and phase.euler_zyx is not None:  # UT 0: flange points to tcp points
        from sim.core.rotations import euler_zyx_to_matrix

        R_end = F[:3, :3] @ euler_zyx_to_matrix(*phase.euler_zyx)
        R_via = (R_end if phase.via_euler_zyx is None
                 else F[:3, :3] @ euler_zyx_to_matrix(*phase.via_euler_zyx))
        off = ctx.flange_to_tcp[:3, 3]
        to = None if to is None else to + R_end @ off
        via = None if via is None else via + R_via @ off
    if phase.move_time is not None:  # the move's time (its ramps included) sets its speed
        if phase.kind == "linear":
            length = float(np.linalg.norm(to - p0))
        else:
            from planners.adnia import CirclePath

            try:
                length = float(CirclePath.through(p0, via, to).length)
            except PlannerError as exc:
                raise ScenarioError(f"{label}: {exc}") from None
        ramp = min(max(3.0 * phase.sample_period, RAMP_FLOOR_S / phase.time_scale),
                   phase.move_time / 3.0)
        phase = dataclasses.replace(phase, ramp=ramp, speed=max(length, 1e-6)
                                    / (phase.move_time - ramp))

    seam = None
    if phase.seam is not None:
        seam = phase.seam_as_welded(_seam(ctx, phase.seam, f"{label}.seam"))
        if seam.kind != ("line" if phase.kind == "linear" else "arc"):
            raise ScenarioError(f"{label}.seam: {phase.seam!r} is a {seam.kind} seam; a "
                                f"{phase.kind} phase needs a {'line' if phase.kind == 'linear' else 'arc'}")
        start = ctx.to_frame0(seam.tcp_point(0.0))
        gap = float(np.linalg.norm(start - p0))
        if corner:  # a polyline's next leg: its tool path starts back along its own torch axis
            p0, gap = start, 0.0
        if gap > 5e-4:
            raise ScenarioError(
                f"{label}.seam: the tool is at {np.round(p0 * 1e3, 2).tolist()} mm (frame 0) but seam "
                f"{phase.seam!r} starts at {np.round(start * 1e3, 2).tolist()} mm, {gap * 1e3:.2f} mm "
                "away; end the previous phase at the seam start")

    if (seam is not None and phase.orientation == "seam" and ctx.kinematics.family.five_axis
            and not moving):
        _check_five_axis_torch(seam, label)

    rot_end = None
    mode = {"keep": "geodesic", "euler": "geodesic", "seam": "geodesic", "follow": "carry"}[
        phase.orientation]
    if phase.orientation == "euler":
        from sim.core.rotations import euler_zyx_to_matrix

        rot_end = F[:3, :3] @ euler_zyx_to_matrix(*phase.euler_zyx)
        if phase.flange:
            rot_end = rot_end @ ctx.flange_to_tcp[:3, :3]
    elif phase.orientation == "seam" and seam_end_pose is not None:
        rot_end = seam_end_pose[:3, :3]
    elif phase.orientation == "seam":
        rot_end = ctx.rot_to_frame0(seam.torch_rotation(seam.length()))
    kw: dict[str, Any] = dict(rotation_start=R0, orientation=mode,
                              ramp_time=phase.ramp if phase.ramp is not None
                              else default_ramp(dataclasses.replace(
                                  phase, to=to, via=via, center=center, axis=axis), p0, seam, ctx))
    if mode != "carry":
        kw["rotation_end"] = rot_end
    try:
        if phase.kind == "linear":
            end = ctx.to_frame0(seam.tcp_points()[1]) if seam is not None else to
            cart = adnia.linear_move(p0, end, phase.speed, **kw)
        elif seam is not None:
            via, end = ctx.to_frame0(seam.tcp_points()[1]), ctx.to_frame0(seam.tcp_points()[2])
            cart = adnia.arc_move(p0, via, end, phase.speed, **kw)
        elif via is not None:
            cart = adnia.arc_move(p0, via, to, phase.speed, **kw)
        else:
            cart = adnia.circle_move(center, axis, p0, phase.sweep, phase.speed, **kw)
    except MoveTooShortError as exc:
        if phase.ramp is None:  # the default ramp fits any move: the planner's own words
            raise ScenarioError(f"{label}: {exc}") from None
        raise ScenarioError(
            f"{label}.ramp_s: start and stop ramps of {phase.ramp:g} s at "
            f"{phase.speed * 1e3:g} mm/s need {phase.speed * phase.ramp * 1e3:.6g} mm of path, "
            "more than the move has; give a shorter ramp_s or a lower speed_mm_s") from None
    except PlannerError as exc:
        raise ScenarioError(f"{label}: {exc}") from None
    if seam is not None and phase.kind == "circular" and \
            abs(cart.length / seam.length() - 1.0) > 1e-4:
        # an arc's tool point kept off the seam by a stand-off runs a coaxial arc of another
        # radius: the weld's travel speed is the seam's, so the tool point's is scaled
        speed = phase.speed * cart.length / seam.length()
        try:
            cart = adnia.arc_move(p0, via, end, speed, **kw)
        except PlannerError as exc:
            raise ScenarioError(f"{label}: {exc}") from None
    if seam is not None and phase.orientation == "seam":
        cart = _along_seam(cart, seam, R0, ctx, label, corner=corner, roll=roll)
    return cart, seam


def _along_seam(cart: Any, seam: Any, R0: NDArray[np.float64], ctx: CartesianContext,
                label: str, *, corner: bool, roll: float | None) -> Any:
    """``cart`` with the seam's torch frame at every point (:func:`_phase_cart`)."""
    from planners.adnia import CartesianTrajectory
    from sim.simulation.seam_orientation import (
        MAX_START_MISALIGNMENT_DEG,
        SeamOrientation,
        roll_about,
    )

    column = int(ctx.kinematics.family.approach_column)
    to0 = ctx.frame0_from_world[:3, :3]
    if roll is None:
        roll = (roll_about(to0 @ seam.torch_rotation(0.0), R0, column) if column == 2 and not corner
                else 0.0)
    ramp_share = 0.5 * cart.speed * float(cart.profile.ramp_time) / cart.length
    law = SeamOrientation(seam, to0, 0.0, seam.length(), column=column, roll=roll,
                          start=None if corner else R0, settle=min(0.5, ramp_share))
    if law.start_misalignment_deg > MAX_START_MISALIGNMENT_DEG:
        raise ScenarioError(
            f"{label}.seam: the torch arrives {law.start_misalignment_deg:.2f} deg off seam "
            f"{seam.name!r}'s posture at its start (at most {MAX_START_MISALIGNMENT_DEG:g} deg "
            "is corrected on the start ramp); end the previous phase in the seam's posture "
            "(to_seam, with approach_mm to stop short of it)")
    return CartesianTrajectory(cart.path, law, cart.profile)


def _plan_cartesian(phase: CartesianPhase, t0: float, q0: NDArray[np.float64],
                    ctx: CartesianContext, label: str) -> PhaseMotion:
    kin = ctx.kinematics
    T0 = np.asarray(kin.fk(q0), dtype=float)
    cart, seam = _phase_cart(phase, T0[:3, 3], T0[:3, :3], ctx, label)
    extra = np.zeros(0)
    period = _turn_limited_period(cart, phase.sample_period, label, ctx.max_phase_s)
    if phase.weave is not None:
        from planners.weave import WeavingTrajectory

        cart = WeavingTrajectory(cart, phase.weave, kin.family.approach_column)
        extra = cart.breakpoints()
        period = min(period, _weave_period(phase.weave))
    ts = _sample_times(cart.duration, period, extra, label, ctx.max_phase_s)
    ts, q_via = _ik_knots_refined(kin, ts, lambda x: _poses(cart.at(x)), q0, label, ctx.robot,
                                  planner=phase.planner if _smooth_weave(phase.weave) else None)
    times = t0 + ts
    placed = JointPhase(index=phase.index, name=phase.name, planner=phase.planner, times=times,
                        durations=np.diff(times), q=q_via)
    traj = plan_phase(placed, "")
    base = cart.base if phase.weave is not None else cart
    return PhaseMotion(phase, float(times[0]), float(times[-1]), traj, cartesian=cart, seam=seam,
                       knot_times=times,
                       programmed=_programmed(base, phase.kind, base.speed))
