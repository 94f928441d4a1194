"""What a script calls: evaluate a scenario in memory, run it into a folder, sweep it.

Each function takes a loaded :class:`~sim.scenario.Scenario` (or a scenario file's path, or a
shipped scenario's name) and gives typed results (:class:`~sim.api.results.RunResult`). A
user mistake raises a :class:`~sim.errors.CellsimError` subclass whose message is the one line
``cellsim`` would print; a physically impossible run (a collision, a saturated drive, a joint
past a limit) is not an exception but a ``"fail"`` verdict with its failed checks.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from sim.api.results import RunResult
from sim.core.arguments import (
    choice_argument,
    count_argument,
    flag_argument,
    got,
    optional_path_argument,
)
from sim.errors import UsageError
from sim.pipeline.options import BACKENDS, changed_options
from sim.pipeline.run import RunOptions, evaluate_scenario, run_and_write, selection_options
from sim.pipeline.sweep import SweepResult, run_sweep, validate_payloads, validate_speed_scales
from sim.pipeline.sweep.engines import ENGINES
from sim.scenario import Scenario, load_scenario

ScenarioLike = Scenario | str | os.PathLike[str]


def _scenario(scenario: ScenarioLike) -> Scenario:
    """A scenario, loaded where it is a path or a name (anything else: one line naming
    ``scenario``, :func:`~sim.scenario.load_scenario`)."""
    return scenario if isinstance(scenario, Scenario) else load_scenario(scenario)


def _options(options: Any, default: RunOptions) -> RunOptions:
    if options is None:
        return default
    if not isinstance(options, RunOptions):
        raise UsageError(f"options: expected sim.RunOptions(...) or None, got {got(options)}",
                         key="options")
    return options


def _selecting(options: RunOptions, scenario: Scenario) -> RunOptions:
    """``options`` with its selection resolved as ``cellsim run`` resolves it: None follows
    the scenario's ``[sizing] select``; True selects from the scenario's catalogue (or the
    starter), a path from that catalogue (loaded here: a bad one is one line before anything
    runs); False never selects."""
    import dataclasses

    sel = options.selection
    if sel is None:
        sel = bool(scenario.sizing.select)
    if sel is False:
        loaded = None
    elif sel is True:
        loaded = selection_options(scenario)
    elif isinstance(sel, (str, os.PathLike)):
        loaded = selection_options(scenario, catalog=Path(sel))
    else:
        return options  # the loaded settings
    return dataclasses.replace(options, selection=loaded)


def evaluate(scenario: ScenarioLike, options: RunOptions | None = None) -> RunResult:
    """Simulate, check and size a scenario in memory; nothing is written.

    Args:
        scenario: A scenario (e.g. ``load_scenario(...).scaled(payload_kg=2.5)``), a scenario
            file's path or a shipped scenario's name.
        options: Run options; only ``feedforward``, ``sizing``, ``selection``, ``backend`` and
            ``progress`` matter here (default: sizing on, no progress bars).

    Returns:
        The result, with every simulated sample in :attr:`RunResult.arrays`.

    Raises:
        CellsimError: A user mistake (bad file, unreachable target, unstable simulation).
    """
    options = _options(options, RunOptions(video=False, plots=False, progress=False))
    loaded = _scenario(scenario)
    return RunResult.from_evaluation(evaluate_scenario(loaded, _selecting(options, loaded)))


def run(scenario: ScenarioLike, options: RunOptions | None = None, **changes: Any) -> RunResult:
    """Run a scenario and write its run folder, as ``cellsim run`` does.

    Args:
        scenario: As for :func:`evaluate`.
        options: Run options (default :class:`RunOptions`: video, plots and sizing report into
            ``runs/<scenario name>``, no progress bars here).
        **changes: Fields of :class:`RunOptions` to change (``out_dir=...``, ``video=False``).
            The video sets up OpenGL (EGL or OSMesa) itself.

    Returns:
        The result; :attr:`RunResult.path` is the run folder.

    Raises:
        CellsimError: A user mistake, or no working OpenGL backend for a video.
    """
    options = changed_options(_options(options, RunOptions(progress=False)), changes)
    loaded = _scenario(scenario)
    options = _selecting(options, loaded)
    if options.video:
        from sim.render.gl import configure_gl

        configure_gl(options.video_args.get("gl"))  # a backend that works, or one line
    evaluation = run_and_write(loaded, options)
    out_dir = Path(options.out_dir) if options.out_dir else Path("runs") / loaded.name
    return RunResult.from_evaluation(evaluation, path=out_dir)


def sweep(scenario: ScenarioLike, payloads_kg: Sequence[float] | None = None,
          speed_scales: Sequence[float] = (1.0,), *, out_dir: str | Path | None = None,
          workers: int = 1, keep_runs: bool = False, select: bool = False,
          engine: str = "pool", backend: str = "mujoco", progress: bool = False
          ) -> SweepResult:
    """Evaluate every (payload, speed scale) variant of a scenario and tabulate them, as
    ``cellsim size`` does: ``sweep.csv``, ``sweep.md``, ``sweep.json`` and ``sweep.svg`` in
    ``out_dir`` (default ``runs/<scenario name>_sweep``).

    Args:
        scenario: As for :func:`evaluate`.
        payloads_kg: Payloads, kg (default: the scenario's); one number is a list of one.
        speed_scales: Speed factors (> 0; 2 runs the cycle twice as fast); one number is a
            list of one.
        workers: Worker processes (1: in this process).
        keep_runs: Also write each variant's run folder.
        select: Choose a motor and a reducer per joint from the scenario's catalogue.
        engine: ``"pool"`` or ``"ray"``.
        backend: ``"mujoco"`` or ``"warp"`` (MuJoCo Warp batches; metrics only).
        progress: Show a progress bar.

    Returns:
        The sweep's result: :attr:`SweepResult.rows` (one per variant and joint),
        :attr:`SweepResult.failures`.

    Raises:
        SweepError: A variant failed (the table of the others is written first).
        CellsimError: Bad payloads or speed scales, or a bad scenario.
    """
    import functools

    from sim.pipeline.sweep.evaluation import evaluate_batch, evaluate_variant

    loaded = _scenario(scenario)
    out_dir = optional_path_argument(out_dir, "out_dir")
    workers = count_argument(workers, "workers")
    for name, flag in (("keep_runs", keep_runs), ("select", select), ("progress", progress)):
        flag_argument(flag, name)
    choice_argument(engine, "engine", ENGINES)
    choice_argument(backend, "backend", BACKENDS)
    payloads = validate_payloads(payloads_kg if payloads_kg is not None
                                 else [loaded.payload_kg], field="payloads_kg")
    scales = validate_speed_scales(speed_scales, field="speed_scales")
    selection = selection_options(loaded) if select or loaded.sizing.select else None
    batch = functools.partial(evaluate_batch, selection=selection) if backend == "warp" else None
    return run_sweep(loaded, payloads, scales,
                     functools.partial(evaluate_variant, selection=selection, keep_runs=keep_runs),
                     workers=min(workers, len(payloads) * len(scales)),
                     out_dir=out_dir or Path("runs") / f"{loaded.name}_sweep",
                     progress=progress, engine=engine, batch=batch)
