"""Compiled cells kept for the variants of a sweep that differ only in payload and speed.

A sweep's metrics-only variants share their cell but for the payload at the tcp (a speed
scale changes the motion, not the cell): a
body ``robot/payload`` with a lumped mass, its inertia and a marker sphere
(:func:`sim.cells.compose.prepare_robot`). Composing the cell with ``dm_control`` and writing
its MJCF costs more than compiling it, so :func:`build_reusing` keeps, per scenario without its
payload, the cell once composed and its ``mujoco.MjSpec``; another payload only sets the
payload's mass, inertia and marker radius in that spec and compiles it again. The compiler does
the rest (subtree masses, the inertia-derived constants, bounding volumes, statistics), so the
model equals a fresh :func:`~sim.simulation.compile.build` of the scenario bit for bit, and
``MjSpec.to_xml`` writes what ``mj_saveLastXML`` writes (both checked by
``tests/simulation/test_build_cache_payload.py``).

Every cell has the payload body (massless at 0 kg), so 0 kg shares the cell too. Kept only for
cells without mechanisms (their servo gains are tuned on the compiled model, payload included);
every other scenario is built in full. The kept cell's ``mjcf`` tree is shared by the cells
built from it: its payload elements are set to the payload of the latest one.
"""

from __future__ import annotations

import dataclasses
import hashlib
import pickle
from dataclasses import dataclass
from typing import Any

from sim.errors import InternalError
from sim.scenario import Scenario
from sim.simulation.compile import BuiltCell, assemble, compile_composed, compose

#: The payload body's (and its marker geom's) name in a composed cell.
PAYLOAD = "robot/payload"
#: How many composed cells a process keeps.
KEPT = 4


@dataclass
class _Kept:
    """A composed cell kept for other payloads: its spec (payload fields set per use)."""

    composed: Any  # ComposedCell
    spec: Any  # mujoco.MjSpec of composed.xml


_CELLS: dict[str, _Kept] = {}


def cell_key(scenario: Scenario) -> str | None:
    """What a cell depends on but for the payload: the scenario without it and without its
    (and its partners') phases and actions, which a speed scale changes and the cell does not
    read (:meth:`~sim.scenario.Scenario.scaled`); None when it cannot be fingerprinted (then it
    is built in full)."""
    try:
        blob = pickle.dumps(dataclasses.replace(
            scenario, payload_kg=0.0, phases=(), actions=(),
            partners=tuple(dataclasses.replace(w, phases=(), actions=())
                           for w in scenario.partners)))
    except Exception:  # noqa: BLE001 - an unpicklable scenario is built every time
        return None
    return hashlib.sha256(blob).hexdigest()


def build_reusing(scenario: Scenario) -> BuiltCell:
    """:func:`~sim.simulation.compile.build`, reusing a cell composed in this process for the
    same scenario with another payload (the same model, bit for bit)."""
    key = cell_key(scenario)
    kept = _CELLS.get(key) if key is not None else None
    if kept is None:
        return _build_and_keep(scenario, key)
    return _with_payload(scenario, kept)


def clear() -> None:
    """Forget every kept cell."""
    _CELLS.clear()


def _build_and_keep(scenario: Scenario, key: str | None) -> BuiltCell:
    import mujoco

    composed = compose(scenario)
    model, saved_xml = compile_composed(composed)
    built = assemble(scenario, composed.cell, model, saved_xml, composed.sensors)
    if key is not None and not composed.cell.mechanisms:
        _CELLS[key] = _Kept(composed, mujoco.MjSpec.from_string(composed.xml,
                                                                assets=composed.assets))
        while len(_CELLS) > KEPT:
            _CELLS.pop(next(iter(_CELLS)))
    return built


def _with_payload(scenario: Scenario, kept: _Kept) -> BuiltCell:
    """The kept cell with the scenario's payload: the spec's payload fields set (as
    :func:`sim.cells.compose.prepare_robot` writes them) and compiled again."""
    from sim.cells.payload import payload_inertia, payload_marker

    mass = float(scenario.payload_kg)
    (radius, rgba), inertia = payload_marker(mass), payload_inertia(mass)
    _set_payload(kept, mass, inertia, radius, rgba)
    try:
        model = kept.spec.compile()
    except ValueError as exc:  # a bug in a cell builder, not a user mistake
        raise InternalError(f"cell {kept.composed.cell.name!r} does not compile: {exc}") \
            from exc
    def saved_xml() -> str:
        # when first asked for (a metrics-only variant never asks): the spec's payload set
        # back to this one's first (a later variant may have set its own since), the same
        # text as written right after this compile (tests/simulation/test_build_cache.py)
        _set_payload(kept, mass, inertia, radius, rgba)
        return str(kept.spec.to_xml())

    cell = kept.composed.cell
    root = cell.mjcf  # the shared tree follows the latest payload
    el_body, el_geom = root.find("body", PAYLOAD), root.find("geom", PAYLOAD)
    el_body.inertial.mass = mass
    el_body.inertial.diaginertia = [inertia] * 3
    el_geom.size = [radius]
    el_geom.rgba = list(rgba)
    rig = cell._rig
    cell = dataclasses.replace(
        cell, payload_kg=mass,
        _rig=None if rig is None else dataclasses.replace(rig, payload_kg=mass))
    return assemble(scenario, cell, model, saved_xml, kept.composed.sensors)


def _set_payload(kept: _Kept, mass: float, inertia: float, radius: float,
                 rgba: tuple[float, ...]) -> None:
    """The payload's mass, principal moments, marker radius and colour in the kept spec."""
    body, geom = kept.spec.body(PAYLOAD), kept.spec.geom(PAYLOAD)
    if body is None or geom is None:
        raise InternalError(f"kept cell {kept.composed.cell.name!r} has no {PAYLOAD!r}")
    body.mass = mass
    body.inertia = [inertia] * 3
    geom.size = [radius, 0.0, 0.0]
    geom.rgba = list(rgba)


__all__ = ["KEPT", "PAYLOAD", "build_reusing", "cell_key", "clear"]
