"""One sweep variant evaluated: what a worker process, a Ray task or a Warp batch runs.

:func:`evaluate_variant` and :func:`evaluate_batch` are module-level (worker processes and Ray
tasks import them by name): ``cellsim size`` and :func:`sim.sweep` give them to
:func:`sim.pipeline.sweep.run_sweep`, which calls them for each
:class:`~sim.pipeline.sweep.Variant`.
"""

from __future__ import annotations

from typing import Any

from sim.pipeline.sweep.variants import Variant


def evaluate_variant(variant: Variant, selection: Any = None, keep_runs: bool = False,
                     plots: bool = False) -> Any:
    """Run one sweep variant (module level, so worker processes and Ray tasks can import it).

    Metrics only by default: the run is evaluated in memory and a
    :class:`~sim.pipeline.sweep.VariantMetrics` (the variant's rows of the table) comes back.
    With ``keep_runs`` the variant's run folder is also written (``variant.run_dir``; its rows
    still come from every sample in memory). ``selection`` is the actuator selection's
    settings with the catalogue loaded (:func:`sim.pipeline.run.selection_options`, once for
    the whole sweep), or None.

    A variant faster or heavier than the robot allows is still simulated (speed and
    acceleration limits are not enforced): it stays in the tables with negative margins and a
    failed verdict instead of being dropped.
    """
    from sim.pipeline.run import RunOptions, evaluate_scenarios, run_and_write
    from sim.pipeline.sweep.reuse import collide_hook

    scenario = _variant_scenario(variant)
    if keep_runs:
        ev = run_and_write(scenario, RunOptions(out_dir=variant.run_dir, video=False,
                                                plots=plots, progress=False,
                                                selection=selection))
        return _metrics(variant, ev, run_dir=str(variant.run_dir))
    # metrics only: the plan and its reference scan are reused by the variants of one plan
    # (sim.pipeline.sweep.reuse; the same rows, no clearance)
    return _metrics(variant, evaluate_scenarios([scenario], RunOptions(
        video=False, plots=False, progress=False, selection=selection),
        collide=collide_hook())[0])


def _variant_scenario(variant: Variant) -> Any:
    import dataclasses

    from sim.scenario import Scenario, load_scenario

    base = variant.scenario if isinstance(variant.scenario, Scenario) \
        else load_scenario(variant.scenario)
    scenario = base.scaled(variant.speed_scale, variant.payload_kg)
    return dataclasses.replace(scenario, simulation=scenario.simulation.model_copy(
        update={"enforce_speed_limits": False, "enforce_accel_limits": False}))


def _metrics(variant: Variant, ev: Any, run_dir: str | None = None) -> Any:
    from sim.pipeline.sweep.variants import VariantMetrics, failed_checks_text, rows_from

    sized = ({j["joint"]: j for j in ev.sizing.to_dict()["joints"]}
             if ev.sizing is not None else {})
    # the sizing's statistics of the same arrays (the same values, not computed again)
    stats = ({j.joint: j.stats for j in ev.sizing.joints} if ev.sizing is not None else None)
    rows = rows_from(variant, ev.record.arrays, ev.summary["joints"], ev.summary["verdict"],
                     sized, run_dir or "", stats=stats, failed=failed_checks_text(ev.summary))
    return VariantMetrics(tuple(rows), ev.selection.to_dict() if ev.selection else None,
                          timings_s=dict(ev.summary.get("timings_s", {})), run_dir=run_dir)


def evaluate_batch(variants: list[Variant], selection: Any = None) -> list[Any]:
    """Every variant at once on MuJoCo Warp (``--backend warp``): planned one by one, simulated
    as batches of one model structure, then checked and sized one by one; metrics only.
    ``selection`` as for :func:`evaluate_variant`."""
    from sim.pipeline.run import RunOptions, evaluate_scenarios

    # speed-major: the variants of one speed scale follow each other, so each plan is made
    # once and reused for every payload
    order = sorted(range(len(variants)),
                   key=lambda i: (variants[i].speed_scale, variants[i].payload_kg))
    scenarios = [_variant_scenario(variants[i]) for i in order]
    evaluations = evaluate_scenarios(scenarios, RunOptions(
        video=False, plots=False, progress=False, selection=selection, backend="warp"),
        labels=[variants[i].label for i in order])
    out: list[Any] = [None] * len(variants)
    for i, ev in zip(order, evaluations, strict=True):
        out[i] = _metrics(variants[i], ev)
    return out
