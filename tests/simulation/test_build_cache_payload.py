"""A sweep's variants that differ only in payload and speed scale reuse one composed cell (issue
29: :mod:`sim.simulation.build_cache`). Specification: whatever payloads and speeds were built
before, the cell built for a variant is the one a fresh :func:`sim.simulation.compile.build` of
that scenario gives, bit for bit: every ``MjModel`` array and scalar (the model's binary MJB
image, and each array named, for a readable failure), the saved MJCF, every id and the Cartesian
context; the cell says the new payload. A payload of 0 kg (a massless payload body, its marker
invisible) shares the cell of the other payloads; a cell with mechanisms (gains tuned on the
compiled model) is built in full. The oracle is a fresh build; a planted patch that forgets the
payload's inertia, its marker's radius or its marker's colour is caught."""

from __future__ import annotations

import dataclasses
from typing import Any

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.sweeps import count_composes

from sim.core.resources import shipped_scenarios
from sim.scenario import load_scenario
from sim.simulation import build_cache
from sim.simulation.compile import BuiltCell, build

WELD = "lrmate200ic_weld_plate"


def _mjb(model: Any) -> bytes:
    buf = np.zeros(mujoco.mj_sizeModel(model), np.uint8)
    mujoco.mj_saveModel(model, None, buf)
    return buf.tobytes()


def _fields(model: Any) -> dict[str, bytes]:
    """Every array of the model and every scalar or array of its option, statistic and visual
    structs, as raw bytes (so -0.0, NaN payloads and dtypes count)."""
    out: dict[str, bytes] = {}
    for name in dir(model):
        value = getattr(model, name, None) if not name.startswith("_") else None
        if isinstance(value, np.ndarray):
            out[name] = repr((value.dtype, value.shape)).encode() + value.tobytes()
    for struct in ("opt", "stat", "vis"):
        obj = getattr(model, struct)
        stack: list[tuple[str, Any]] = [(struct, obj)]
        while stack:
            prefix, o = stack.pop()
            for name in dir(o):
                if name.startswith("_"):
                    continue
                value = getattr(o, name)
                if isinstance(value, (int, float, np.ndarray)):
                    out[f"{prefix}.{name}"] = np.asarray(value).tobytes()
                elif struct == "vis" and not callable(value):
                    stack.append((f"{prefix}.{name}", value))
    return out


def model_differences(a: Any, b: Any) -> list[str]:
    """The names of the fields in which two models differ (``mjb`` if only the image does)."""
    fa, fb = _fields(a), _fields(b)
    names = sorted(k for k in fa.keys() | fb.keys() if fa.get(k) != fb.get(k))
    if not names and _mjb(a) != _mjb(b):
        names = ["mjb"]
    return names


def built_differences(got: BuiltCell, want: BuiltCell) -> list[str]:
    """Where two built cells differ: the model's fields, the saved MJCF, the ids, the sensors'
    slices, the Cartesian context's numbers and the cell's payload."""
    out = model_differences(got.model, want.model)
    if got.xml != want.xml:
        out.append("xml")
    for f in dataclasses.fields(BuiltCell):
        g, w = getattr(got, f.name), getattr(want, f.name)
        if isinstance(w, np.ndarray) and (g.dtype != w.dtype or not np.array_equal(g, w)):
            out.append(f.name)
        elif isinstance(w, (int, dict, type(None))) and f.name != "partner_cols" and g != w:
            out.append(f.name)
    gc, wc = got.context, want.context
    for name in ("flange_to_tcp", "world_from_frame0", "home_q"):
        if not np.array_equal(getattr(gc, name), getattr(wc, name)):
            out.append(f"context.{name}")
    if not np.array_equal(gc.kinematics.tcp_offset, wc.kinematics.tcp_offset) \
            or gc.kinematics.family != wc.kinematics.family:
        out.append("context.kinematics")
    if got.cell.payload_kg != want.cell.payload_kg:
        out.append("cell.payload_kg")
    if got.cell._rig is not None and want.cell._rig is not None \
            and got.cell._rig.payload_kg != want.cell._rig.payload_kg:
        out.append("cell._rig.payload_kg")
    return out


def _with(scenario: Any, payload: float) -> Any:
    return dataclasses.replace(scenario, payload_kg=payload)


@pytest.fixture(scope="module")
def weld() -> Any:
    return load_scenario(WELD)


@pytest.fixture
def composed_count(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """How many cells :mod:`build_cache` composed (a reused cell composes none)."""
    return count_composes(monkeypatch)


@settings(max_examples=4, deadline=None, derandomize=True, database=None)
@given(payloads=st.lists(st.one_of(st.just(0.0),
                                   st.floats(min_value=1e-3, max_value=40.0, allow_nan=False)),
                         min_size=1, max_size=2),
       scales=st.lists(st.floats(min_value=0.2, max_value=3.0), min_size=1, max_size=2))
def test_reused_cell_equals_a_fresh_build(weld: Any, payloads: list[float],
                                          scales: list[float]) -> None:
    build_cache.clear()
    build_cache.build_reusing(_with(weld, 2.0))
    for p, s in zip(payloads, scales * 2, strict=False):  # one kept cell, payload set again
        variant = weld.scaled(s, p)
        got = build_cache.build_reusing(variant)
        assert built_differences(got, build(variant)) == []


def test_a_cells_mjcf_asked_for_after_later_variants_is_its_own(weld: Any) -> None:
    # a reused cell writes its MJCF when first asked for (a metrics-only variant never asks),
    # from the kept spec that later variants have set to their own payloads since
    build_cache.clear()
    build_cache.build_reusing(_with(weld, 2.0))
    got = {p: build_cache.build_reusing(_with(weld, p)) for p in (0.0, 4.5, 1.25)}
    for p in (4.5, 0.0, 1.25, 4.5):
        want = build(_with(weld, p))
        assert got[p].xml == want.xml
        assert mujoco.MjModel.from_xml_string(got[p].xml).body(build_cache.PAYLOAD).mass[0] == p
    build_cache.clear()


def test_the_cell_is_composed_once_per_scenario(weld: Any, composed_count: list[int]) -> None:
    first = build_cache.build_reusing(_with(weld, 1.0))
    second = build_cache.build_reusing(_with(weld, 5.0))
    build_cache.build_reusing(weld.scaled(0.6, 3.0))  # another speed: the same cell
    assert composed_count[0] == 1
    assert second.model.body(build_cache.PAYLOAD).mass[0] == 5.0
    assert first.model is not second.model
    # the earlier cell keeps its own model
    assert first.model.body(build_cache.PAYLOAD).mass[0] == 1.0
    # another scenario (its own cell key) is composed again
    build_cache.build_reusing(dataclasses.replace(_with(weld, 1.0), name="other"))
    assert composed_count[0] == 2
    finer = weld.simulation.model_copy(update={"timestep_s": 0.0005})
    build_cache.build_reusing(dataclasses.replace(weld, simulation=finer, payload_kg=1.0))
    assert composed_count[0] == 3  # another timestep: another cell


def test_zero_payload_shares_the_cell_and_mechanisms_are_built_in_full(
        weld: Any, composed_count: list[int]) -> None:
    assert build_cache.cell_key(_with(weld, 0.0)) == build_cache.cell_key(_with(weld, 3.0))
    build_cache.build_reusing(_with(weld, 3.0))
    for _ in range(2):
        got = build_cache.build_reusing(_with(weld, 0.0))
    assert composed_count[0] == 1
    assert built_differences(got, build(_with(weld, 0.0))) == []
    assert got.model.body(build_cache.PAYLOAD).mass[0] == 0.0
    assert got.model.geom(build_cache.PAYLOAD).rgba[3] == 0.0  # no marker drawn
    again = build_cache.build_reusing(_with(weld, 3.0))  # and back: the marker shows again
    assert built_differences(again, build(_with(weld, 3.0))) == []
    assert composed_count[0] == 1
    track = _with(load_scenario("track_beam_weld"), 1.0)
    build_cache.build_reusing(track)
    build_cache.build_reusing(_with(track, 2.0))
    assert composed_count[0] == 3  # the track's cell, composed for each payload


@pytest.mark.parametrize(("fault", "field", "to_payload"), [
    ("inertia", "body_inertia", 3.0), ("radius", "geom_size", 3.0), ("colour", "geom_rgba", 0.0)])
def test_a_patch_that_forgets_a_field_is_caught(weld: Any, fault: str, field: str,
                                                to_payload: float,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    real = build_cache._set_payload

    def forgetful(kept: Any, mass: float, inertia: float, radius: float,
                  rgba: tuple[float, ...]) -> None:
        body, geom = kept.spec.body(build_cache.PAYLOAD), kept.spec.geom(build_cache.PAYLOAD)
        old = {"inertia": body.inertia.copy(), "radius": geom.size.copy(),
               "colour": geom.rgba.copy()}
        real(kept, mass, inertia, radius, rgba)
        if fault == "inertia":
            body.inertia = old[fault]
        elif fault == "radius":
            geom.size = old[fault]
        else:
            geom.rgba = old[fault]

    build_cache.clear()
    build_cache.build_reusing(_with(weld, 1.0))
    monkeypatch.setattr(build_cache, "_set_payload", forgetful)
    got = build_cache.build_reusing(_with(weld, to_payload))
    found = built_differences(got, build(_with(weld, to_payload)))
    assert field in found
    assert "xml" in found
    build_cache.clear()


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(shipped_scenarios()))
def test_every_shipped_scenario_reuses_its_cell_bit_for_bit(name: str) -> None:
    scenario = load_scenario(name)
    build_cache.clear()
    build_cache.build_reusing(_with(scenario, 1.5))
    for p in (4.0, 0.25):
        got = build_cache.build_reusing(_with(scenario, p))
        assert built_differences(got, build(_with(scenario, p))) == []
    build_cache.clear()
