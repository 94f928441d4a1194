"""A sweep's variants reuse what does not change between the variants of one plan (issue 29):
the plan (by the scenario without its payload) and the reference's collision scan
(:mod:`sim.simulation.collision_reuse`), so that only what the simulated motion changes is
checked again. Specification: the sweep's rows are those of each variant evaluated alone, with
nothing cached, bit for bit; a variant whose SIMULATED motion fails (a motor past its rating, a
collision the reference does not have) is reported as failing although it reused its plan.

The scenario: the LR Mate 200iC/5L on the weld table, its torch passing 57 mm above the base
plate (a clearance, no collision) in 1.2 s; payloads 1 kg and 40 kg (beyond the rating, j3's and
j5's motors past their RMS torque: checks of the simulated motion fail); speed scales 0.8 and 1
(two plans).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.sweeps import rows_text, short_weld_scenario

from sim.pipeline import run as run_module
from sim.pipeline.run import RunOptions, add_collisions, evaluate_scenarios
from sim.pipeline.sweep import Variant, reuse, run_sweep, task_groups
from sim.pipeline.sweep.evaluation import _variant_scenario, evaluate_variant
from sim.simulation import collision_reuse

PAYLOADS = [1.0, 40.0]
SPEEDS = [0.8, 1.0]


@pytest.fixture
def scenario(tmp_path: Path) -> Path:
    return short_weld_scenario(tmp_path)


@pytest.fixture(autouse=True)
def fresh(monkeypatch: pytest.MonkeyPatch):
    """Nothing cached from another test, and the reuse on."""
    run_module._PLANS.clear()
    collision_reuse.clear_cache()
    monkeypatch.setattr(reuse, "ENABLED", True)
    yield
    run_module._PLANS.clear()
    collision_reuse.clear_cache()


def _alone(scenario: Path, monkeypatch: pytest.MonkeyPatch) -> dict[tuple[float, float], list]:
    """Each variant evaluated on its own: no plan and no scan kept, checked as a run is."""
    out = {}
    with monkeypatch.context() as m:
        m.setattr(reuse, "ENABLED", False)
        for p in PAYLOADS:
            for s in SPEEDS:
                run_module._PLANS.clear()
                collision_reuse.clear_cache()
                out[(p, s)] = rows_text(list(evaluate_variant(Variant(p, s, scenario)).rows))
    run_module._PLANS.clear()
    collision_reuse.clear_cache()
    return out


def _mismatches(scenario: Path, tmp_path: Path, alone: dict) -> list[tuple[float, float]]:
    """The variants whose rows in a sweep with the reuse differ from their rows alone."""
    res = run_sweep(scenario, PAYLOADS, SPEEDS, evaluate_variant, workers=1,
                    out_dir=tmp_path / "sweep", progress=False, write=False,
                    raise_on_failure=False)
    assert not res.failures, [o.error for o in res.failures]
    return [(o.variant.payload_kg, o.variant.speed_scale) for o in res.outcomes
            if rows_text(list(o.rows)) != alone[(o.variant.payload_kg, o.variant.speed_scale)]]


def test_a_sweep_reusing_its_plans_gives_each_variant_s_rows_alone(scenario, tmp_path,
                                                                    monkeypatch):
    alone = _alone(scenario, monkeypatch)
    # the heavy variants fail in their simulated motion (the motors' RMS torque), the light pass
    verdicts = {k: {json.loads(r)["verdict"] for r in v} for k, v in alone.items()}
    assert verdicts == {(p, s): {"'pass'" if p == 1.0 else "'fail'"} for p, s in alone}
    assert _mismatches(scenario, tmp_path, alone) == []
    # it did reuse: one reference scan per plan (the payloads share the geometry), found by
    # the other variant of each plan (a 40 kg variant strays from its reference by more than
    # the scan can bound, and is checked in full: the same rows all the same)
    stats = collision_reuse.STATS
    assert (stats["scans"], stats["hits"]) == (len(SPEEDS), len(SPEEDS)) and stats["full"] <= 2

    # planted fault: a plan kept by a key that ignores the speed scale (the scenario's name)
    run_module._PLANS.clear()
    collision_reuse.clear_cache()
    monkeypatch.setattr(run_module, "_plan_key", lambda sc: sc.name)
    assert _mismatches(scenario, tmp_path, alone), "the equality check missed a wrong plan key"


def test_a_collision_of_the_simulated_motion_only_is_reported(scenario, monkeypatch):
    """The reference and the simulated motion pass 57 mm above the plate; the same motion
    offset by -0.2 rad on j2 (a constant offset: the motion bounds inside each interval stay
    small, only the distance to the reference grows) drives the torch into the plate and the
    table. Checked with the reference's scan (cached by the variant evaluated first), the
    collisions are exactly the full check's."""
    base = Variant(1.0, 1.0, scenario)
    evaluate_variant(base)  # the plan and its reference scan, kept
    sc = _variant_scenario(base)
    (ev,) = evaluate_scenarios([sc], RunOptions(video=False, plots=False, progress=False),
                               collide=reuse.reuse_collisions)
    _, motion, _ = run_module._prepare(sc, RunOptions(video=False, plots=False, progress=False),
                                       run_module.Stages(enabled=False), reuse_plan=True)
    arrays = dict(ev.record.arrays)
    qpos = arrays["qpos"].copy()
    qpos[:, ev.built.robot_qpos[1]] -= 0.2
    arrays["qpos"] = qpos
    full: dict = {}
    add_collisions(full, ev.built, motion, arrays)
    assert {tuple(c["bodies"]) for c in full["collisions"]} == {
        ("robot/tool/torch", "base_plate"), ("robot/tool/torch", "table_top")}
    reused: dict = {}
    hits = collision_reuse.STATS["hits"]
    reuse.reuse_collisions(reused, ev.built, motion, arrays)
    assert collision_reuse.STATS["hits"] > hits  # the reference scan was reused
    assert reused["collisions"] == full["collisions"]
    assert reused["allowed_contacts"] == full["allowed_contacts"]

    # planted fault: the distance to the reference ignored; the offset motion is then taken
    # for the reference and its collisions are missed
    monkeypatch.setattr(collision_reuse, "deviation",
                        lambda cm, q, r: np.zeros(q.shape[0]))
    planted: dict = {}
    reuse.reuse_collisions(planted, ev.built, motion, arrays)
    assert planted["collisions"] == [] != full["collisions"]


@pytest.mark.slow
def test_a_pool_sweep_reusing_its_plans_gives_each_variant_s_rows_alone(scenario, tmp_path,
                                                                         monkeypatch):
    """The same on two warmed pool workers (each keeps its own plans and scans)."""
    alone = _alone(scenario, monkeypatch)
    res = run_sweep(scenario, PAYLOADS, SPEEDS, evaluate_variant, workers=2,
                    out_dir=tmp_path / "sweep", progress=False, write=False,
                    raise_on_failure=False)
    assert not res.failures
    assert {(o.variant.payload_kg, o.variant.speed_scale): rows_text(list(o.rows))
            for o in res.outcomes} == alone


@settings(max_examples=60, deadline=None)
@given(n_payloads=st.integers(1, 7), n_speeds=st.integers(1, 9), workers=st.integers(1, 5),
       order=st.sampled_from(["ascending", "descending", "shuffled"]), seed=st.integers(0, 99))
def test_tasks_keep_a_plan_s_variants_together_and_balance_the_workers(n_payloads, n_speeds,
                                                                        workers, order, seed):
    """Every variant (the sweep's payload-major order) in exactly one task, the tasks one
    after the other in speed-major order, the slowest speed scale first whatever the order
    they were given in (the longest cycles first); a speed scale per task when there are at
    least two per worker, else 2 x workers tasks of sizes that differ by one at most."""
    speeds = [0.5 + 0.05 * s for s in range(n_speeds)]
    given_order = {"ascending": speeds, "descending": speeds[::-1],
                   "shuffled": [speeds[i] for i in np.random.default_rng(seed).permutation(
                       n_speeds)]}[order]
    variants = [Variant(float(p), given_order[s], "x", index=p * n_speeds + s)
                for p in range(n_payloads) for s in range(n_speeds)]
    groups = task_groups(variants, workers)
    flat = [v.index for g in groups for v in g]
    position = {x: s for s, x in enumerate(given_order)}
    assert flat == [p * n_speeds + position[x] for x in speeds for p in range(n_payloads)]
    if n_speeds >= 2 * workers:
        assert [{v.speed_scale for v in g} for g in groups] == [{x} for x in speeds]
    else:
        sizes = [len(g) for g in groups]
        assert len(groups) == min(2 * workers, len(variants))
        assert max(sizes) - min(sizes) <= 1
