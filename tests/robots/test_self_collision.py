"""Self-collision specification of the three robot models: the collision geoms (class
``collision``, group 3) report a contact between two links exactly where the arm's shape says
the links hit each other, and nowhere inside the wrist's ranges.

The check is an independent computation with raw MuJoCo (nothing from ``sim``): the robot MJCF
is loaded through ``mujoco.MjSpec`` with only the geoms of one group colliding (``contype =
conaffinity = 1``, every other geom 0 and 0), MuJoCo's parent-child filter on and the model's
``<exclude>`` pairs kept. The masks are set *before* compiling: the compiler leaves geoms that
collide with nothing out of their body's bounding-volume tree, so enabling the visual geoms
(group 2) on a compiled model would silently miss most of their contacts. Then ``qpos``,
``mj_kinematics`` and ``mj_collision``; a *self-contact* is a contact between geoms of two
different bodies with ``dist < -TOL``.
"""

from __future__ import annotations

import itertools
import re

import mujoco
import numpy as np
import pytest

from sim.robots.registry import ROBOTS

NAMES = list(ROBOTS)
DEG = np.pi / 180
COLLISION, VISUAL = 3, 2
#: Penetration below which two geoms only touch (m); the tolerance of sim's collision check.
TOL = 1e-4


def _model(name: str, group: int, drop: tuple[tuple[str, str], ...] = ()) -> mujoco.MjModel:
    """The robot with only the geoms of ``group`` colliding, without the excludes in ``drop``."""
    spec = mujoco.MjSpec.from_file(str(ROBOTS[name].robot_path))
    for g in spec.geoms:
        on = int(g.group == group)
        g.contype = g.conaffinity = on
    for e in list(spec.excludes):
        if (e.bodyname1, e.bodyname2) in drop:
            spec.delete(e)
    return spec.compile()


def _excludes(name: str) -> list[tuple[str, str]]:
    spec = mujoco.MjSpec.from_file(str(ROBOTS[name].robot_path))
    return [(e.bodyname1, e.bodyname2) for e in spec.excludes]


def self_contacts(model: mujoco.MjModel, data: mujoco.MjData, q,
                  tol: float = TOL) -> dict[tuple[str, str], float]:
    """Deepest penetration (m, > ``tol``) per pair of bodies in contact at ``q``."""
    data.qpos[:] = q
    mujoco.mj_kinematics(model, data)
    mujoco.mj_collision(model, data)
    out: dict[tuple[str, str], float] = {}
    n = data.ncon
    if n == 0:
        return out
    dist = data.contact.dist[:n]
    geoms = data.contact.geom[:n]
    for k in np.flatnonzero(dist < -tol):
        b1, b2 = (int(model.geom_bodyid[g]) for g in geoms[k])
        if b1 == b2:
            continue
        pair = tuple(sorted((model.body(b1).name, model.body(b2).name)))
        out[pair] = max(out.get(pair, 0.0), float(-dist[k]))
    return out


def _grid(lo: float, hi: float, step_deg: float) -> np.ndarray:
    """``lo``, ``lo + step``, ..., and ``hi``; angles equal modulo 360 deg kept once (a revolute
    joint's geometry repeats every turn)."""
    g = np.r_[np.arange(lo, hi, step_deg * DEG), hi]
    wrapped = np.round(np.mod(g + np.pi, 2 * np.pi), 9)
    _, first = np.unique(wrapped, return_index=True)
    return g[np.sort(first)]


def wrist_sweep(model: mujoco.MjModel):
    """``home`` for J1..J3; the wrist joints over their full ranges: the bend (the wrist joint
    about +-y at q = 0) every 2.5 deg, the rolls every 15 deg, range ends included."""
    home = model.key("home").qpos.copy()
    lo, hi = model.jnt_range.T
    axes = []
    for j in range(3, model.njnt):
        bend = abs(model.jnt_axis[j, 1]) == 1.0
        axes.append(_grid(lo[j], hi[j], 2.5 if bend else 15.0))
    for wrist in itertools.product(*axes):
        q = home.copy()
        q[3:] = wrist
        yield q


def _random_configs(model: mujoco.MjModel, n: int = 2000, seed: int = 0) -> np.ndarray:
    lo, hi = model.jnt_range.T
    return np.random.default_rng(seed).uniform(lo, hi, size=(n, model.njnt))


# ---------------------------------------------------------------------------------------------
# Specifications
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", NAMES)
def test_wrist_sweep_at_home_has_no_self_contact(name):
    """The wrist moves over its full ranges with the arm at ``home``: no two links touch."""
    model = _model(name, COLLISION)
    data = mujoco.MjData(model)
    worst: dict[tuple[str, str], tuple[float, np.ndarray]] = {}
    n = 0
    for q in wrist_sweep(model):
        n += 1
        for pair, depth in self_contacts(model, data, q).items():
            if depth > worst.get(pair, (0.0,))[0]:
                worst[pair] = (depth, q.copy())
    assert n > 2000
    report = [f"{a}-{b}: {1e3 * d:.1f} mm at q = {np.round(q / DEG, 1).tolist()} deg"
              for (a, b), (d, q) in sorted(worst.items(), key=lambda kv: -kv[1][0])]
    assert not worst, f"{name}: self-contacts in the wrist sweep ({n} configurations): {report}"


@pytest.mark.parametrize("name", NAMES)
def test_collision_contacts_are_contacts_of_the_visual_shape(name):
    """Over 2000 random configurations of the full ranges: every self-contact of the collision
    geoms is a penetration of the visual primitives of the same two links (the collision geoms
    are the visual primitives or shortened copies of them: they invent nothing)."""
    coll, vis = _model(name, COLLISION), _model(name, VISUAL)
    dc, dv = mujoco.MjData(coll), mujoco.MjData(vis)
    bad = []
    found = 0
    for q in _random_configs(coll):
        c = self_contacts(coll, dc, q)
        if not c:
            continue
        found += 1
        v = self_contacts(vis, dv, q, tol=0.0)
        bad += [f"{pair} {1e3 * depth:.1f} mm at {np.round(q / DEG, 1).tolist()} deg"
                for pair, depth in c.items() if pair not in v]
    assert found >= 5  # the sample does fold the arm onto itself
    assert not bad, f"{name}: {len(bad)} contacts the visual shape does not have: {bad[:5]}"


@pytest.mark.parametrize("name", NAMES)
def test_collision_geoms_are_visual_primitives_or_shortened_copies(name):
    """Each collision geom lies inside a visual primitive of its body: the same box, or the same
    cylinder/capsule (radius, axis) over a part of its length."""
    model = mujoco.MjModel.from_xml_path(str(ROBOTS[name].robot_path))
    for g in np.flatnonzero(model.geom_group == COLLISION):
        body = model.geom_bodyid[g]
        ax = np.zeros(9)
        mujoco.mju_quat2Mat(ax, model.geom_quat[g])
        axis = ax.reshape(3, 3)[:, 2]
        ok = False
        for v in np.flatnonzero((model.geom_group == VISUAL) & (model.geom_bodyid == body)):
            if model.geom_type[v] != model.geom_type[g]:
                continue
            if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX:
                ok = (np.allclose(model.geom_size[v], model.geom_size[g])
                      and np.allclose(model.geom_pos[v], model.geom_pos[g])
                      and np.allclose(model.geom_quat[v], model.geom_quat[g]))
            else:
                vx = np.zeros(9)
                mujoco.mju_quat2Mat(vx, model.geom_quat[v])
                vaxis = vx.reshape(3, 3)[:, 2]
                off = model.geom_pos[g] - model.geom_pos[v]
                along = float(off @ vaxis)
                ok = (np.isclose(model.geom_size[v, 0], model.geom_size[g, 0])
                      and abs(abs(axis @ vaxis) - 1) < 1e-9
                      and np.linalg.norm(off - along * vaxis) < 1e-9
                      and abs(along) + model.geom_size[g, 1] <= model.geom_size[v, 1] + 1e-9)
            if ok:
                break
        assert ok, f"{name}: collision geom {g} of {model.body(body).name} is no visual primitive"


@pytest.mark.parametrize("name", NAMES)
def test_excludes_are_necessary_and_documented(name):
    """An ``<exclude>`` is kept only where the real joint makes two links touch: without it a
    contact appears (at ``home``, ``zero`` or in a random sample of the ranges), and an XML
    comment on the line before says why."""
    lines = ROBOTS[name].robot_path.read_text().splitlines()
    for i, line in enumerate(lines):
        if "<exclude" in line:
            assert re.match(r"\s*<!-- .+ -->$", lines[i - 1]), (
                f"{name}: undocumented {line.strip()}")
    for pair in _excludes(name):
        model = _model(name, COLLISION, drop=(pair,))
        data = mujoco.MjData(model)
        configs = [model.key("home").qpos, model.key("zero").qpos, *_random_configs(model)]
        assert any(tuple(sorted(pair)) in self_contacts(model, data, q) for q in configs), (
            f"{name}: <exclude {pair}> hides no contact: remove it")


# The 200iC/5L folded onto itself (deg): the forearm folded down along the upper arm, its wrist
# in the J2 housing of link1; the upper arm tilted 130 deg forwards and the forearm folded back
# down, its wrist in the base column.
FOLDS_200IC = [(0, 0, -100, 0, -90, 0), (0, -130, -60, 0, -90, 0)]


@pytest.mark.parametrize("q_deg", FOLDS_200IC)
def test_200ic_forearm_folded_into_its_base_is_a_self_contact(q_deg):
    """Links that really hit each other inside the ranges still collide: the 200iC's wrist folded
    into link1 or the base (the visual shapes clearly intersect there, > 20 mm)."""
    q = np.array(q_deg) * DEG
    low, wrist = {"base", "link1"}, {"link4", "link5", "link6"}

    def folds(contacts):
        return {p: d for p, d in contacts.items() if set(p) & low and set(p) & wrist}

    coll, vis = _model("lrmate200ic5l", COLLISION), _model("lrmate200ic5l", VISUAL)
    lo, hi = coll.jnt_range.T
    assert np.all((lo <= q) & (q <= hi))
    v = folds(self_contacts(vis, mujoco.MjData(vis), q))
    assert v and max(v.values()) > 0.020, v
    c = folds(self_contacts(coll, mujoco.MjData(coll), q))
    assert c and max(c.values()) > 0.010, c
