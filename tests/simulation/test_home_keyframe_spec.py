"""The cell's ``home`` keyframe added to the world, compiled once (issue 29: the world's MJCF
is written and parsed once, and not compiled again with the keyframe). Specification:
:func:`sim.cells.compose.add_home_keyframe` returns a model and the home ``qpos`` on which a
mechanism's gains are tuned as on the world compiled afresh with its keyframe: the keyframe's
``qpos`` bit for bit, and at it the same joint-space inertia (what
:func:`sim.cells.mechanisms.tune_gains` reads), bit for bit. The oracle compiles the world's
MJCF afresh and resets to its keyframe; a ``qpos`` one bit off is caught."""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np
import pytest

from sim.cells import builder
from sim.cells.compose import compile_model
from sim.core.resources import shipped_scenarios
from sim.scenario import load_scenario
from sim.simulation.compile import build


def _pairs(name: str, monkeypatch: pytest.MonkeyPatch) -> list[tuple[Any, Any, Any]]:
    """(returned model, returned qpos, the world compiled afresh) for each keyframe the
    scenario's cell adds."""
    pairs = []
    real = builder.add_home_keyframe

    def checked(world: Any, *args: Any) -> Any:
        model, qpos = real(world, *args)
        pairs.append((model, qpos.copy(), compile_model(world)))  # before any gain is tuned
        return model, qpos

    monkeypatch.setattr(builder, "add_home_keyframe", checked)
    build(load_scenario(name))
    return pairs


def _inertia(model: Any, qpos: Any = None) -> np.ndarray:
    """The joint-space inertia at ``qpos`` (None: at the model's first keyframe)."""
    data = mujoco.MjData(model)
    if qpos is None:
        mujoco.mj_resetDataKeyframe(model, data, 0)
    else:
        data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, M)
    return M


def _same_bits(a: Any, b: Any) -> bool:
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.int64), b.view(np.int64))


def _check(pairs: list[tuple[Any, Any, Any]]) -> None:
    assert pairs
    for model, qpos, want in pairs:
        assert want.nkey >= 1
        assert _same_bits(qpos, want.key_qpos[0])
        assert _same_bits(_inertia(model, qpos), _inertia(want))


@pytest.mark.parametrize("name", ["lrmate200ic_weld_plate", "positioner_cylinder_downhand"])
def test_gains_are_tuned_at_the_keyframe_of_the_world_compiled(
        name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    _check(_pairs(name, monkeypatch))


def test_a_home_qpos_one_bit_off_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    model, qpos, want = _pairs("lrmate200ic_weld_plate", monkeypatch)[0]
    qpos[0] = np.nextafter(qpos[0], np.inf)
    with pytest.raises(AssertionError):
        _check([(model, qpos, want)])


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(shipped_scenarios()))
def test_every_shipped_cell(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    _check(_pairs(name, monkeypatch))
