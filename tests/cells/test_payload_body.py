"""Every robot of every cell carries a body ``<robot>/payload`` at its tcp, massless at 0 kg
(:func:`sim.cells.compose.prepare_robot`): one model structure for every payload, so a sweep's
0 kg variant shares the other payloads' cell and collision scan. Specification: at 0 kg the
body changes nothing a run computes. The oracle is the same compiled cell with the payload
bodies deleted (``MjSpec.delete``): on generated joint positions, velocities and accelerations
of every shipped scenario's cell, the inverse dynamics (``qfrc_inverse``), the forward
dynamics (``qacc``) and a few steps of the integrator agree bit for bit. A planted 1 g
payload is caught."""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sim.core.resources import shipped_scenarios
from sim.scenario import load_scenario
from sim.simulation.compile import ComposedCell, compose

SCENARIOS = sorted(shipped_scenarios())
_COMPOSED: dict[tuple[str, float], ComposedCell] = {}


def composed(name: str, payload_kg: float = 0.0) -> ComposedCell:
    """The scenario's cell at that payload as the runner composes it (its MJCF and assets,
    what :func:`sim.simulation.compile.compile_composed` compiles), once per test session."""
    key = (name, payload_kg)
    if key not in _COMPOSED:
        _COMPOSED[key] = compose(load_scenario(name).scaled(1.0, payload_kg))
    return _COMPOSED[key]


def compiled(c: ComposedCell, delete_payload: bool = False) -> Any:
    """The composed cell compiled from its spec; with every payload body deleted: the oracle,
    a cell without one."""
    spec = mujoco.MjSpec.from_string(c.xml, assets=c.assets)
    if delete_payload:
        for body in [b for b in spec.bodies if b.name.endswith("/payload")]:
            spec.delete(body)
    return spec.compile()


def payload_bodies(model: Any) -> list[str]:
    return [model.body(b).name for b in range(model.nbody)
            if model.body(b).name.endswith("/payload")]


def state(model: Any, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Joint positions inside each limited joint's range (else within +-pi), velocities and
    accelerations, drawn from ``seed``; free joints keep qpos0."""
    rng = np.random.default_rng(seed)
    qpos = model.qpos0.copy()
    for j in range(model.njnt):
        if model.jnt_type[j] not in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
            continue
        lo, hi = model.jnt_range[j] if model.jnt_limited[j] else (-np.pi, np.pi)
        qpos[model.jnt_qposadr[j]] = rng.uniform(lo, hi)
    return qpos, rng.normal(0.0, 1.0, model.nv), rng.normal(0.0, 3.0, model.nv)


def dynamics(model: Any, qpos: np.ndarray, qvel: np.ndarray, qacc: np.ndarray,
             ctrl: np.ndarray, steps: int = 3) -> dict[str, np.ndarray]:
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:], data.qacc[:] = qpos, qvel, qacc
    mujoco.mj_inverse(model, data)
    out = {"qfrc_inverse": data.qfrc_inverse.copy()}
    data.ctrl[:] = ctrl
    mujoco.mj_forward(model, data)
    out["qacc"] = data.qacc.copy()
    for _ in range(steps):
        mujoco.mj_step(model, data)
    out["qpos_after_steps"], out["qvel_after_steps"] = data.qpos.copy(), data.qvel.copy()
    return out


@pytest.mark.parametrize("name", SCENARIOS)
def test_every_robot_has_its_payload_body(name: str) -> None:
    c = composed(name)
    model = mujoco.MjModel.from_xml_string(c.xml, c.assets)  # as the runner compiles it
    bodies = payload_bodies(model)
    assert len(bodies) == 1 + len(c.cell.partners)
    for body in bodies:
        assert model.body(body).mass[0] == 0.0
        geom = model.geom(body)  # the marker, named as its body
        assert geom.rgba[3] == 0.0 and geom.contype[0] == geom.conaffinity[0] == 0
    # the oracle's own path (the spec compiled) gives the runner's model
    spec_model = compiled(c)
    qpos, qvel, qacc = state(model, 1)
    a = dynamics(model, qpos, qvel, qacc, np.zeros(model.nu))
    b = dynamics(spec_model, qpos, qvel, qacc, np.zeros(model.nu))
    assert all(a[k].tobytes() == b[k].tobytes() for k in a)


@pytest.mark.parametrize("name", SCENARIOS)
@settings(max_examples=3, deadline=None, derandomize=True, database=None)
@given(seed=st.integers(min_value=0, max_value=2**32 - 1))
def test_a_massless_payload_changes_no_dynamics(name: str, seed: int) -> None:
    c = composed(name)
    model, oracle = compiled(c), compiled(c, delete_payload=True)
    assert oracle.nbody == model.nbody - 1 - len(c.cell.partners)
    assert oracle.nv == model.nv and oracle.nu == model.nu
    qpos, qvel, qacc = state(model, seed)
    ctrl = np.array([qpos[model.jnt_qposadr[model.actuator_trnid[a, 0]]]
                     if model.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT else 0.0
                     for a in range(model.nu)])
    got = dynamics(model, qpos, qvel, qacc, ctrl)
    want = dynamics(oracle, qpos, qvel, qacc, ctrl)
    for key in want:
        assert got[key].tobytes() == want[key].tobytes(), (name, key)


def test_a_planted_gram_is_caught() -> None:
    """The oracle sees a payload: 1 g at the tcp changes the inverse dynamics."""
    name = "lrmate200ic_weld_plate"
    c = composed(name, 0.001)
    model, oracle = compiled(c), compiled(c, delete_payload=True)
    qpos, qvel, qacc = state(model, 7)
    got = dynamics(model, qpos, qvel, qacc, np.zeros(model.nu))
    want = dynamics(oracle, qpos, qvel, qacc, np.zeros(model.nu))
    assert got["qfrc_inverse"].tobytes() != want["qfrc_inverse"].tobytes()
