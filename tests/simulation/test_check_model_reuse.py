"""A check model made for one payload checks the cell's other payloads
(:func:`sim.simulation.collision_reuse.check_model`). Specification: a sweep variant's check
model is the one made for another payload of the same composed cell only where the two cells
compile to the same checked geometry; then every scan, bound and collision it reports is what
a check model made for the variant's own cell reports, bit for bit.

The payloads and the motions are generated (hypothesis): joint positions drawn across the LR
Mate 200iC/5L's whole range on the weld-plate cell, most of them through the table, the plate
or the robot itself. The oracle is a :class:`CollisionModel` made for the variant's own
compiled cell.
"""

from __future__ import annotations

import copy
import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sim.scenario import load_scenario
from sim.simulation import build_cache
from sim.simulation import collision_reuse as cr
from sim.simulation import collisions as col
from sim.simulation.allowed_contacts import allowed_contacts
from sim.simulation.collision_model import CollisionModel, MotionSamples

SCENARIO = "lrmate200ic_weld_plate"
N = 240


@pytest.fixture(scope="module")
def scenario():
    return load_scenario(SCENARIO)


@pytest.fixture(autouse=True)
def fresh_caches():
    cr.clear_cache()
    build_cache.clear()
    yield
    cr.clear_cache()
    build_cache.clear()


def _motion(built, seed: int) -> MotionSamples:
    """N samples: a smooth walk through drawn joint positions across the joints' ranges."""
    rng = np.random.default_rng(seed)
    m = built.model
    lo, hi = m.jnt_range[built.joint_ids].T
    knots = lo + (hi - lo) * rng.uniform(0.1, 0.9, (6, len(lo)))
    s = np.linspace(0.0, 5.0, N)
    q = np.stack([np.interp(s, np.arange(6), knots[:, j]) for j in range(len(lo))], axis=1)
    qpos = np.tile(m.qpos0, (N, 1))
    qpos[:, built.robot_qpos] = q
    zeros = np.zeros(N, bool)
    return MotionSamples(0.004 * np.arange(N), qpos, np.zeros(N, int), zeros, zeros.copy())


def _everything(cm: CollisionModel, samples: MotionSamples):
    """What the checks read from a check model: both scans at every sample, each joint's
    reach, the geometry key and the collisions found."""
    every = np.arange(N)
    found = col.find_collisions(cm, samples, ["move"], allowed_contacts(cm, samples, [None],
                                                                           [0.0]))
    scans = [cm.scan(samples.qpos, every), cm.scan(samples.qpos, every, ranged=True)]
    return (found, [(c.s.tolist(), c.g1.tolist(), c.g2.tolist(), c.dist.tolist())
                    for c in scans],
            [cm.reach_from_joint(int(j)) for j in cm.built.joint_ids], cr.geometry_key(cm))


@settings(max_examples=6, deadline=None, derandomize=True)
@given(first=st.one_of(st.just(0.0), st.floats(0.1, 5.0)),
       other=st.one_of(st.just(0.0), st.floats(0.1, 5.0)), seed=st.integers(0, 2**16))
def test_another_payload_is_checked_as_its_own_check_model_checks_it(scenario, first, other,
                                                                       seed):
    cr.clear_cache()
    build_cache.clear()
    a = build_cache.build_reusing(scenario.scaled(1.0, first))
    made = cr.check_model(a)
    b = build_cache.build_reusing(scenario.scaled(1.0, other))
    reused = cr.check_model(b)
    assert reused.model is made.model and reused.built is b  # not compiled again
    samples = _motion(b, seed)
    assert _everything(reused, samples) == _everything(CollisionModel(b), samples)


def test_the_drawn_motions_touch_the_cell(scenario):
    """The generated motions are no empty test: most go through the table, the plate or the
    robot itself (seeds drawn like the property's)."""
    built = build_cache.build_reusing(scenario.scaled(1.0, 1.0))
    cm = cr.check_model(built)
    touching = [bool(cm.scan(_motion(built, seed).qpos, np.arange(N)).s.size)
                for seed in range(8)]
    assert sum(touching) >= 4, touching


def test_zero_payload_shares_the_check_model(scenario):
    """0 kg has the payload body too (massless): its cell shares the other payloads' check
    model, and checks as the one made for it does (a motion through the cell)."""
    a = build_cache.build_reusing(scenario.scaled(1.0, 2.0))
    b = build_cache.build_reusing(scenario.scaled(1.0, 0.0))
    reused = cr.check_model(b)
    assert reused.model is cr.check_model(a).model
    samples = _motion(b, 3)
    assert _everything(reused, samples) == _everything(CollisionModel(b), samples)


@pytest.mark.parametrize("field", ["geom_size", "geom_pos", "body_pos", "jnt_axis"])
def test_a_changed_checked_geometry_is_never_checked_with_the_old_model(scenario, field):
    """Planted fault: the variant's cell differs in one checked geom, body or joint (the
    same composed tree); its check model must be made anew."""
    a = build_cache.build_reusing(scenario.scaled(1.0, 2.0))
    made = cr.check_model(a)
    model = copy.copy(a.model)
    rows = {"geom_size": max(made.geoms), "geom_pos": max(made.geoms), "body_pos": 2,
            "jnt_axis": int(a.joint_ids[1])}
    getattr(model, field)[rows[field]] += 0.01
    b = dataclasses.replace(a, model=model)
    assert not cr.same_checked_geometry(a, b, list(made.geoms))
    assert cr.check_model(b).model is not made.model


def test_the_unchecked_payload_marker_may_differ(scenario):
    """The payload's marker grows with its mass and is never checked: the cells of two
    payloads differ there and still share their check model."""
    a = build_cache.build_reusing(scenario.scaled(1.0, 0.5))
    b = build_cache.build_reusing(scenario.scaled(1.0, 4.5))
    made = cr.check_model(a)
    marker = [g for g in range(a.model.ngeom) if a.model.geom(g).name.endswith("payload")]
    assert marker and not set(marker) & set(made.geoms)
    assert not np.array_equal(a.model.geom_size[marker], b.model.geom_size[marker])
    assert cr.same_checked_geometry(a, b, list(made.geoms))
