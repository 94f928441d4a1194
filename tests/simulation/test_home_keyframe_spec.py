"""The cell's ``home`` keyframe added to the world and to its ``MjSpec`` (issue 29: the world's
MJCF is written and parsed once where it was twice). Specification: the model
:func:`sim.cells.compose.add_home_keyframe` returns (what mechanisms' gains are tuned on) is
the model :func:`sim.cells.compose.compile_model` compiles from the world with its keyframe,
bit for bit (the binary MJB image). The oracle compiles the world's MJCF afresh; a keyframe
that differs in one bit is caught."""

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


def _mjb(model: Any) -> bytes:
    buf = np.zeros(mujoco.mj_sizeModel(model), np.uint8)
    mujoco.mj_saveModel(model, None, buf)
    return buf.tobytes()


def _pairs(name: str, monkeypatch: pytest.MonkeyPatch) -> list[tuple[Any, Any]]:
    """(returned model, the world compiled afresh) for each keyframe the scenario's cell adds."""
    pairs = []
    real = builder.add_home_keyframe

    def checked(world: Any, *args: Any) -> Any:
        got = real(world, *args)
        pairs.append((got, compile_model(world)))  # before any gain is tuned on it
        return got

    monkeypatch.setattr(builder, "add_home_keyframe", checked)
    build(load_scenario(name))
    return pairs


@pytest.mark.parametrize("name", ["lrmate200ic_weld_plate", "track_beam_weld"])
def test_the_keyframed_model_is_the_world_compiled(name: str,
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    pairs = _pairs(name, monkeypatch)
    assert pairs
    for got, want in pairs:
        assert got.nkey == want.nkey >= 1
        assert _mjb(got) == _mjb(want)


def test_a_keyframe_one_bit_off_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    got, want = _pairs("lrmate200ic_weld_plate", monkeypatch)[0]
    got.key_qpos[0, 0] = np.nextafter(got.key_qpos[0, 0], np.inf)
    assert _mjb(got) != _mjb(want)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(shipped_scenarios()))
def test_every_shipped_cell(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    for got, want in _pairs(name, monkeypatch):
        assert _mjb(got) == _mjb(want)
