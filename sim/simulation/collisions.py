"""Collisions and clearance along a motion: the robots, their tools, the cell and the parts.

The physics model keeps contacts that are part of the work only (parts on fixtures, the suction
cup on a part): a contact of the arm or the torch with the cell would push back and pollute the
joint torques used for sizing, and a real robot does not bounce off a fixture; it crashes.
Collisions are therefore a geometric question, answered along the recorded (or reference)
motion on a *check model*: a copy of the compiled cell whose contact masks are set here.

What is checked (:class:`CollisionModel`):

* **geoms**: the robot links' collision geoms (group 3), every geom of the tool, every static
  cell geom that collides in the physics model (fixtures, workpieces, the floor; markers such as
  the seam lines and slots do not) and the parts;
* **pairs**: robot link with robot link but each link with its parent (they meet at their
  joint; the robot's own ``<exclude>`` pairs apply too), tool with robot link (every link but
  the one it is mounted on), robot or tool with any cell object or part, part with cell object
  or part;
* **several robots** (a cell's ``[[robots]]``, prefix their name: ``r2/link3``,
  ``r2/tool/nozzle``): each robot's links and tool as above, and against every other robot's
  links and tool (link with link, tool with link, tool with tool); two robots' bases both
  welded to the floor are not paired (neither moves).

Allowed contacts are declared (:func:`allowed_contacts`), not guessed (each robot's wire
and tool mount for itself, on its own phases and arc: :class:`MotionSamples` ``lanes``; nothing
between two robots is ever allowed):

* the tool's *work geoms* (:attr:`sim.cells.tools.ToolSpec.work_geoms`): the welding wire
  in the joint while the arc is on: with the workpieces of the seam the phase welds
  (:attr:`sim.cells.Cell.seam_objects`), up to its radius, plus the phase's weave reach
  (:func:`weave_reach`: the largest offset of its pattern from the path; moving a geom by a
  vector ``d`` deepens its penetration of another by at most ``|d|``), plus
  :data:`WIRE_ARC_DEPTH_M` (the tip in the pool); and at any time, arc off included, with any
  workpiece up to its radius plus the torch's ``touch_depth_m`` (touch sensing: the tip set on
  the root). A wire tip whose centre lies on the work's surface overlaps it by at most its
  radius however the wire is tilted (a cylinder's rim: ``r sin(tilt)``; a 0.6 mm wire with its
  tip on the corner line of two boxes, 45 deg work and 12 deg travel angle: 0.433 mm into each,
  ``mj_geomDistance``). Each geom pair is measured and allowed on its own, so a tip in a
  fillet's corner counts once per wall, never the sum, and no deeper than on one wall (a
  pair's depth is the least translation that frees the wire from that geom alone). Deeper
  means the tip's centre is in the work: 1 mm along the torch axis into that corner measures
  1.125 mm (so does a root drawn where a bent part's faces would meet: that line lies
  ``0.41 R`` deep in a bend of inside radius ``R``);
  the cup lip with the part it picks (the nearest part holding the tool point when
  suction comes on), from the start of the phase before suction comes on (the descent) to the
  end of the phase after it goes off (the retract);
* a part with the cell while it is not held (it rests), with another part while neither is
  held, and while held in the phase where suction comes on and the next one (lift-off) and in
  the phase where suction goes off and the one before (set-down); parts and the lip up to
  :data:`PART_CONTACT_DEPTH_M` deep;
* a tool geom with a geom of the link before the one the tool is mounted on, when the two
  overlap at every angle of the joint between them (:func:`~sim.simulation.allowed_contacts.
  mount_overlaps`: the model's shapes meeting at the mount, e.g. a generated arm's wrist capsule
  whose cap reaches past the flange face into the torch's adapter; MoveIt's "always in
  collision" pair); a pair that overlaps at some angles only is a collision;
* everything else (nozzle, contact tip, torch body, arm, a held part in transfer) never.

A contact is a collision when its penetration exceeds :data:`PENETRATION_TOLERANCE_M` (0.1 mm,
below the soft-contact sinkage of a resting part and the wire's touch at a seam start).
Every sample that can hold a collision is checked: a coarse scan every
:data:`CLEARANCE_STRIDE_S` measures the distances of the pairs closer than
:data:`CLEARANCE_RANGE_M`, and an interval between two coarse samples is checked sample by
sample unless no pair there can get deeper than it may: the pair's distance at the interval's
ends less how much closer its two geoms can get inside it (:func:`motion_bound`: joint travel
times each joint's reach, part travel) stays above the tolerance, or above the depth an allowed
contact may reach where that declaration holds all through. Collisions are reported as
intervals (:func:`find_collisions`): ``t0``, ``t1`` (s), the ``phase`` at ``t0`` and every
phase the interval spans (``phases``), the two ``bodies`` (robot body, tool body, cell object
or part), the worst geom pair (``geoms``), every geom involved (``all_geoms``, for the video)
and the worst penetration ``depth_mm`` at ``t_worst``. In a cell with several robots each
interval also names the ``robots`` of its two bodies (None for the cell or a part), each one's
phase (``robot_phases``) and says it in a line (``message``: ``"robot link5 against r2 tool
nozzle at 2.000 s (...)"``); two robots' bodies are kind ``robot_robot``, the first robot's
first. The coarse scan bounds each robot's geoms by its own joints (:func:`motion_bound`).

Clearance (:func:`clearance`): per phase, the smallest distance from the tool (its geoms but the
work geoms: nozzle and torch body) and from the arm (the links but the fixed base) to any cell
object or part, allowed contacts left out. MuJoCo's narrow phase computes the distances of the
pairs closer than :data:`CLEARANCE_RANGE_M` (the check model's geom margin); the scan runs every
:data:`CLEARANCE_STRIDE_S` and is refined at every sample around each phase's closest sample. A
phase farther than the range reports ``null``; a phase closer than the scenario's
``simulation.clearance_mm`` (default 5 mm) is a failed warning check of the verdict. With
several robots, each other robot gets the same entries per phase of its own (``"r2: weld"``),
and each pair of robots its distance per phase of the first robot (``"weld: robot / r2"``,
every geom of the two: tool with the other robot, ``tool_mm``; link with link, ``arm_mm``): a
near miss between two robots is a clearance warning naming both.

Owns the search along a motion (collision intervals, clearance) and the entry point
(:func:`check_motion`); the check model is :mod:`sim.simulation.collision_model`'s, the
declarations of what may touch :mod:`sim.simulation.allowed_contacts`', the samples of a
motion :mod:`sim.simulation.collision_samples`' (their names importable from here, as before).
May import: :mod:`sim.errors` and the simulation modules below it.
"""


from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.errors import SimulationError
from sim.simulation import collision_samples as _samples
from sim.simulation.allowed_contacts import (  # the declarations, importable from here as before
    PART_CONTACT_DEPTH_M,  # noqa: F401
    PICK_REACH_M,  # noqa: F401
    WIRE_ARC_DEPTH_M,  # noqa: F401
    allowed_contacts,
    allowed_mask,
    weave_reach,  # noqa: F401
)
from sim.simulation.collision_model import (  # the check model, importable from here as before
    CELL,
    CLEARANCE_RANGE_M,
    DETECTION_MARGIN_M,  # noqa: F401
    LEAD,
    LINK,
    PART,
    PENETRATION_TOLERANCE_M,
    ROLE_CODE,
    TOOL,
    AllowedContact,
    CheckGeom,  # noqa: F401
    CollisionModel,
    Contacts,
    LaneSamples,  # noqa: F401
    MotionSamples,
    coarse_scan,
    mujoco_module,  # noqa: F401
)
from sim.simulation.compile import BuiltCell

#: Period of the coarse scan (clearance, and the intervals a collision may hide in), s.
CLEARANCE_STRIDE_S = 0.01
#: Dips of the coarse clearance refined per phase and group (tool, arm), the deepest first.
MAX_DIPS = 50


# --------------------------------------------------------------------------------------------
# Reports
# --------------------------------------------------------------------------------------------


def _intervals_to_check(cm: CollisionModel, samples: MotionSamples, coarse: NDArray[np.int64],
                        scan: Contacts, allowed: Sequence[AllowedContact]
                        ) -> list[tuple[int, int]]:
    """Coarse intervals ``(first, last sample)`` in which a collision cannot be ruled out.

    A pair at distance ``d`` at an end of interval ``k`` gets at most the sum of its geoms'
    bounds closer inside it (:func:`motion_bound`): it cannot collide there when that stays
    above the penetration tolerance, or above the depth an allowed contact may reach when that
    declaration holds all through the interval.
    """
    if len(coarse) < 2:
        return [(int(coarse[0]), int(coarse[0]))] if len(coarse) else []
    starts = coarse[:-1]
    bounds = motion_bound(cm, samples, coarse)
    # too fast for the coarse distances to tell: a pair beyond the range at both ends (not in
    # the scan) may come closer by its two geoms' bounds, the largest a robot's and another
    # robot's, a part's or a cell mechanism's
    robots = [bounds[LINK], *(bounds[f"{r}/"] for r in cm.robots[1:])]
    hi = np.maximum.reduce([*robots, bounds[PART], bounds[CELL]])
    need = (np.maximum.reduce(robots) + hi) >= CLEARANCE_RANGE_M
    through = [(rule, np.logical_and.reduceat(rule.when, starts) & rule.when[coarse[1:]])
               for rule in allowed]
    pos = np.searchsorted(coarse, scan.s)
    for side in (0, -1):  # a coarse sample starts interval pos and ends interval pos - 1
        k = pos + side
        ok = (k >= 0) & (k < len(starts))
        rows, k = np.flatnonzero(ok), k[ok]
        # the deepest the pair can be inside the interval
        worst = scan.dist[rows] - _pair_reach(cm, bounds, scan.g1[rows], scan.g2[rows], k)
        risky = worst < -PENETRATION_TOLERANCE_M
        rows, k, worst = rows[risky], k[risky], worst[risky]
        safe = np.zeros(rows.size, bool)
        g1, g2 = scan.g1[rows], scan.g2[rows]
        for rule, all_when in through:
            a, b = np.fromiter(rule.a, int), np.fromiter(rule.b, int)
            pair = (np.isin(g1, a) & np.isin(g2, b)) | (np.isin(g1, b) & np.isin(g2, a))
            safe |= pair & all_when[k] & (worst >= -rule.max_depth_m)
        need[k[~safe]] = True
    return [(int(coarse[k]), int(coarse[k + 1])) for k in np.flatnonzero(need)]


def _kind(cm: CollisionModel, g1: int, g2: int) -> str:
    roles = {cm.geoms[g1].role, cm.geoms[g2].role}
    if roles <= {LINK, TOOL}:
        return "self" if cm.geoms[g1].robot == cm.geoms[g2].robot else "robot_robot"
    if PART in roles and roles & {LINK, TOOL}:
        return "part"
    if PART in roles:
        return "held_part"
    return "cell"


def _ordered(cm: CollisionModel, g1: int, g2: int) -> tuple[int, int]:
    """Robot side first (link, tool, part, cell); two robots: in the cell's order (the first
    robot first)."""
    ra, rb = int(cm.robot_of[g1]), int(cm.robot_of[g2])
    if ra >= 0 and rb >= 0 and ra != rb:
        return (g1, g2) if ra < rb else (g2, g1)
    order = {LINK: 0, TOOL: 1, PART: 2, CELL: 3}
    a, b = cm.geoms[g1], cm.geoms[g2]
    return (g1, g2) if order[a.role] <= order[b.role] else (g2, g1)


def describe_geom(cm: CollisionModel, g: int) -> str:
    """A checked geom as a message names it: ``r2 tool nozzle``, ``robot link5``, an object's
    name, ``part box``."""
    cg = cm.geoms[g]
    if cg.robot is not None and cg.role == TOOL:
        return f"{cg.robot} tool {cg.name.removeprefix(f'{cg.robot}/tool/')}"
    if cg.robot is not None:
        return f"{cg.robot} {cg.owner.removeprefix(f'{cg.robot}/')}"
    return f"part {cg.owner}" if cg.role == PART else cg.owner


def coarse_samples(samples: MotionSamples) -> NDArray[np.int64]:
    """The samples of the coarse scan: every :data:`CLEARANCE_STRIDE_S`, each phase's first and
    last sample, and the last sample."""
    n = samples.t.size
    stride = max(1, int(round(CLEARANCE_STRIDE_S / max(samples.dt, 1e-12))))
    return np.unique(np.concatenate([np.arange(0, n, stride), _phase_ends(samples), [n - 1]])
                     ).astype(int)


def motion_bound(cm: CollisionModel, samples: MotionSamples, coarse: NDArray[np.int64]
                 ) -> dict[str, NDArray[np.float64]]:
    """Upper bounds of how far a checked geom of each role moves within each coarse interval
    (between any two of its samples), m, by role (``link`` and ``tool``: the first robot's
    bound; ``part``; ``cell``: its mechanisms', 0 without) and, for each other robot of the
    cell, by its prefix (``r2/``: its links' and tool's bound, from its own joints).

    Interval ``k`` runs from sample ``coarse[k]`` to ``coarse[k + 1]``. A robot joint turning
    by ``dq`` moves a point at most ``dq`` times its distance from the joint's axis, bounded
    (whatever the configuration) by the chain of body offsets from the joint's anchor to the
    geom plus the geom's bounding radius: ``R_j``. A part moves by its translation plus its
    bounding radius times its rotation angle. So ``bound_k = sum_j range_k(q_j) R_j`` plus
    the largest part motion. Two geoms come closer by at most the sum of their bounds: a pair
    farther apart than that at an interval's ends cannot touch inside it
    (:func:`find_collisions`).
    """
    m = cm.built.model
    qpos = samples.qpos
    ends = coarse[1:]
    starts = coarse[:-1]
    idx = np.arange(qpos.shape[0])
    # the interval each sample belongs to (an interval's end sample also ends it)
    k_of = np.clip(np.searchsorted(coarse, idx, side="right") - 1, 0, len(starts) - 1)

    def span(x: NDArray[np.float64]) -> NDArray[np.float64]:
        """max - min of x (N,) over each interval, end samples included."""
        hi = np.maximum.reduceat(x, starts)
        lo = np.minimum.reduceat(x, starts)
        return np.maximum(hi, x[ends]) - np.minimum(lo, x[ends])

    import mujoco

    robot = np.zeros(len(starts))
    cell = np.zeros(len(starts))  # the cell's mechanisms move their solids and what they carry
    n_arm = cm.built.cell.robot.n_joints
    # the other robots' joints move their own geoms only
    partner_of = {i: name for name, cols in cm.built.partner_cols.items()
                  for i in range(cols.start, cols.stop)}
    partners = {f"{name}/": np.zeros(len(starts)) for name in cm.built.partner_cols}
    for i, (j, adr) in enumerate(zip(cm.built.joint_ids, cm.built.robot_qpos, strict=True)):
        slide = m.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE  # moves every point as far
        move = span(qpos[:, adr]) * (1.0 if slide else cm.reach_from_joint(int(j)))
        if i in partner_of:
            partners[f"{partner_of[i]}/"] += move
            continue
        robot += move
        if i >= n_arm:
            cell += move
    part = np.zeros(len(starts))
    for adr in cm.built.part_qpos:
        body = int(m.jnt_bodyid[np.flatnonzero(m.jnt_qposadr == adr[0])[0]])
        geoms = np.flatnonzero(m.geom_bodyid == body)
        r = float(np.max(np.linalg.norm(m.geom_pos[geoms], axis=1) + m.geom_rbound[geoms]))
        move = np.sqrt(sum(span(qpos[:, a]) ** 2 for a in adr[:3]))
        quat = qpos[:, adr[3:7]]
        ref = quat[coarse[k_of]]
        ang = 2.0 * np.arccos(np.clip(np.abs(np.sum(quat * ref, axis=1)), 0.0, 1.0))
        turn = np.maximum.reduceat(ang, starts)
        turn = np.maximum(turn, ang[ends])
        part = np.maximum(part, move + r * 2.0 * turn)  # any two samples: twice from the start
    return {LINK: robot, TOOL: robot, PART: part, CELL: cell, **partners}


def _pair_reach(cm: CollisionModel, bounds: dict[str, NDArray[np.float64]],
                g1: NDArray[np.int64], g2: NDArray[np.int64], k: NDArray[np.int64]
                ) -> NDArray[np.float64]:
    """How much closer each pair (geoms g1, g2) can get within interval k, m."""
    table, row = _bound_table(cm, bounds)
    return table[row[g1], k] + table[row[g2], k]


def _bound_table(cm: CollisionModel, bounds: dict[str, NDArray[np.float64]]
                 ) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """The bounds of :func:`motion_bound` as a table (one row per role, then one per other
    robot) and each geom's row in it, (ngeom,)."""
    table = np.stack([bounds[LINK], bounds[TOOL], bounds[CELL], bounds[PART],  # by role code
                      *(bounds[f"{r}/"] for r in cm.robots[1:])])
    row = np.where(cm.robot_of > 0, len(ROLE_CODE) - 1 + cm.robot_of, cm.role)
    return table, row


def find_collisions(cm: CollisionModel, samples: MotionSamples, phase_names: Sequence[str],
                    allowed: Sequence[AllowedContact], scanned: Contacts | None = None
                    ) -> list[dict[str, Any]]:
    """Collision intervals along the motion (module docstring).

    Every sample that can hold a collision is checked: the coarse scan
    (:func:`coarse_samples`, :func:`coarse_scan`) rules an interval out when no pair can get
    deeper inside it than it may (:func:`_intervals_to_check`); every other interval is
    checked at every sample.
    """
    coarse = coarse_samples(samples)
    if scanned is None:
        scanned = coarse_scan(cm, samples.qpos, coarse)
    fine = np.concatenate([np.arange(a, b + 1) for a, b in _intervals_to_check(
        cm, samples, coarse, scanned, allowed)] or [np.zeros(0, int)])
    c = cm.scan(samples.qpos, np.unique(fine).astype(int))
    c = c.select(~allowed_mask(c, allowed))
    groups: dict[tuple[str, str], list[int]] = {}
    for r in range(c.s.size):
        a, b = _ordered(cm, int(c.g1[r]), int(c.g2[r]))
        groups.setdefault((cm.geoms[a].owner, cm.geoms[b].owner), []).append(r)
    out = []
    for (oa, ob), rows in groups.items():
        rows_a = np.array(rows)
        s = c.s[rows_a]
        uniq = np.unique(s)
        cuts = np.flatnonzero(np.diff(uniq) > 1)
        starts = np.concatenate([[0], cuts + 1])
        ends = np.concatenate([cuts, [uniq.size - 1]])
        for i0, i1 in zip(starts, ends, strict=True):
            lo, hi = uniq[i0], uniq[i1]
            sel = rows_a[(s >= lo) & (s <= hi)]
            w = sel[int(np.argmin(c.dist[sel]))]
            a, b = _ordered(cm, int(c.g1[w]), int(c.g2[w]))
            names = sorted({cm.geoms[int(g)].name for g in np.concatenate([c.g1[sel], c.g2[sel]])})
            entry: dict[str, Any] = {
                "t0": float(samples.t[lo]), "t1": float(samples.t[hi]),
                "phase": phase_names[int(samples.phase[lo])],
                "phases": [phase_names[int(k)] for k in dict.fromkeys(samples.phase[lo:hi + 1])],
                "kind": _kind(cm, a, b),
                "bodies": [oa, ob],
                "geoms": [cm.geoms[a].name, cm.geoms[b].name],
                "all_geoms": names,
                "depth_mm": float(-c.dist[w] * 1e3),
                "t_worst": float(samples.t[c.s[w]]),
            }
            if len(cm.robots) > 1:  # several robots: which, in which of its phases, and a line
                entry.update(_samples.robots_named(cm, samples, phase_names, a, b, int(lo)))
                entry["message"] = (f"{describe_geom(cm, a)} against {describe_geom(cm, b)} at "
                                    f"{entry['t0']:.3f} s ({entry['t0']:.3f}-{entry['t1']:.3f} s, "
                                    f"{entry['depth_mm']:.1f} mm deep)")
            out.append(entry)
    return sorted(out, key=lambda e: (e["t0"], e["bodies"]))


def clearance(cm: CollisionModel, samples: MotionSamples, phase_names: Sequence[str],
              allowed: Sequence[AllowedContact], scanned: Contacts | None = None
              ) -> list[dict[str, Any]]:
    """Per phase: the tool's and the arm's smallest distance to the cell (module docstring).

    Each entry: ``phase``, ``tool_mm`` and ``arm_mm`` (null beyond :data:`CLEARANCE_RANGE_M`),
    with the ``tool_pair``/``arm_pair`` (geom names), ``tool_bodies``/``arm_bodies`` (the robot
    body, tool body, cell object or part of each) and ``tool_t``/``arm_t`` where they occur.
    Allowed contacts (and the tool near the part it picks, in the same windows) are left out.
    The coarse scan is refined at every sample around each dip of the distance (a coarse sample
    closer than both neighbours, plateaus counted once) that could hide a value below the
    phase's coarse minimum (:func:`motion_bound`), the :data:`MAX_DIPS` deepest per phase.

    With several robots, the first robot's entries come first, then each other robot's, per
    phase of its own (``phase`` ``"r2: weld"``, ``robot``), then each pair of robots', per
    phase of the first robot (``phase`` ``"weld: robot / r2"``, ``robots``): ``tool_mm``
    between a tool and the other robot (its tool or links, the wire included), ``arm_mm``
    between their links.
    """
    coarse = coarse_samples(samples)
    if scanned is None:
        scanned = coarse_scan(cm, samples.qpos, coarse)
    bounds = motion_bound(cm, samples, coarse) if len(coarse) > 1 else None
    subjects = _subjects(cm, samples, phase_names, bounds)
    c = _clearance_rows(cm, scanned, allowed)
    pos_of = {int(i): k for k, i in enumerate(coarse)}
    refine: set[int] = set()
    subject_of = _subject_of(cm, c)
    for si, subject in enumerate(subjects):
        bound = subject.bound
        for grp_rows in _group_rows(cm, c).values():
            rows = grp_rows & (subject_of == si)
            # the group's smallest distance at each coarse sample (the range where none is
            # closer)
            d = np.full(len(coarse), CLEARANCE_RANGE_M)
            np.minimum.at(d, [pos_of[int(i)] for i in c.s[rows]], c.dist[rows])
            ph = subject.phase[coarse]
            for k in range(len(subject.names)):
                idx = np.flatnonzero(ph == k)
                if idx.size == 0 or np.min(d[idx]) >= CLEARANCE_RANGE_M:
                    continue
                best = float(np.min(d[idx]))
                left = np.concatenate([[np.inf], d[idx][:-1]])
                right = np.concatenate([d[idx][1:], [np.inf]])
                dips = idx[(d[idx] < left) & (d[idx] <= right)]
                slack = np.array([max(bound[j - 1] if j > 0 else 0.0,
                                      bound[j] if j < len(bound) else 0.0) for j in dips])
                dips = dips[d[dips] - slack < best]
                for j in dips[np.argsort(d[dips])][:MAX_DIPS]:
                    lo = int(coarse[max(j - 1, 0)])
                    hi = int(coarse[min(j + 1, len(coarse) - 1)])
                    refine.update(range(lo, hi + 1))
    fine = (_clearance_rows(cm, cm.scan(samples.qpos, np.array(sorted(refine), int),
                                        ranged=True), allowed) if refine else Contacts())
    both = Contacts.concat([c, fine])
    rows_by = _group_rows(cm, both)
    subject_of = _subject_of(cm, both)
    out = []
    for si, subject in enumerate(subjects):
        for k, name in enumerate(subject.names):
            entry: dict[str, Any] = {"phase": subject.label.format(phase=name), **subject.keys}
            for grp in ("tool", "arm"):
                sel = rows_by[grp] & (subject_of == si) & (subject.phase[both.s] == k)
                if sel.any():
                    r = np.flatnonzero(sel)[int(np.argmin(both.dist[sel]))]
                    a, b = _ordered(cm, int(both.g1[r]), int(both.g2[r]))
                    entry[f"{grp}_mm"] = max(0.0, float(both.dist[r] * 1e3))
                    entry[f"{grp}_pair"] = [cm.geoms[a].name, cm.geoms[b].name]
                    entry[f"{grp}_bodies"] = [cm.geoms[a].owner, cm.geoms[b].owner]
                    entry[f"{grp}_t"] = float(samples.t[both.s[r]])
                else:
                    entry[f"{grp}_mm"] = None
            out.append(entry)
    return out


@dataclass
class _Subject:
    """What a clearance entry measures: a robot's distance to the cell and the parts, or two
    robots' distance to each other.

    Attributes:
        robots: The robot (one index in ``cm.robots``) or the two robots.
        phase: The phase each sample counts in (the robot's; a pair: the first robot's), (N,).
        names: Those phases' names.
        label: The entries' ``phase``, ``{phase}`` standing for the phase's name.
        keys: What else the entries say (the robot or robots).
        bound: How much closer the pair of geoms can get within each coarse interval, m.
    """

    robots: tuple[int, ...]
    phase: NDArray[np.int64]
    names: Sequence[str]
    label: str
    keys: dict[str, Any]
    bound: NDArray[np.float64]


def _subjects(cm: CollisionModel, samples: MotionSamples, phase_names: Sequence[str],
              bounds: dict[str, NDArray[np.float64]] | None) -> list[_Subject]:
    """The clearance entries' subjects: the first robot against the cell, each other robot
    against it, each pair of robots (:func:`clearance`)."""
    def bound(r: int) -> NDArray[np.float64]:
        assert bounds is not None
        return bounds[LINK] if r == 0 else bounds[f"{cm.robots[r]}/"]

    none = np.zeros(0)
    # the first robot: as with a single robot (against the cell or a part)
    out = [_Subject((0,), samples.phase, phase_names, "{phase}", {},
                    (bounds[LINK] + bounds[PART]) if bounds is not None else none)]
    for r, name in enumerate(cm.robots[1:], start=1):
        lane = samples.lane(name)
        out.append(_Subject((r,), lane.phase, lane.phase_names, f"{name}: {{phase}}",
                            {"robot": name},
                            (bound(r) + np.maximum(bounds[PART], bounds[CELL]))
                            if bounds is not None else none))
    for ra in range(len(cm.robots)):
        for rb in range(ra + 1, len(cm.robots)):
            a, b = cm.robots[ra], cm.robots[rb]
            out.append(_Subject((ra, rb), samples.phase, phase_names,
                                f"{{phase}}: {a} / {b}", {"robots": [a, b]},
                                (bound(ra) + bound(rb)) if bounds is not None else none))
    return out


def _subject_of(cm: CollisionModel, c: Contacts) -> NDArray[np.int64]:
    """The subject (:func:`_subjects`) of each clearance row: its robot's index for a robot
    against the cell or a part, then one per pair of robots."""
    r1, r2 = cm.robot_of[c.g1], cm.robot_of[c.g2]
    n = len(cm.robots)
    lo, hi = np.minimum(r1, r2), np.maximum(r1, r2)
    # pair (a, b), a < b: after the n robots, in the order of _subjects
    pair = n + lo * n - lo * (lo + 1) // 2 + (hi - lo - 1)
    return np.where(lo >= 0, pair, hi).astype(int)


def _phase_ends(samples: MotionSamples) -> NDArray[np.int64]:
    ph = samples.phase
    edges = np.flatnonzero(np.diff(ph) != 0)
    return np.concatenate([edges, edges + 1, [ph.size - 1]]).astype(int)


def _clearance_rows(cm: CollisionModel, c: Contacts, allowed: Sequence[AllowedContact]
                    ) -> Contacts:
    """Pairs of a robot (tool but its work geoms, links but the base) with the cell or a part,
    and pairs of two robots' geoms (every geom), leaving out allowed pairs and the tool near a
    part it may touch."""
    r1, r2 = cm.role[c.g1], cm.role[c.g2]
    robot = ROLE_CODE[LINK], ROLE_CODE[TOOL]
    world = ROLE_CODE[CELL], ROLE_CODE[PART]
    keep = ((np.isin(r1, robot) & np.isin(r2, world)) | (np.isin(r2, robot) & np.isin(r1, world)))
    keep &= ~(cm.is_work[c.g1] | cm.is_work[c.g2] | cm.is_base[c.g1] | cm.is_base[c.g2])
    if len(cm.robots) > 1:
        o1, o2 = cm.robot_of[c.g1], cm.robot_of[c.g2]
        keep |= (o1 >= 0) & (o2 >= 0) & (o1 != o2)
    c = c.select(keep)
    ok = allowed_mask(c, allowed)
    # the whole tool near a part its lip may touch: picking, not a clearance
    tool, parts = cm.ids(TOOL, robot=LEAD), cm.ids(PART)
    for rule in allowed:
        if rule.a & tool and rule.b <= parts and c.s.size:
            ok |= AllowedContact(tool, rule.b, rule.when, rule.reason).mask(c.s, c.g1, c.g2)
    return c.select(~ok)


def _group_rows(cm: CollisionModel, c: Contacts) -> dict[str, NDArray[np.bool_]]:
    """Clearance rows by group: ``tool`` (a tool geom in the pair), ``arm`` (a link and no
    tool)."""
    tool = (cm.role[c.g1] == ROLE_CODE[TOOL]) | (cm.role[c.g2] == ROLE_CODE[TOOL])
    link = (cm.role[c.g1] == ROLE_CODE[LINK]) | (cm.role[c.g2] == ROLE_CODE[LINK])
    return {"tool": tool, "arm": link & ~tool}


# --------------------------------------------------------------------------------------------
# One call
# --------------------------------------------------------------------------------------------


@dataclass
class CollisionReport:
    """Collisions (intervals) and per-phase clearance of a motion (module docstring)."""

    collisions: list[dict[str, Any]]
    clearance: list[dict[str, Any]]
    allowed: list[str]


def check_motion(built: BuiltCell, samples: MotionSamples, phase_names: Sequence[str],
                 phase_seams: Sequence[str | None], *, with_clearance: bool = True,
                 weaves: Sequence[float] | None = None) -> CollisionReport:
    """Check a sampled motion for collisions (and clearance) on the cell's check model
    (``weaves``: each phase's weave reach, m, :func:`phase_weaves`)."""
    if not np.all(np.isfinite(samples.qpos)):
        i = int(np.flatnonzero(~np.all(np.isfinite(samples.qpos), axis=1))[0])
        raise SimulationError(f"the motion has non-finite positions at t = {samples.t[i]:.6g} s: "
                              "no collision check is possible")
    cm = CollisionModel(built)
    allowed = allowed_contacts(cm, samples, phase_seams, weaves)
    scanned = coarse_scan(cm, samples.qpos, coarse_samples(samples))
    collisions = find_collisions(cm, samples, phase_names, allowed, scanned)
    clear = clearance(cm, samples, phase_names, allowed, scanned) if with_clearance else []
    return CollisionReport(collisions, clear, sorted({a.reason for a in allowed}))


# the samples of a motion, importable from here as before
samples_from_arrays = _samples.samples_from_arrays
samples_from_motion = _samples.samples_from_motion
lane_samples = _samples.lane_samples
phase_seams = _samples.phase_seams
phase_weaves = _samples.phase_weaves
collision_phase = _samples.collision_phase
