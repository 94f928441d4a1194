"""Cartesian phases blended into one another (``blend_mm``) and polyline seams: one tool path
through rounded corners, one speed law, one joint polynomial.

Owns which phases blend (:func:`_blends`, :func:`_is_polyline`, :func:`_check_seam_blends`),
a polyline as its segments (:func:`_segments`), the blended path's geometry (moves trimmed at
their corners, the corner curves and orientation laws: :func:`_blend_geometry`), its time law
with each corner slowed until its joints stay within their limits
(:func:`_time_blended`, :func:`_time_with_corner_speeds`), a polyline leg's roll away from
the wrist singularity (:func:`_wrist_roll`), and the phases as windows of the one plan
(:func:`_plan_blended`).
"""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planners.errors import PlannerError
from sim.errors import CellsimError, CellsimWarning, ScenarioError
from sim.scenario import CartesianPhase, JointPhase, Phase, plan_phase
from sim.simulation.motion.cartesian import _phase_cart
from sim.simulation.motion.context import CartesianContext
from sim.simulation.motion.programmed import CNT_SHARE, _programmed, _programmed_legs
from sim.simulation.motion.sampling import (
    DEG_PER_CORNER_SAMPLE,
    SAMPLES_PER_BLEND,
    _ik_knots_refined,
    _into_j1_plane,
    _poses,
    _sample_times,
    _smooth_weave,
    _turn_limited_period,
    _weave_period,
)
from sim.simulation.motion.timeline import PhaseMotion

#: Largest turn of the path a corner blend may round at speed, deg (a near reversal would
#: be a cusp).
MAX_BLEND_TURN = 150.0
#: Smallest corner zone, m: below it the joint polynomial through the inverse kinematics
#: samples cannot follow the corner curve (a CNT on such short moves gets this).
MIN_BLEND = 1e-4
#: Corner blend of a polyline seam welded without ``blend_mm``, m.
POLYLINE_BLEND = 0.002
#: Largest corner blend of a polyline seam, as a share of the shorter of its two segments (a
#: larger ``blend_mm`` is cut back to it, with a warning).
POLYLINE_BLEND_SHARE = 0.45


def _blends(phase: CartesianPhase) -> bool:
    """Whether the phase blends into the next one (a seam phase never does: it ends on its
    seam's last point; a polyline's ``blend_mm`` rounds its own corners)."""
    return phase.seam is None and (phase.blend > 0 or phase.blend_fraction > 0)


def _check_seam_blends(phase: CartesianPhase, nxt: Phase | None,
                       ctx: CartesianContext | None, label: str) -> None:
    """A seam phase starts and ends on its seam's end points: no blend may cut them.

    Raises:
        ScenarioError: A line or arc seam phase with ``blend_mm``, or a phase blending into a
            seam phase.
    """
    if phase.seam is not None and (phase.blend > 0 or phase.blend_fraction > 0) \
            and not _is_polyline(phase, ctx):
        raise ScenarioError(
            f"{label}.blend_mm: a seam phase ends on its seam's last point (the arc goes off "
            "there); a blend would cut it. To weld round a corner without stopping, make the "
            "seam one polyline (its blend_mm rounds the inner corners); else leave blend_mm out")
    if _blends(phase) and isinstance(nxt, CartesianPhase) and nxt.seam is not None:
        raise ScenarioError(
            f"{label}.blend_mm: the next phase {nxt.name!r} welds seam {nxt.seam!r}, which "
            "starts on its first point; a blend into it would cut that point (leave blend_mm "
            "out: the tool stops on the seam's start)")


def _is_polyline(phase: CartesianPhase, ctx: CartesianContext | None) -> bool:
    seam = None if ctx is None or phase.seam is None else ctx.seams.get(phase.seam)
    return phase.kind == "linear" and seam is not None and seam.kind == "polyline"


def _segments(phase: CartesianPhase, ctx: CartesianContext, label: str
              ) -> list[CartesianPhase]:
    """A linear phase along a polyline seam as one linear move per segment (the seam's
    ``<name>/<i>`` line seams), blended at the inner corners by ``blend_mm`` (default
    :data:`POLYLINE_BLEND`, at most :data:`POLYLINE_BLEND_SHARE` of the shorter segment at each
    corner: a larger ``blend_mm`` is cut back to it there, with a warning naming the corners).
    The seam's last point is never cut: the last segment stops there (blend 0)."""
    seam = ctx.seams[phase.seam]
    segs = seam.segments()
    corner = phase.blend if phase.blend > 0 else POLYLINE_BLEND
    out = []
    cut: list[str] = []  # the corners where the user's blend_mm is more than their share
    for i, sg in enumerate(segs):
        r = 0.0
        if i + 1 < len(segs):
            share = POLYLINE_BLEND_SHARE * min(sg.length(), segs[i + 1].length())
            r = min(corner, share)
            if phase.blend > share:
                cut.append(f"{i + 1} ({share * 1e3:.3g} mm)")
        out.append(dataclasses.replace(phase, seam=sg.name, blend=r, blend_fraction=0.0,
                                       weave=None))
    if cut:
        many = len(cut) > 1
        warnings.warn(CellsimWarning(
            f"{label}.blend_mm: {phase.blend * 1e3:.4g} mm is more than "
            f"{POLYLINE_BLEND_SHARE:.0%} of the shorter segment at corner{'s' if many else ''} "
            f"{', '.join(cut)} of seam {phase.seam!r}; blended there with "
            f"{'those' if many else 'that'} instead"), stacklevel=2)
    return out


#: Share of a joint's speed and acceleration limits a blended corner may use; a corner whose
#: joint motion needs more (the torch turning fast in a small blend) is passed more slowly.
CORNER_LIMIT_SHARE = 0.8
#: Slowest a corner may be passed, as a share of the set speed, before it is refused as too
#: sharp for its blend.
MIN_CORNER_SPEED_SHARE = 0.02


def _corner_load(joint: Any, t0: float, windows: dict[int, tuple[float, float]],
                 robot: Any) -> dict[int, float]:
    """Per corner (piece index -> its time window on the path's clock): the largest share of a
    joint's speed or acceleration limit the joint reference uses there (acceleration as the
    square root of its share, so both scale with the corner's speed)."""
    if robot is None:
        return {}
    vlim = np.asarray(robot.max_speed, dtype=float)
    alim = np.asarray(robot.max_accel, dtype=float) if robot.max_accel else None
    out = {}
    for i, (ta, tb) in windows.items():
        pad = 0.25 * (tb - ta)
        t = np.clip(t0 + np.linspace(ta - pad, tb + pad, 401), joint.start, joint.end)
        st = joint.at(t)
        load = float(np.max(np.abs(st.qd) / vlim))
        if alim is not None:
            load = max(load, float(np.sqrt(np.max(np.abs(st.qdd) / alim))))
        out[i] = load
    return out


def _plan_blended(phases: list[CartesianPhase], t0: float, q0: NDArray[np.float64],
                  ctx: CartesianContext, labels: list[str]) -> list[PhaseMotion]:
    """Consecutive Cartesian phases that blend into each other (``blend_mm``) as one tool path
    (:mod:`planners.blend`): one speed law without stops, one joint polynomial through the
    inverse kinematics of the whole path, each phase a time window of it (ending where its
    corner blend joins the next phase). A phase along a polyline seam is one window over its
    segments, blended at the corners (:func:`_segments`): each leg holds the seam's torch
    frame, and the torch turns from one leg's frame to the next inside the corner only
    (:class:`planners.blend.CornerOrientation`). A corner whose joint motion would need more
    than :data:`CORNER_LIMIT_SHARE` of a joint's speed or acceleration limit at the set speed
    is passed more slowly (the speed dips inside the corner zone, and only there)."""
    # the moves: the phases, a polyline phase one move per segment (of: move -> its phase)
    moves, move_labels, of = [], [], []
    for j, (ph, lb) in enumerate(zip(phases, labels, strict=True)):
        parts = _segments(ph, ctx, lb) if _is_polyline(ph, ctx) else [ph]
        moves += parts
        move_labels += [lb] * len(parts)
        of += [j] * len(parts)
    ctx_seams = dict(ctx.seams)
    welded = [None if ph.seam is None else ph.seam_as_welded(ctx.seams[ph.seam])
              for ph in phases]
    for ph, seam in zip(phases, welded, strict=True):
        if _is_polyline(ph, ctx):
            for sg in seam.segments():
                ctx_seams[sg.name] = sg
    ctx = dataclasses.replace(ctx, seams=ctx_seams)
    rolls: dict[int, float] = {}
    for _ in range(len(moves)):  # first the legs' rolls, at the set speed
        geo = _blend_geometry(moves, move_labels, of, ctx, q0, rolls)
        trial = _time_blended(phases, labels, moves, of, geo, {}, t0, q0, ctx, one_branch=False)
        fix = _wrist_roll(trial, geo, of, t0, ctx)
        if not fix:
            break
        rolls.update(fix)
    plan = _time_with_corner_speeds(phases, labels, moves, move_labels, of, geo, t0, q0, ctx)
    carts, radii = geo.carts, geo.radii
    n = len(moves)
    out = []
    times, bounds, windows = plan.times, plan.bounds, plan.windows
    seams = welded
    for k in range(len(phases)):
        ta, tb = t0 + bounds[k], t0 + bounds[k + 1]
        knots = times[(times >= ta - 1e-12) & (times <= tb + 1e-12)]
        programmed = [mv for i, c in enumerate(carts) if of[i] == k
                      for mv in _programmed(c, moves[i].kind, c.speed, radii[i],
                                            carts[i + 1].length if i + 1 < len(carts) else 0.0)]
        zones = []
        if _is_polyline(phases[k], ctx):
            win = windows[k].base if hasattr(windows[k], "weave") else windows[k]
            mine = [plan.blend_t[i] for i in sorted(plan.blend_t)
                    if of[geo.owner[i]] == k and of[geo.owner[i] + 1] == k]
            programmed = _programmed_legs(win.base, bounds[k], bounds[k + 1], mine,
                                          phases[k].speed)
            cum = np.r_[0.0, np.cumsum([sg.length() for sg in seams[k].segments()])]
            legs = [i for i in range(n) if of[i] == k]
            zones = [(float(cum[m + 1] - radii[i]), float(cum[m + 1] + radii[i]))
                     for m, i in enumerate(legs[:-1])]
        out.append(PhaseMotion(phases[k], float(ta), float(tb), plan.joint,
                               cartesian=windows[k], seam=seams[k], knot_times=knots,
                               programmed=programmed, corner_zones=zones))
    return out


@dataclass
class _BlendGeometry:
    carts: list[Any]
    radii: list[float]
    pieces: list[Any]
    laws: list[Any]
    owner: list[int]
    path: Any


def _blend_geometry(moves: list[CartesianPhase], move_labels: list[str], of: list[int],
                    ctx: CartesianContext, q0: NDArray[np.float64],
                    rolls: dict[int, float]) -> _BlendGeometry:
    """The moves of a blended path (each a polyline leg's roll from ``rolls`` where given),
    trimmed at their corners, the corner curves and the orientation laws."""
    from planners.blend import (
        BlendCurve,
        CompositePath,
        CornerOrientation,
        SubOrientation,
        SubPath,
    )
    from planners.rotations import angular_velocity

    T0 = np.asarray(ctx.kinematics.fk(q0), dtype=float)
    p, R = T0[:3, 3], T0[:3, :3]
    carts = []
    roll = None
    for k, (move, label) in enumerate(zip(moves, move_labels, strict=True)):
        leg = k > 0 and of[k] == of[k - 1]  # a polyline's next leg, entered through a corner
        cart, _ = _phase_cart(move, p, R, ctx, label, corner=leg,
                              roll=rolls.get(k, roll) if leg else None)
        roll = getattr(cart.orientation, "roll", None)
        carts.append(cart)
        p = cart.path.evaluate(np.array([cart.length]))[0][0]
        R = cart.orientation.evaluate(np.array([1.0]))[0][0]
    n = len(moves)
    radii = [(moves[k].blend if moves[k].blend > 0 else
              max(MIN_BLEND, moves[k].blend_fraction * CNT_SHARE
                  * min(carts[k].length, carts[k + 1].length)))
             if k < n - 1 else 0.0 for k in range(n)]
    for k, r in enumerate(radii[:-1]):
        if r < MIN_BLEND - 1e-15:
            raise ScenarioError(f"{move_labels[k]}.blend_mm: {r * 1e3:.4g} mm is too small to blend "
                                f"(at least {MIN_BLEND * 1e3:g} mm; leave it out to stop)")
    pieces, laws, owner = [], [], []
    for k, cart in enumerate(carts):
        L = cart.length
        r_in = radii[k - 1] if k else 0.0
        r_out = radii[k]
        for r, who in ((r_in, k - 1), (r_out, k)):
            if r > 0 and r > 0.5 * L + 1e-12:
                raise ScenarioError(
                    f"{move_labels[who]}.blend_mm: {r * 1e3:.4g} mm is more than half of "
                    f"{moves[k].name!r} ({L * 1e3:.4g} mm long)")
        pieces.append(SubPath(cart.path, r_in, L - r_out))
        laws.append(SubOrientation(cart.orientation, r_in / L, (L - r_out) / L))
        owner.append(k)
        if r_out > 0:
            nxt = carts[k + 1]
            pa, ta = (v[0] for v in cart.path.evaluate(np.array([L - r_out]))[:2])
            pb, tb = (v[0] for v in nxt.path.evaluate(np.array([r_out]))[:2])
            turn = float(np.degrees(np.arccos(np.clip(ta @ tb, -1.0, 1.0))))
            if turn > MAX_BLEND_TURN and of[k] == of[k + 1]:  # inside one polyline seam
                raise ScenarioError(
                    f"{move_labels[k]}: seam {str(moves[k].seam).rsplit('/', 1)[0]!r} turns "
                    f"{turn:.1f} deg at its corner {k - of.index(of[k]) + 1}, too sharp to weld "
                    f"through in one pass (at most {MAX_BLEND_TURN:g} deg); weld it as two "
                    "seams, each its own phase")
            if turn > MAX_BLEND_TURN:
                raise ScenarioError(
                    f"{move_labels[k]}.blend_mm: the path turns {turn:.1f} deg at the corner into "
                    f"{moves[k + 1].name!r}, too sharp to pass at speed (at most "
                    f"{MAX_BLEND_TURN:g} deg); stop there (leave the blend out)")
            try:
                pieces.append(BlendCurve(pa, ta, pb, tb, r_out / 4))
            except PlannerError as exc:
                raise ScenarioError(f"{move_labels[k]}.blend_mm: {exc}") from None
            # each move's turning rate where the corner meets it (rad/m), carried into the
            # corner so the tool's angular velocity stays continuous there
            Ra, dRa = (v[0] for v in cart.orientation.evaluate(np.array([(L - r_out) / L])))
            Rb, dRb = (v[0] for v in nxt.orientation.evaluate(np.array([r_out / nxt.length])))
            laws.append(CornerOrientation(Ra, Rb, angular_velocity(Ra, dRa) / L,
                                          angular_velocity(Rb, dRb) / nxt.length,
                                          pieces[-1].length))
            owner.append(k)
    return _BlendGeometry(carts, radii, pieces, laws, owner, CompositePath(pieces))


def _time_with_corner_speeds(phases: list[CartesianPhase], labels: list[str],
                             moves: list[CartesianPhase], move_labels: list[str], of: list[int],
                             geo: _BlendGeometry, t0: float, q0: NDArray[np.float64],
                             ctx: CartesianContext) -> _BlendedPlan:
    """:func:`_time_blended`, each corner slowed until its joints stay within
    :data:`CORNER_LIMIT_SHARE` of their limits (at most a few passes). A corner whose load does
    not fall as it slows is not what overloads the joints there (the moves beside it are: the
    run's limit check reports them); it keeps its speed."""
    corner_speed: dict[int, float] = {}
    before: dict[int, tuple[float, float | None]] = {}  # corner -> (load, speed) last pass
    settled: set[int] = set()
    plan = _time_blended(phases, labels, moves, of, geo, corner_speed, t0, q0, ctx)
    for _ in range(12):
        load = _corner_load(plan.joint, t0, plan.blend_t, ctx.robot)
        over = {i: x for i, x in load.items()
                if x > CORNER_LIMIT_SHARE * (1 + 1e-6) and i not in settled}
        for i in list(over):
            if i in before and over[i] > 0.9 * before[i][0]:  # slowing did not help
                settled.add(i)
                del over[i]
                if before[i][1] is None:
                    corner_speed.pop(i, None)
                else:
                    corner_speed[i] = before[i][1]  # type: ignore[assignment]
        if not over:
            if settled:
                plan = _time_blended(phases, labels, moves, of, geo, corner_speed, t0, q0, ctx)
            break
        for i, x in over.items():
            k = geo.owner[i]
            before[i] = (x, corner_speed.get(i))
            v = corner_speed.get(i, min(moves[k].speed, moves[k + 1].speed))
            v_new = v * max(0.25, CORNER_LIMIT_SHARE / x * 0.98)  # a quarter at most a pass
            if v_new < MIN_CORNER_SPEED_SHARE * min(moves[k].speed, moves[k + 1].speed):
                turn = float(np.degrees(geo.laws[i].angle))
                raise ScenarioError(
                    f"{move_labels[k]}.blend_mm: the corner into {moves[k + 1].name!r} is too "
                    f"sharp for its {geo.radii[k] * 1e3:.3g} mm blend: the torch turns "
                    f"{turn:.1f} deg there, which the joints cannot follow at "
                    f"{MIN_CORNER_SPEED_SHARE * 100:g} % of the set speed; give a larger "
                    "blend_mm (or stop at the corner)")
            corner_speed[i] = v_new
        plan = _time_blended(phases, labels, moves, of, geo, corner_speed, t0, q0, ctx)
    return plan


#: A polyline leg whose wrist comes closer than this to its singularity (|sin theta5|) is
#: given another roll about the torch axis, where one keeps the wrist farther from it.
WRIST_CLEARANCE = float(np.sin(np.radians(10.0)))
#: Largest joint change between neighbouring samples of a corner before it counts as a wrist
#: flip, rad.
MAX_SAMPLE_STEP = float(np.radians(20.0))
#: Rolls about the torch axis tried for such a leg, deg (relative to the roll it has).
ROLL_CANDIDATES_DEG = (30.0, -30.0, 60.0, -60.0, 90.0, -90.0, 120.0, -120.0, 150.0, -150.0, 180.0)


def _wrist_roll(plan: _BlendedPlan, geo: _BlendGeometry, of: list[int], t0: float,
                ctx: CartesianContext) -> dict[int, float]:
    """The roll about the torch axis is free on a 6-axis arm (the seam fixes the torch axis
    only). A polyline leg entered through a corner whose joints pass near the wrist
    singularity (the torch turning through it makes the wrist spin) gets the roll, among
    :data:`ROLL_CANDIDATES_DEG`, that keeps the wrist farthest from it over the corner and
    the leg (and no wrist flip, where the branch the inverse kinematics had would take a
    joint out of its range). Returns the first such leg's new roll (move index -> rad), or
    nothing."""
    from planners.blend import CornerOrientation
    from sim.robots.kinematics.ik import ik_path
    from sim.robots.kinematics.jacobian import singularity_measures
    from sim.simulation.seam_orientation import SeamOrientation

    kin = ctx.kinematics
    if kin.family.five_axis:
        return {}

    def clearance(q: NDArray[np.float64]) -> float:
        """The wrist's least distance from its singularity along ``q`` (|sin theta5|), less
        1 where the joints jump between neighbouring samples (a wrist flip: the branch the
        inverse kinematics had runs into a joint's range)."""
        m = singularity_measures(kin, q)
        c = float(np.min(np.abs(m["wrist"]))) if "wrist" in m else 1.0
        return c - float(np.max(np.abs(np.diff(q, axis=0))) > MAX_SAMPLE_STEP)

    for i, (ta, _) in plan.blend_t.items():
        k = geo.owner[i]
        if of[k] != of[k + 1] or getattr(geo.carts[k + 1].orientation, "name", "") != "seam":
            continue
        t_leg_end = plan.blend_t.get(i + 2, (None,))[0]
        if t_leg_end is None:
            t_leg_end = float(plan.times[-1] - t0)
        tb = plan.blend_t[i][1]
        ts = np.r_[np.linspace(ta, tb, 81), np.linspace(tb, t_leg_end, 81)]
        if clearance(plan.joint.at(t0 + ts).q) >= WRIST_CLEARANCE:
            continue
        q_a = plan.joint.at(t0 + ta).q
        cart, nxt = geo.carts[k], geo.carts[k + 1]
        law = nxt.orientation
        r = geo.radii[k]
        pa = geo.pieces[i].evaluate(np.array([0.0]))[0][0]
        pb = geo.pieces[i].evaluate(np.array([geo.pieces[i].length]))[0][0]
        Ra = cart.orientation.evaluate(np.array([(cart.length - r) / cart.length]))[0][0]
        best, best_c = None, clearance(plan.joint.at(t0 + ts).q)
        for d in ROLL_CANDIDATES_DEG:
            cand = SeamOrientation(law.seam, law.to_frame0, law.s0, law.s1, column=2,
                                   roll=law.roll + np.radians(d))
            u = np.linspace(0.0, 1.0, 41)
            corner = CornerOrientation(Ra, cand.evaluate(np.array([r / nxt.length]))[0][0])
            poses = np.zeros((82, 4, 4))
            poses[:, 3, 3] = 1.0
            poses[:41, :3, :3] = corner.evaluate(u)[0]
            poses[:41, :3, 3] = pa + u[:, None] * (pb - pa)
            poses[41:, :3, :3] = cand.evaluate(u)[0]
            poses[41:, :3, 3] = nxt.path.evaluate(u * nxt.length)[0]
            try:
                c = clearance(ik_path(kin, poses, q_start=q_a))
            except CellsimError:
                continue
            if c > best_c + 1e-3:
                best, best_c = law.roll + np.radians(d), c
        if best is not None:
            return {k + 1: float(best)}
    return {}


@dataclass
class _BlendedPlan:
    joint: Any
    times: NDArray[np.float64]
    bounds: list[float]
    windows: list[Any]
    blend_t: dict[int, tuple[float, float]]


def _time_blended(phases: list[CartesianPhase], labels: list[str], moves: list[CartesianPhase],
                  of: list[int], geo: _BlendGeometry, corner_speed: dict[int, float],
                  t0: float, q0: NDArray[np.float64], ctx: CartesianContext,
                  one_branch: bool = True) -> _BlendedPlan:
    """The time law of a blended path (each corner at ``corner_speed`` where given: the speed
    dips over the corner's first third, holds, and recovers over its last third), the
    phases' time windows, and the joint polynomial through the inverse kinematics of its
    samples."""
    from planners import adnia
    from planners.blend import CompositeOrientation, PiecewiseProfile, TimeWindow

    kin = ctx.kinematics
    carts, pieces, laws, owner, path = geo.carts, geo.pieces, geo.laws, geo.owner, geo.path
    lengths = [pc.length for pc in pieces]
    changes = [(0.0, 0.0, moves[0].speed, float(carts[0].profile.ramp_time))]
    for i, pc in enumerate(pieces):
        if pc.kind == "blend":
            k = owner[i]
            va, vb = moves[k].speed, moves[k + 1].speed
            vc = corner_speed.get(i)
            s0, ell = float(path.starts[i]), pc.length
            if vc is not None and vc < min(va, vb):
                changes.append((s0 + ell / 6, va, vc, 2.0 * (ell / 3) / (va + vc)))
                changes.append((s0 + 5 * ell / 6, vc, vb, 2.0 * (ell / 3) / (vc + vb)))
            elif va != vb:
                changes.append((s0 + ell / 2, va, vb, 2.0 * ell / (va + vb)))
    changes.append((path.length, moves[-1].speed, 0.0, float(carts[-1].profile.ramp_time)))
    try:
        profile = PiecewiseProfile(changes, path.length)
        traj = adnia.CartesianTrajectory(path, CompositeOrientation(laws, path.starts[:-1],
                                                                   lengths), profile)
    except PlannerError as exc:
        raise ScenarioError(f"{labels[0]}: {exc}") from None
    # each phase's window ends in the middle of its last corner (where the tool
    # "reaches" the programmed point it blends past)
    m = len(phases)
    blend_t = {i: (profile.time_at(path.starts[i]), profile.time_at(path.starts[i + 1]))
               for i, pc in enumerate(pieces) if pc.kind == "blend"}
    last = [max(i for i in range(len(pieces)) if of[owner[i]] == j) for j in range(m)]
    bounds = [0.0]
    for j in range(m - 1):
        i = last[j]
        bounds.append(0.5 * sum(blend_t[i]) if i in blend_t
                      else profile.time_at(path.starts[i + 1]))
    bounds.append(profile.duration)
    windows = []
    for j in range(m):
        ramp_in = float(carts[0].profile.ramp_time) if j == 0 else 0.0
        ramp_out = float(carts[-1].profile.ramp_time) if j == m - 1 else 0.0
        # the part at the set speed: after the start ramp or the incoming corner, before the
        # stop ramp or the outgoing corner
        first = min(i for i in range(len(pieces)) if of[owner[i]] == j)
        a = ramp_in if j == 0 else blend_t[first - 1][1] - bounds[j] if first - 1 in blend_t \
            else 0.0
        b = (bounds[j + 1] - bounds[j] - ramp_out if j == m - 1 else
             blend_t[last[j]][0] - bounds[j] if last[j] in blend_t else bounds[j + 1] - bounds[j])
        win = TimeWindow(traj, bounds[j], bounds[j + 1], phases[j].speed, ramp_in, ramp_out,
                         steady=(max(a, 0.0), max(b, max(a, 0.0))))
        if phases[j].weave is not None:
            from planners.weave import WeavingTrajectory

            # a weave carries on into and out of the phases beside it that weave alike
            first_j = j
            while first_j > 0 and phases[first_j - 1].weave == phases[j].weave:
                first_j -= 1
            win = WeavingTrajectory(
                win, phases[j].weave, kin.family.approach_column,
                clock=bounds[j] - bounds[first_j], fade_in=first_j == j,
                fade_out=j == m - 1 or phases[j + 1].weave != phases[j].weave)
        windows.append(win)
    # samples: every period (finer where the tool turns fast), at the phase ends, and at the
    # weaves' turns
    period = _turn_limited_period(traj, min(ph.sample_period for ph in phases), labels[0],
                                  ctx.max_phase_s)
    extra = [np.array(bounds[1:-1])]
    for i, (t_a, t_b) in blend_t.items():  # each corner sampled on its own, finer as it turns
        turn = float(np.degrees(getattr(laws[i], "angle", 0.0)))
        n_c = max(SAMPLES_PER_BLEND, int(np.ceil(turn / DEG_PER_CORNER_SAMPLE)))
        extra.append(np.linspace(t_a, t_b, n_c + 1))
    for k, win in enumerate(windows):
        if phases[k].weave is not None:
            period = min(period, _weave_period(phases[k].weave))
            extra.append(bounds[k] + win.breakpoints())
    ts = _sample_times(profile.duration, period, np.concatenate(extra), labels[0],
                       ctx.max_phase_s)

    def poses_at(ts: NDArray[np.float64]) -> NDArray[np.float64]:
        which = np.clip(np.searchsorted(np.array(bounds), ts, side="right") - 1, 0, m - 1)
        poses = np.zeros((len(ts), 4, 4))
        for k, win in enumerate(windows):
            sel = which == k
            if np.any(sel):
                poses[sel] = _poses(win.at(ts[sel] - bounds[k]))
        if kin.family.five_axis:  # a 5-axis arm: corners in its plane
            poses = _into_j1_plane(poses)
        return poses

    smooth = all(_smooth_weave(ph.weave) for ph in phases)
    ts, q_via = _ik_knots_refined(kin, ts, poses_at, q0, labels[0], ctx.robot, one_branch,
                                  planner=phases[0].planner if smooth else None)
    times = t0 + ts
    placed = JointPhase(index=phases[0].index, name=phases[0].name, planner=phases[0].planner,
                        times=times, durations=np.diff(times), q=q_via)
    return _BlendedPlan(plan_phase(placed, ""), times, bounds, windows, blend_t)
