"""The check model of a cell: a copy of the compiled cell whose contact masks select the pairs
collisions are checked for (robot links, tool, cell objects, parts), the geoms' roles, and the
scan that measures the pairs' distances at given samples of a motion.

Every robot of the cell is checked: the first (prefix ``robot``) and each other robot
(:attr:`sim.cells.Cell.partners`, prefix its name, ``r2/link3``, ``r2/tool/nozzle``). Each
checked geom of a robot names its robot (:attr:`CheckGeom.robot`); a robot's links and tool
are checked against the cell, the parts and every other robot's links and tool (tool against
tool too), and against its own links as for a single robot.

Owns what is checked and how a sample is measured (:class:`CollisionModel`,
:class:`Contacts`, :func:`coarse_scan`); what may touch is
:mod:`sim.simulation.allowed_contacts`', the search for collisions and clearance along a motion
:mod:`sim.simulation.collisions`'.
May import: :mod:`sim.errors` and the compiled cell.
"""

from __future__ import annotations

import copy
import itertools
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.errors import InternalError
from sim.simulation.compile import BuiltCell

#: Penetration a contact may have without being a collision, m.
PENETRATION_TOLERANCE_M = 1e-4
#: Pairs closer than this are measured for penetration (``mj_geomDistance``), m.
DETECTION_MARGIN_M = 1e-3
#: Distances are measured up to this range, m (the check model's geom margin).
CLEARANCE_RANGE_M = 0.1


#: Roles of the checked geoms.
LINK, TOOL, CELL, PART = "link", "tool", "cell", "part"
_BITS = {LINK: 1, TOOL: 2, CELL: 4, PART: 8}
_AFFINITY = {LINK: 1 | 2 | 4 | 8, TOOL: 1 | 4 | 8, CELL: 1 | 2 | 8, PART: 1 | 2 | 4 | 8}
#: With several robots a tool is checked against the other robots' tools too (a robot's own
#: tool geoms share its last link's weld body: MuJoCo never pairs them).
_AFFINITY_ROBOTS = {**_AFFINITY, TOOL: 1 | 2 | 4 | 8}
#: The first robot's name (its MJCF prefix).
LEAD = "robot"
#: The name dm_control gives a geom a model file left unnamed (``robot//unnamed_geom_18``):
#: reported as ``<body>#<k>`` (which link touched), as an unnamed one.
_DM_CONTROL_UNNAMED = re.compile(r"/unnamed_geom_\d+$")
ROLE_CODE = {LINK: 0, TOOL: 1, CELL: 2, PART: 3}


@dataclass(frozen=True)
class CheckGeom:
    """One checked geom.

    Attributes:
        id: Geom id in the compiled cell.
        name: Geom name (``robot/link4/...``; unnamed robot geoms get ``<body>#<k>``).
        role: ``link``, ``tool``, ``cell`` or ``part``.
        owner: What a report names: the robot body, the tool body, the cell object or the part.
        work: A tool work geom (wire, cup lip).
        base: A geom of the robot's fixed base (left out of the arm's clearance).
        robot: The robot a link or tool geom belongs to (``robot`` for the first, the cell's
            name of another, ``r2``); None for the cell and the parts.
    """

    id: int
    name: str
    role: str
    owner: str
    work: bool = False
    base: bool = False
    robot: str | None = None


@dataclass
class MotionSamples:
    """A motion sampled for checking, N samples.

    Attributes:
        t: Times, s, (N,).
        qpos: Full MuJoCo qpos of the cell, (N, nq).
        phase: Phase index of each sample, (N,).
        arc_on: Arc on, (N,).
        suction: Suction on, (N,).
        lanes: The cell's other robots' work on the same samples, by name (their phases and
            arc); :attr:`phase` and :attr:`arc_on` are the first robot's.
    """

    t: NDArray[np.float64]
    qpos: NDArray[np.float64]
    phase: NDArray[np.int64]
    arc_on: NDArray[np.bool_]
    suction: NDArray[np.bool_]
    lanes: dict[str, LaneSamples] = field(default_factory=dict)

    @property
    def dt(self) -> float:
        return float(np.median(np.diff(self.t))) if self.t.size > 1 else 1.0

    def lane(self, name: str) -> LaneSamples:
        """Another robot's work (:attr:`lanes`); one phase following no seam, arc off, when
        the samples do not say (a motion sampled without it)."""
        got = self.lanes.get(name)
        if got is not None:
            return got
        n = self.t.size
        return LaneSamples(np.zeros(n, int), np.zeros(n, bool), ["cycle"], [None], [0.0])


@dataclass
class LaneSamples:
    """Another robot's work on the samples of a :class:`MotionSamples`.

    Attributes:
        phase: Index of its phase at each sample, (N,).
        arc_on: Its arc on, (N,).
        phase_names: Its phases' names.
        phase_seams: The seam each of its phases follows (None where it follows none).
        weaves: Each of its phases' weave reach, m.
    """

    phase: NDArray[np.int64]
    arc_on: NDArray[np.bool_]
    phase_names: list[str]
    phase_seams: list[str | None]
    weaves: list[float]


@dataclass(frozen=True)
class AllowedContact:
    """Contacts between geoms ``a`` and ``b`` are allowed on the samples where ``when`` is set,
    up to a penetration of ``max_depth_m``."""

    a: frozenset[int]
    b: frozenset[int]
    when: NDArray[np.bool_]
    reason: str
    max_depth_m: float = np.inf

    def mask(self, s: NDArray[np.int64], g1: NDArray[np.int64], g2: NDArray[np.int64],
             dist: NDArray[np.float64] | None = None) -> NDArray[np.bool_]:
        """Which contacts (sample ``s``, geoms ``g1``, ``g2``, distance ``dist``, m; arrays)
        this declaration allows."""
        a, b = np.fromiter(self.a, int), np.fromiter(self.b, int)
        pair = (np.isin(g1, a) & np.isin(g2, b)) | (np.isin(g1, b) & np.isin(g2, a))
        ok = pair & self.when[s]
        if dist is not None and np.isfinite(self.max_depth_m):
            ok &= -dist <= self.max_depth_m
        return ok


@dataclass
class Contacts:
    """Contacts found on a set of samples (one row per geom pair and sample, closest only)."""

    s: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, int))
    g1: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, int))
    g2: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, int))
    dist: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))

    def select(self, keep: NDArray[np.bool_]) -> Contacts:
        return Contacts(self.s[keep], self.g1[keep], self.g2[keep], self.dist[keep])

    @staticmethod
    def concat(parts: Sequence[Contacts]) -> Contacts:
        if not parts:
            return Contacts()
        return Contacts(*(np.concatenate([getattr(p, k) for p in parts])
                          for k in ("s", "g1", "g2", "dist")))


class CollisionModel:
    """The check model of a compiled cell: which geoms are checked, as what, against what.

    Args:
        built: The compiled cell.

    Attributes:
        geoms: Checked geoms by id.
        model: Check model for collisions (geom margins :data:`DETECTION_MARGIN_M`).
        range_model: Check model for clearance (cell and part geoms with margin
            :data:`CLEARANCE_RANGE_M`).
        pair_model: With several robots, the check model of the robots' distances to each
            other (every robot geom with margin :data:`CLEARANCE_RANGE_M`, paired with the
            other robots' geoms only); None with one robot.
    """

    def __init__(self, built: BuiltCell) -> None:
        import mujoco

        self.built = built
        src = built.model
        cell = built.cell
        #: The cell's robots, the first one first: (name, tool).
        self.robots: list[str] = [LEAD, *(cr.name for cr in cell.partners)]
        tools = [cell.tool, *(cr.tool for cr in cell.partners)]
        work = {f"{name}/tool/{g}" for name, tool in zip(self.robots, tools, strict=True)
                for g in (tool.work_geoms if tool else ())}
        object_of = {g: obj for obj, geoms in cell.objects.items() for g in geoms}
        parts = set(cell.parts)
        geoms: dict[int, CheckGeom] = {}
        unnamed: dict[int, int] = {}
        # each robot's base: the bodies welded to its root (the world's on the floor, a track's
        # carriage when it stands on one)
        base_weld = {}
        for name in self.robots:
            root = next(b for b in range(1, src.nbody) if src.body(b).name.startswith(f"{name}/"))
            base_weld[name] = int(src.body_weldid[root])
        moving_cell = {int(src.body_weldid[src.body(f"{pm.name}_{a.name}").id])
                       for pm in cell.mechanisms for a in pm.spec.axes}
        moving_cell |= {int(src.body(pm.mount_body).id) for pm in cell.mechanisms}
        for g in range(src.ngeom):
            body = int(src.geom_bodyid[g])
            bname = src.body(body).name
            gname = src.geom(g).name
            if _unnamed(gname):
                unnamed[body] = unnamed.get(body, 0) + 1
                gname = f"{bname}#{unnamed[body] - 1}"
            robot = next((r for r in self.robots if bname.startswith(f"{r}/")
                          or gname.startswith(f"{r}/tool/")), None)
            if robot is not None and (gname.startswith(f"{robot}/tool/")
                                      or bname.startswith(f"{robot}/tool/")):
                geoms[g] = CheckGeom(g, gname, TOOL, bname, work=gname in work, robot=robot)
            elif robot is not None:
                if src.geom_group[g] == 3:
                    geoms[g] = CheckGeom(g, gname, LINK, bname,
                                         base=bool(src.body_weldid[body] == base_weld[robot]),
                                         robot=robot)
            elif bname in parts:
                geoms[g] = CheckGeom(g, gname, PART, bname)
            elif src.geom_contype[g] | src.geom_conaffinity[g]:
                if src.body_weldid[body] != 0 and int(src.body_weldid[body]) not in moving_cell:
                    raise InternalError(f"cell body {bname!r} moves but is neither a robot nor "
                                        "a part: collision checks do not cover it")
                geoms[g] = CheckGeom(g, gname, CELL, object_of.get(gname, gname))
        missing = work - {cg.name for cg in geoms.values() if cg.work}
        if missing:
            names = ", ".join(repr(t.name) for t in tools if t is not None)
            raise InternalError(f"tool {names} declares work geoms it does not have: "
                                f"{', '.join(sorted(missing))}")
        self.geoms = geoms
        self.model = self._masked(src, DETECTION_MARGIN_M, every=True)
        self.range_model = self._masked(src, CLEARANCE_RANGE_M)
        # several robots: their distances to each other are a clearance too, measured on a
        # model of their geoms only, each paired with the other robots' (not with its own: a
        # robot's pairs with itself, dozens within the range, are penetrations or nothing)
        self.pair_model = (self._masked(src, CLEARANCE_RANGE_M, robots_only=True)
                           if len(self.robots) > 1 else None)
        self._data = mujoco.MjData(self.model)
        self._range_data = mujoco.MjData(self.range_model)
        self._pair_data = None if self.pair_model is None else mujoco.MjData(self.pair_model)
        n = src.ngeom
        self.role = np.full(n, -1)
        self.is_work = np.zeros(n, bool)
        self.is_base = np.zeros(n, bool)
        #: Index in :attr:`robots` of each geom's robot (-1: the cell or a part), (ngeom,).
        self.robot_of = np.full(n, -1)
        for g, cg in geoms.items():
            self.role[g] = ROLE_CODE[cg.role]
            self.is_work[g] = cg.work
            self.is_base[g] = cg.base
            if cg.robot is not None:
                self.robot_of[g] = self.robots.index(cg.robot)

    def _masked(self, src: Any, margin: float, every: bool = False,
                robots_only: bool = False) -> Any:
        """The cell recompiled with the check masks and ``margin`` on the cell and part geoms
        (on every checked geom when ``every``); ``robots_only``: the robots' geoms only, each
        robot's paired with every other robot's (one contact bit per robot), all with
        ``margin``.

        The masks are set before compiling, not on a compiled copy: MuJoCo's compiler leaves
        geoms that collide with nothing out of their body's bounding-volume tree, so a geom
        enabled after compiling would be skipped by the broad phase. MuJoCo's parent filter is
        replaced by explicit exclusions of each robot link with its parent: the filter works on
        bodies welded together, so it would also skip the tool (welded to the last link) against
        the link before it.
        """
        mujoco = mujoco_module()
        spec = mujoco.MjSpec.from_string(self.built.xml, assets=self.built.cell.mjcf.get_assets())
        geoms = spec.geoms
        if len(geoms) != src.ngeom or any(
                g.name != src.geom(i).name for i, g in enumerate(geoms) if g.name):
            raise InternalError("the check model's geoms do not match the compiled cell's")
        affinity = _AFFINITY_ROBOTS if len(self.robots) > 1 else _AFFINITY
        every_robot = (1 << len(self.robots)) - 1
        for i, g in enumerate(geoms):
            cg = self.geoms.get(i)
            if robots_only:
                bit = 1 << self.robots.index(cg.robot) if cg and cg.robot is not None else 0
                g.contype, g.conaffinity = bit, (every_robot & ~bit) if bit else 0
                g.margin = margin if bit else 0.0
            else:
                g.contype = _BITS[cg.role] if cg else 0
                g.conaffinity = affinity[cg.role] if cg else 0
                g.margin = margin if cg and (every or cg.role in (CELL, PART)) else 0.0
            g.gap = 0.0
        spec.option.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_FILTERPARENT)
        for body in spec.bodies:
            own = next((f"{r}/" for r in self.robots if body.name.startswith(f"{r}/")), None)
            if own is None:
                continue
            if body.joints and body.parent is not None:
                ex = spec.add_exclude()
                ex.bodyname1, ex.bodyname2 = body.parent.name, body.name
            if (body.parent is not None and body.parent.name
                    and not body.parent.name.startswith(own)):
                # a robot standing on a track: its base sits on the carriage (the bodies up to
                # the carriage's jointed link)
                up = body.parent
                while up is not None and up.name and up.name != "world":
                    ex = spec.add_exclude()
                    ex.bodyname1, ex.bodyname2 = up.name, body.name
                    if up.joints:
                        break
                    up = up.parent
        try:
            m = spec.compile()
        except ValueError as exc:
            raise InternalError(f"the check model does not compile: {exc}") from exc
        m.opt.disableflags &= ~int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
        return m

    def rebound(self, built: BuiltCell) -> CollisionModel:
        """This check model for ``built``: another compile of the same composed cell whose
        checked geoms, bodies and joints are this one's (a sweep's other payload, which
        changes only masses and its unchecked marker; the caller makes sure:
        :func:`sim.simulation.collision_reuse.check_model`). A shallow copy: the check models
        and their data are shared, the compiled cell read for joints and bounds is
        ``built``'s."""
        other = copy.copy(self)
        other.built = built
        return other

    def reach_from_joint(self, joint: int) -> float:
        """Upper bound of the distance from a joint's anchor to any point of a checked geom it
        moves, whatever the configuration, m: the chain of body offsets from the anchor to the
        geom's body, the geom's offset and its bounding radius."""
        m = self.built.model
        jbody = int(m.jnt_bodyid[joint])
        best = 0.0
        for g in self.geoms:
            b = int(m.geom_bodyid[g])
            chain = 0.0
            while b != jbody and b != 0:
                chain += float(np.linalg.norm(m.body_pos[b]))
                b = int(m.body_parentid[b])
            if b != jbody:
                continue  # not moved by this joint
            r = (float(np.linalg.norm(m.jnt_pos[joint])) + chain
                 + float(np.linalg.norm(m.geom_pos[g])) + float(m.geom_rbound[g]))
            best = max(best, r)
        return best

    def ids(self, role: str | None = None, owner: str | None = None,
            robot: str | None = None) -> frozenset[int]:
        """Ids of the checked geoms with that role and/or owner (and of that robot)."""
        return frozenset(g for g, cg in self.geoms.items()
                         if (role is None or cg.role == role)
                         and (owner is None or cg.owner == owner)
                         and (robot is None or cg.robot == robot))

    def scan(self, qpos: NDArray[np.float64], samples: NDArray[np.int64], *,
             ranged: bool = False) -> Contacts:
        """Contacts at the given samples of ``qpos`` (N, nq): penetrations deeper than the
        tolerance, or every pair closer than :data:`CLEARANCE_RANGE_M` when ``ranged``.

        Penetration depths come from ``mj_geomDistance`` (GJK/EPA) for every pair the broad and
        narrow phases report within :data:`DETECTION_MARGIN_M`: the depth of a contact point
        of ``mj_collision`` can be far from the geoms' penetration (a cylinder against a box,
        measured: 0.09 mm reported where the geoms overlap by 2.2 mm).
        """
        mujoco = mujoco_module()
        models = ([(self.range_model, self._range_data)] if ranged
                  else [(self.model, self._data)])
        if ranged and self.pair_model is not None:
            models.append((self.pair_model, self._pair_data))
        fromto = np.zeros(6)
        out_s, out_g1, out_g2, out_d = [], [], [], []
        for i, (m, d) in itertools.product(samples, models):
            d.qpos[:] = qpos[i]
            mujoco.mj_kinematics(m, d)
            mujoco.mj_collision(m, d)
            n = d.ncon
            if not n:
                continue
            geom = d.contact.geom[:n]
            if ranged:
                keep = d.contact.dist[:n] < CLEARANCE_RANGE_M
                if keep.any():
                    out_s.append(np.full(int(keep.sum()), i))
                    out_g1.append(geom[keep, 0].copy())
                    out_g2.append(geom[keep, 1].copy())
                    out_d.append(d.contact.dist[:n][keep].copy())
                continue
            for a, b in {(int(x), int(y)) for x, y in geom}:
                dist = mujoco.mj_geomDistance(m, d, a, b, 2.0 * DETECTION_MARGIN_M, fromto)
                if dist < -PENETRATION_TOLERANCE_M:
                    out_s.append(np.array([i]))
                    out_g1.append(np.array([a]))
                    out_g2.append(np.array([b]))
                    out_d.append(np.array([dist]))
        if not out_s:
            return Contacts()
        ga, gb = np.concatenate(out_g1), np.concatenate(out_g2)
        g1, g2 = np.minimum(ga, gb), np.maximum(ga, gb)
        s, dist = np.concatenate(out_s), np.concatenate(out_d)
        # one row per (sample, pair): the closest of the pair's contact points
        order = np.lexsort((dist, g2, g1, s))
        s, g1, g2, dist = s[order], g1[order], g2[order], dist[order]
        first = np.ones(s.size, bool)
        first[1:] = (s[1:] != s[:-1]) | (g1[1:] != g1[:-1]) | (g2[1:] != g2[:-1])
        return Contacts(s[first], g1[first], g2[first], dist[first])


def _unnamed(name: str) -> bool:
    """A geom the model file left unnamed: no name, or the one dm_control gives it when it
    attaches a model (``robot//unnamed_geom_18``)."""
    return not name or bool(_DM_CONTROL_UNNAMED.search(name))


def geom_id(model: Any, name: str) -> int:
    """Id of the geom a finding names (-1 when the model has none): a name of the model, or
    ``<body>#<k>``, the k-th geom of that body that the model file left unnamed (as
    :class:`CollisionModel` names it)."""
    import mujoco

    g = int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name))
    if g >= 0 or "#" not in name:
        return g
    body_name, _, k = name.rpartition("#")
    body = int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body_name))
    if body < 0 or not k.isdigit():
        return -1
    mine = [i for i in np.flatnonzero(np.asarray(model.geom_bodyid) == body)
            if _unnamed(model.geom(int(i)).name)]
    return int(mine[int(k)]) if int(k) < len(mine) else -1


def painted_geoms(model: Any, names: Sequence[str]) -> frozenset[int]:
    """Geom ids a picture of a finding paints for its geoms (names as :func:`geom_id` reads
    them): a robot link's every geom (its collision geoms are hidden in pictures, so the
    whole link is painted), a tool's, the cell's or a part's geom itself."""
    ids: set[int] = set()
    for name in names:
        g = geom_id(model, str(name))
        if g < 0:
            continue
        body = int(model.geom_bodyid[g])
        bname = model.body(body).name
        if bname.startswith(f"{LEAD}/") and not bname.startswith(f"{LEAD}/tool/"):
            ids.update(int(k) for k in np.flatnonzero(np.asarray(model.geom_bodyid) == body))
        else:
            ids.add(g)
    return frozenset(ids)


def coarse_scan(cm: CollisionModel, qpos: NDArray[np.float64], samples: NDArray[np.int64]
                ) -> Contacts:
    """Every pair closer than :data:`CLEARANCE_RANGE_M` at the given samples, with exact
    penetration depths: a geom margin makes MuJoCo's distances exact when positive but its
    penetration depths approximate, so pairs in contact are measured again without margin
    (a contact within the tolerance counts as touching, distance 0)."""
    ranged = cm.scan(qpos, samples, ranged=True)
    exact = cm.scan(qpos, samples)
    n = max(1, cm.model.ngeom)
    key = lambda c: (c.s.astype(np.int64) * n + c.g1) * n + c.g2  # noqa: E731
    keep = ranged.dist >= 0.0
    touching = ~keep & ~np.isin(key(ranged), key(exact))
    ranged.dist[touching] = 0.0
    return Contacts.concat([ranged.select(keep | touching), exact])


def mujoco_module() -> Any:
    """The ``mujoco`` module, imported when a check first needs it."""
    import mujoco

    return mujoco
