"""Parameter sweeps: the same cycle over payloads and speeds, run in parallel.

A sweep runs every combination of a list of payloads (kg) and a list of speed scales. A
*variant* is one ``(payload_kg, speed_scale)`` pair (:class:`Variant`, which also carries the
base scenario and a suggested run folder). The runner is any picklable callable (a module-level
function) ``runner(variant) -> run_dir`` that simulates the variant and returns the folder
holding its ``trajectory.npz`` (and ``summary.json``, ``sizing.json`` when it sized the run).

Speed scale ``s`` divides every knot time of the base scenario (``Scenario.scaled``):
``s = 2`` runs the cycle twice as fast (half the duration), so joint speeds scale by ``s``,
accelerations by ``s^2`` and the inertial part of the torques by ``s^2``; ``s = 0.5`` is half
speed. The payload is the mass at the tool (kg), added by the runner.

Variants run over a ``concurrent.futures.ProcessPoolExecutor`` (start method ``spawn`` by
default: safe with MuJoCo and OpenGL state in the parent); results are gathered in variant
order whatever the completion order, so a parallel sweep gives exactly the table a serial one
gives. A failing variant does not stop the others: the outputs are written for those that
succeeded, then :class:`SweepError` names the failures.

Outputs in ``out_dir``: ``sweep.csv`` (one row per variant and joint), ``sweep.md`` (pivot
tables of peak and RMS torque, failures), ``sweep.svg`` (peak and RMS torque per joint against
payload and against speed scale) and ``sweep.json``.

The package, one concept per module, each importing only those before it:
:mod:`~sim.pipeline.sweep.variants` (the variants, their validation, outcomes and rows) <-
:mod:`~sim.pipeline.sweep.report` (``sweep.csv``, ``sweep.md``, ``sweep.svg``, ``sweep.json``)
<- :mod:`~sim.pipeline.sweep.engines` (where variants run: a process pool, Ray, a batch) <-
:mod:`~sim.pipeline.sweep.run` (:func:`run_sweep`: the sweep folder, its lock and its move
into place). Parsing the command line's value lists is :mod:`sim.cli.size`'s.
:mod:`~sim.pipeline.sweep.evaluation` is what runs a variant (metrics only by default), and
:mod:`~sim.pipeline.sweep.reuse` what a metrics-only variant reuses from the other variants of
its plan in the same worker (the plan, the reference's collision scan: the same rows, bit for
bit, without clearance, a warning no row depends on).
"""

from sim.errors import SweepError
from sim.pipeline.sweep.engines import ENGINES, run_group, task_groups
from sim.pipeline.sweep.report import (
    SWEEP_COLUMNS,
    sweep_markdown,
    sweep_svg,
    write_sweep,
)
from sim.pipeline.sweep.run import run_sweep
from sim.pipeline.sweep.variants import (
    MAX_SWEEP_VARIANTS,
    Outcome,
    SweepResult,
    Variant,
    VariantMetrics,
    make_variants,
    rows_from,
    run_variant,
    validate_payloads,
    validate_speed_scales,
    variant_rows,
)

__all__ = ["ENGINES", "MAX_SWEEP_VARIANTS", "SWEEP_COLUMNS", "Outcome", "SweepError",
           "SweepResult", "Variant", "VariantMetrics", "make_variants", "rows_from", "run_group",
           "run_sweep", "run_variant", "sweep_markdown", "sweep_svg", "task_groups",
           "validate_payloads", "validate_speed_scales", "variant_rows", "write_sweep"]
