"""The reference's singularity measures kept for a sweep's variants (issue 29:
:mod:`sim.simulation.singularity_cache`). Specification: whatever was asked before, each
answer is :func:`sim.robots.kinematics.jacobian.singularity_measures` of that model and those
joints computed afresh, bit for bit; joints that differ in one bit, or another model (another
robot, another tool offset), get their own answer; a caller that writes into an answer does
not change a later one. The oracle is the uncached function; a planted key that forgets the
joints' values is caught."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sim.robots.kinematics import jacobian
from sim.robots.kinematics.model import closed_form_model
from sim.robots.registry import ROBOTS
from sim.simulation import singularity_cache

MODELS = [closed_form_model(ROBOTS[name]) for name in sorted(ROBOTS)[:3]]


def _same(got: dict[str, Any], want: dict[str, Any]) -> bool:
    return got.keys() == want.keys() and all(
        np.asarray(got[k]).dtype == np.asarray(want[k]).dtype
        and np.asarray(got[k]).tobytes() == np.asarray(want[k]).tobytes() for k in want)


def _joints(model: Any, seed: int, n: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-2.5, 2.5, size=(n, model.n_joints))


def _shifted(model: Any) -> Any:
    offset = model.tcp_offset.copy()
    offset[2, 3] += 0.01
    return dataclasses.replace(model, tcp_offset=offset)


@settings(max_examples=20, deadline=None, derandomize=True, database=None)
@given(asks=st.lists(st.tuples(st.integers(0, len(MODELS) - 1), st.integers(0, 3),
                               st.integers(1, 40), st.booleans(), st.booleans()),
                     min_size=1, max_size=8))
def test_every_answer_is_the_fresh_one(asks: list[tuple[int, int, int, bool, bool]]) -> None:
    singularity_cache.clear()
    for m, seed, n, one_bit, other_tool in asks:
        model = _shifted(MODELS[m]) if other_tool else MODELS[m]
        q = _joints(model, seed, n)
        if one_bit:
            q[-1, 0] = np.nextafter(q[-1, 0], np.inf)
        got = singularity_cache.singularity_measures(model, q)
        assert _same(got, jacobian.singularity_measures(model, q))
        for v in got.values():  # a caller writing into its answer changes no later one
            np.asarray(v)[...] = 0.0


def test_the_same_question_is_answered_from_the_kept_answer(
        monkeypatch: pytest.MonkeyPatch) -> None:
    singularity_cache.clear()
    calls = [0]
    real = jacobian.singularity_measures

    def counting(model: Any, q: Any) -> Any:
        calls[0] += 1
        return real(model, q)

    monkeypatch.setattr(jacobian, "singularity_measures", counting)
    q = _joints(MODELS[0], 1, 30)
    for _ in range(3):
        singularity_cache.singularity_measures(MODELS[0], q.copy())
    assert calls[0] == 1
    singularity_cache.singularity_measures(closed_form_model(ROBOTS[sorted(ROBOTS)[0]]), q)
    assert calls[0] == 1  # an equal model (another object) is the same question


def test_a_key_that_forgets_the_joints_values_is_caught(
        monkeypatch: pytest.MonkeyPatch) -> None:
    singularity_cache.clear()
    real = singularity_cache.measures_key
    monkeypatch.setattr(singularity_cache, "measures_key",
                        lambda model, q: real(model, np.zeros_like(q)))
    model = MODELS[0]
    singularity_cache.singularity_measures(model, _joints(model, 1, 10))
    q = _joints(model, 2, 10)
    assert not _same(singularity_cache.singularity_measures(model, q),
                     jacobian.singularity_measures(model, q))
    singularity_cache.clear()
