"""Running a sweep: :func:`run_sweep` validates the variants, locks the sweep folder (cellsim's
own, like a run folder), runs the variants on an engine, writes the report in a hidden sibling
and moves it into place (or, when every variant failed, next to the previous folder)."""

from __future__ import annotations

import contextlib
import dataclasses
import multiprocessing
import os
import shutil
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from sim.errors import SweepError
from sim.pipeline.sweep.engines import (
    ENGINES,
    check_reachable,
    import_ray,
    run_variants,
)
from sim.pipeline.sweep.report import write_sweep
from sim.pipeline.sweep.variants import SweepResult, Variant, make_variants
from sim.simulation import runfolder


def run_sweep(base_scenario: Any, payloads: Sequence[float], speed_scales: Sequence[float],
              runner: Callable[[Variant], Any], workers: int | None = None,
              out_dir: str | Path = "sweep", *, mp_context: str = "spawn",
              progress: bool = True, write: bool = True, raise_on_failure: bool = True,
              engine: str = "pool", address: str | None = None,
              batch: Callable[[Sequence[Variant]], Sequence[Any]] | None = None
              ) -> SweepResult:
    """Run every ``(payload, speed_scale)`` variant of ``base_scenario`` and tabulate them.

    Args:
        base_scenario: Passed to the runner inside each :class:`Variant`.
        payloads: Payloads, kg (>= 0).
        speed_scales: Speed factors (> 0); knot times are divided by them.
        runner: Module-level function ``runner(variant) -> run_dir``.
        workers: Worker processes (default ``os.cpu_count()``, capped at the number of
            variants); 1 runs serially in this process.
        out_dir: Folder for the sweep outputs (and the variant run folders). cellsim's own,
            as a run folder is: locked while the sweep runs (a second sweep into it refuses),
            written in a hidden sibling and moved into place only when the sweep's table is
            written; when every variant failed, the previous folder stays as it was and the
            failed sweep's report goes to ``<out_dir>.failed``.
        mp_context: Start method of the worker processes (``"spawn"``, ``"forkserver"``,
            ``"fork"``).
        progress: Show a progress bar (tqdm; silent when not a terminal).
        write: Write ``sweep.csv``, ``sweep.md``, ``sweep.json``, ``sweep.svg``.
        raise_on_failure: Raise :class:`SweepError` after writing when a variant failed.
        engine: ``"pool"`` (a process pool on this machine) or ``"ray"`` (Ray tasks: a local
            Ray instance, or the cluster at ``address``); see :data:`ENGINES`.
        address: Ray only: ``"auto"`` (the cluster this machine belongs to), ``"HOST:PORT"``,
            or None to start a local instance with ``workers`` CPUs.
        batch: Instead of ``runner`` per variant: one call with every variant, returning what
            the runner would for each, in order (a batched backend: MuJoCo Warp); runs in
            this process, the engine is not used.

    Returns:
        The :class:`SweepResult`.

    Raises:
        SweepError: Bad payloads, speed scales or workers; failed variants (after writing).
        RunFolderError: Another sweep or run is writing ``out_dir``.
    """
    if not callable(runner):
        raise SweepError(f"runner: {runner!r} is not callable")
    if engine not in ENGINES:
        raise SweepError(f"engine: unknown {engine!r}; valid: {', '.join(ENGINES)}")
    if address is not None and engine != "ray":
        raise SweepError(f"--address {address!r} is for --engine ray (the pool runs on this "
                         "machine)")
    if engine == "ray":  # before any folder is made
        import_ray()
        if address not in (None, "auto"):
            check_reachable(address)
    # the sweep folder is cellsim's, like a run folder: never the working directory, a file,
    # a symbolic link or a user's folder (its marker lets a later sweep reuse it)
    out_dir = runfolder.check_out_dir(out_dir)
    make_variants(base_scenario, payloads, speed_scales, out_dir)  # validated before any folder
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or workers < 1):
        raise SweepError(f"workers: must be a whole number >= 1, got {workers!r}")
    if mp_context not in multiprocessing.get_all_start_methods():
        raise SweepError(f"mp_context: unknown start method {mp_context!r}; known: "
                         f"{', '.join(multiprocessing.get_all_start_methods())}")
    try:
        out_dir.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SweepError(f"{out_dir}: cannot create the sweep folder: {exc.strerror or exc}"
                         ) from None
    # a sweep has a run's guarantees: one writer per place (a second sweep into it refuses),
    # everything written into a hidden sibling marked "writing" and moved into place only
    # when its table is written (a killed sweep leaves the previous folder as it was, and what
    # it left goes at the next sweep); a sweep whose every variant failed leaves the previous
    # table too, its own report in the failed folder next to it
    # (the pool's workers, let go once every variant is in, are joined as the lock is left)
    with runfolder.RunLock(out_dir), contextlib.ExitStack() as closing:
        runfolder.remove_stale(out_dir)
        tmp = runfolder.make_folder(f".{out_dir.name}.", out_dir.parent)
        try:
            runfolder.write_marker(tmp, state="writing")
            variants = make_variants(base_scenario, payloads, speed_scales, tmp)
            n_workers = min(workers or os.cpu_count() or 1, len(variants))
            result = run_variants(runner, variants, n_workers, mp_context, engine, address,
                                   batch, progress, closing)
            result = moved(result, tmp, out_dir)
            failures = result.failures
            every_failed = bool(failures) and len(failures) == len(result.outcomes)
            if write:
                result.files = {k: out_dir / v.name
                                for k, v in write_sweep(tmp, result).items()}
            if every_failed:
                runfolder.write_marker(tmp, state="failed")
                failed = runfolder.failed_folder(out_dir)
                if runfolder.is_run_folder(failed):
                    shutil.rmtree(failed)
                elif failed.exists() or failed.is_symlink():  # not ours: never replaced
                    failed = runfolder.make_folder(failed.name + "-", out_dir.parent)
                    failed.rmdir()
                os.replace(tmp, failed)
                result = moved(result, out_dir, failed)
                result.files = {k: failed / v.name for k, v in result.files.items()}
            else:
                runfolder.write_marker(tmp, state="complete")
                runfolder.check_out_dir(out_dir)  # again: the place may have changed meanwhile
                if out_dir.exists():
                    trash = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.old.",
                                                  dir=out_dir.parent))
                    os.replace(out_dir, trash / "old")
                    shutil.rmtree(trash, ignore_errors=True)
                os.replace(tmp, out_dir)
                failed = runfolder.failed_folder(out_dir)
                if runfolder.is_run_folder(failed):  # an earlier failed sweep's, now stale
                    shutil.rmtree(failed, ignore_errors=True)
        except BaseException:
            shutil.rmtree(tmp, ignore_errors=True)
            raise
    if failures and raise_on_failure:
        first = failures[0]
        where = f"; see {result.files['md']}" if "md" in result.files else ""
        kept = (f" (every variant failed: the previous {out_dir} is as it was)"
                if every_failed else "")
        raise SweepError(f"{len(failures)} of {len(result.outcomes)} sweep variants failed; first: "
                         f"{first.variant.label}: {first.error}{where}{kept}")
    return result


def moved(result: SweepResult, old: Path, new: Path) -> SweepResult:
    """``result`` with every path under ``old`` (run folders, in outcomes and rows) under
    ``new``: the sweep is written in a hidden sibling and then moved into place."""
    a, b = str(old), str(new)

    def path(p: Any) -> Any:
        return b + p[len(a):] if isinstance(p, str) and (p == a or p.startswith(a + os.sep)) \
            else p

    outcomes = [dataclasses.replace(
        o, run_dir=path(o.run_dir),
        variant=dataclasses.replace(o.variant, run_dir=Path(path(str(o.variant.run_dir)))),
        rows=tuple({k: path(v) for k, v in r.items()} for r in o.rows)) for o in result.outcomes]
    return dataclasses.replace(result, outcomes=outcomes)


__all__ = ["moved", "run_sweep"]
