"""Parameter sweeps: the same cycle over payloads and speeds, run in parallel.

A sweep runs every combination of a list of payloads (kg) and a list of speed scales. A
*variant* is one ``(payload_kg, speed_scale)`` pair (:class:`Variant`, which also carries the
base scenario and a suggested run folder). The runner is any picklable callable (a module-level
function) ``runner(variant) -> run_dir`` that simulates the variant and returns the folder
holding its ``trajectory.npz`` (and ``summary.json``, ``sizing.json`` when it sized the run).

Speed scale ``s`` divides every knot time of the base scenario (:func:`scale_knot_times`):
``s = 2`` runs the cycle twice as fast (half the duration), so joint speeds scale by ``s``,
accelerations by ``s^2`` and the inertial part of the torques by ``s^2``; ``s = 0.5`` is half
speed. The payload is the mass at the tool (kg), added by the runner.

Variants run over a ``concurrent.futures.ProcessPoolExecutor`` (start method ``spawn`` by
default: safe with MuJoCo and OpenGL state in the parent); results are gathered in variant
order whatever the completion order, so a parallel sweep gives exactly the table a serial one
gives. A failing variant does not stop the others: the outputs are written for those that
succeeded, then :class:`SweepError` names the failures.

Outputs in ``out_dir``: ``sweep.csv`` (one row per variant and joint), ``sweep.md`` (pivot
tables of peak and RMS torque, failures), ``sweep.png`` (peak and RMS torque per joint against
payload and against speed scale) and ``sweep.json``.
"""

from __future__ import annotations

import json
import math
import multiprocessing
import os
import re
import shutil
import tempfile
import time
import traceback
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.analysis.report import csv_text, figure_png, write_atomic
from sim.analysis.sizing import (
    PEAK_WINDOW_S,
    load_summary,
    load_trajectory,
    peak_abs,
    rms,
    sustained,
)
from sim.errors import CellsimError, SweepError
from sim.simulation.runfolder import SIZING_JSON

#: Columns of sweep.csv, in order.
SWEEP_COLUMNS = ("payload_kg", "speed_scale", "joint", "peak_torque_nm", "rms_torque_nm",
                 "peak_torque_id_nm", "peak_torque_sim_nm", "rms_torque_id_nm", "rms_torque_sim_nm",
                 "peak_speed_rad_s", "peak_power_w", "duration_s", "margin_pct", "pass",
                 "limiting", "verdict", "run_dir")


# --------------------------------------------------------------------------------------------
# Input parsing and validation
# --------------------------------------------------------------------------------------------

def _number(token: str, field: str) -> float:
    try:
        value = float(token)
    except ValueError:
        raise SweepError(f"{field}: {token!r} is not a number (expected a comma-separated list "
                         "like 0,2.5,5 or a range start:stop:step like 0:10:2.5)") from None
    if not math.isfinite(value):
        raise SweepError(f"{field}: {token!r} is not a finite number")
    return value


#: Most values one sweep option may list, and most variants of a sweep.
MAX_SWEEP_VALUES = 10_000
MAX_SWEEP_VARIANTS = 10_000


def parse_float_list(text: str, field: str = "value") -> list[float]:
    """Numbers from a command-line list: ``"0,2.5,5"`` or an inclusive range ``"0:10:2.5"``
    (items may mix: ``"0,1:3:1"``). Duplicates are dropped, the order kept.

    Args:
        text: The option's text.
        field: Option name for error messages (``"--payload"``).

    Returns:
        The numbers, in order of appearance.

    Raises:
        SweepError: Empty list, empty item, non-number, or a bad range (names ``field``).
    """
    if text is None or not str(text).strip():
        raise SweepError(f"{field}: empty list (expected numbers like 0,2.5,5)")
    out: list[float] = []
    for item in str(text).split(","):
        item = item.strip()
        if not item:
            raise SweepError(f"{field}: empty item in {text!r} (expected numbers like 0,2.5,5)")
        if ":" in item:
            parts = item.split(":")
            if len(parts) != 3:
                raise SweepError(f"{field}: range {item!r} must be start:stop:step")
            a, b, step = (_number(p.strip(), field) for p in parts)
            if step <= 0:
                raise SweepError(f"{field}: range {item!r} needs a positive step")
            if b < a:
                raise SweepError(f"{field}: range {item!r} has stop < start")
            span = (b - a) / step  # inf for a huge range or a tiny step: refused, not allocated
            if not math.isfinite(span) or span + 1 > MAX_SWEEP_VALUES:
                shown = "more than 1e308" if not math.isfinite(span) else f"{int(span) + 1}"
                raise SweepError(f"{field}: range {item!r} has {shown} values (at most "
                                 f"{MAX_SWEEP_VALUES})")
            count = int(math.floor(span + 1e-9)) + 1
            out.extend(round(a + k * step, 12) for k in range(count))
        else:
            out.append(_number(item, field))
    return list(dict.fromkeys(out))


def validate_payloads(payloads: Sequence[float], field: str = "payload") -> list[float]:
    """Payloads in kg: 0 to :data:`~sim.scenario.schema.MAX_PAYLOAD_KG`, at least one;
    duplicates dropped.

    Raises:
        SweepError: One line naming ``field`` and the bad value.
    """
    values = [float(p) for p in payloads]
    if not values:
        raise SweepError(f"{field}: no payload given (expected kg values like 0,2.5,5)")
    from sim.scenario.schema import MAX_PAYLOAD_KG

    for p in values:
        if not math.isfinite(p) or p < 0 or p > MAX_PAYLOAD_KG:
            raise SweepError(f"{field}: payload must be a mass of 0 to {MAX_PAYLOAD_KG:g} kg, "
                             f"got {p:g}")
    return list(dict.fromkeys(values))


def validate_speed_scales(scales: Sequence[float], field: str = "speed scale") -> list[float]:
    """Speed scales: finite, > 0, at least one; duplicates dropped.

    Raises:
        SweepError: One line naming ``field`` and the bad value.
    """
    values = [float(s) for s in scales]
    if not values:
        raise SweepError(f"{field}: no speed scale given (expected factors like 0.5,1,1.5)")
    for s in values:
        if not math.isfinite(s) or s <= 0:
            raise SweepError(f"{field}: speed scale must be a finite factor > 0 "
                             f"(1 = as planned, 2 = twice as fast), got {s:g}")
    return list(dict.fromkeys(values))


def scale_knot_times(times: ArrayLike, speed_scale: float) -> NDArray[np.float64]:
    """Knot times of a variant: the base knot times divided by ``speed_scale``.

    Args:
        times: Base knot times, s, any shape.
        speed_scale: Factor > 0 (2 = twice as fast).

    Returns:
        ``times / speed_scale``, s.
    """
    validate_speed_scales([speed_scale])
    return np.asarray(times, dtype=float) / float(speed_scale)


# --------------------------------------------------------------------------------------------
# Variants and their results
# --------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Variant:
    """One point of a sweep.

    Attributes:
        payload_kg: Payload at the tool, kg.
        speed_scale: Knot times are divided by this factor.
        scenario: The base scenario, passed to the runner unchanged (a name, a path or a
            loaded scenario object; must be picklable).
        run_dir: Suggested run folder for this variant (inside the sweep's ``out_dir``).
        index: Position in the sweep (payload-major order).
    """

    payload_kg: float
    speed_scale: float
    scenario: Any = None
    run_dir: Path = Path(".")
    index: int = 0

    @property
    def label(self) -> str:
        return f"payload {self.payload_kg:g} kg, speed x{self.speed_scale:g}"

    @property
    def slug(self) -> str:
        """Folder-safe name, e.g. ``payload_2.5kg_speed_1.5x``."""
        return re.sub(r"[^A-Za-z0-9_.-]", "_",
                      f"payload_{self.payload_kg:g}kg_speed_{self.speed_scale:g}x")


def make_variants(base_scenario: Any, payloads: Sequence[float], speed_scales: Sequence[float],
                  out_dir: str | Path) -> list[Variant]:
    """Every ``(payload, speed_scale)`` combination, payload-major, validated."""
    ps = validate_payloads(payloads)
    ss = validate_speed_scales(speed_scales)
    if len(ps) * len(ss) > MAX_SWEEP_VARIANTS:  # each list may be long, not their product
        raise SweepError(f"{len(ps)} payloads x {len(ss)} speed scales make "
                         f"{len(ps) * len(ss)} variants (at most {MAX_SWEEP_VARIANTS})")
    out = Path(out_dir)
    combos = [(p, s) for p in ps for s in ss]
    names = [Variant(p, s).slug for p, s in combos]
    clash = {n for n in names if names.count(n) > 1}
    # values that print alike (1.0000001 and 1.0000002 kg: both "1") get their exact digits,
    # so that no two variants share a run folder
    names = [re.sub(r"[^A-Za-z0-9_.-]", "_", f"payload_{p!r}kg_speed_{s!r}x") if n in clash
             else n for n, (p, s) in zip(names, combos, strict=True)]
    return [Variant(p, s, base_scenario, out / name, i)
            for i, ((p, s), name) in enumerate(zip(combos, names, strict=True))]


@dataclass(frozen=True)
class Outcome:
    """What one variant gave: its rows of sweep.csv, or the error that stopped it."""

    variant: Variant
    run_dir: str | None
    rows: tuple[dict[str, Any], ...] = ()
    error: str | None = None
    traceback: str | None = None
    wall_s: float = 0.0
    selection: dict[str, Any] | None = None
    timings_s: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class VariantMetrics:
    """What a metrics-only runner returns instead of a run folder: the variant's rows of
    sweep.csv, computed where the variant ran from every sample in memory, its actuator
    selection (``selection.json``'s content) when one was made, its stage timings, and its run
    folder when one was kept. Small: what crosses a process or a cluster is a few numbers per
    joint, never the arrays."""

    rows: tuple[dict[str, Any], ...]
    selection: dict[str, Any] | None = None
    timings_s: dict[str, float] = field(default_factory=dict)
    run_dir: str | None = None


def rows_from(variant: Variant, arrays: Mapping[str, NDArray[Any]], joints: Sequence[str],
              verdict: str, sized: Mapping[str, Mapping[str, Any]], run_dir: str = ""
              ) -> list[dict[str, Any]]:
    """Rows of sweep.csv for one variant (one per joint), from its recorded arrays.

    Args:
        variant: The variant.
        arrays: ``t``, ``tau``, ``tau_id``, ``qd_ref``, ``qd`` (N samples; torques N m,
            speeds rad/s).
        joints: Joint names, one per column.
        verdict: The run's verdict (``"pass"``/``"fail"``).
        sized: ``sizing.json``'s joints by name (``margin_pct``, ``pass``, ``limiting``);
            empty when the run was not sized.
        run_dir: The variant's run folder ("" when none was kept).

    Peak and RMS torques are computed from both sources; the unsuffixed value is the larger.
    The simulated peaks are of the torque sustained over
    :data:`~sim.analysis.sizing.PEAK_WINDOW_S`, as sizing takes them.
    """
    t = np.asarray(arrays["t"], dtype=float)
    rows = []
    for k, name in enumerate(joints):
        tau_id, tau = arrays["tau_id"][:, k], arrays["tau"][:, k]
        pk_id, _ = peak_abs(t, tau_id)
        # the simulated source's peaks as sizing takes them: sustained over PEAK_WINDOW_S
        pk_sim, _ = peak_abs(t, sustained(t, tau, PEAK_WINDOW_S))
        rms_id = float(rms(t, tau_id))
        rms_sim = float(rms(t, tau))
        speed = max(peak_abs(t, arrays["qd_ref"][:, k])[0], peak_abs(t, arrays["qd"][:, k])[0])
        power = max(peak_abs(t, tau_id * arrays["qd_ref"][:, k])[0],
                    peak_abs(t, sustained(t, tau * arrays["qd"][:, k], PEAK_WINDOW_S))[0])
        s = sized.get(name, {})
        margin = s.get("margin_pct")
        rows.append({
            "payload_kg": variant.payload_kg, "speed_scale": variant.speed_scale, "joint": name,
            "peak_torque_nm": max(pk_id, pk_sim), "rms_torque_nm": max(rms_id, rms_sim),
            "peak_torque_id_nm": pk_id, "peak_torque_sim_nm": pk_sim,
            "rms_torque_id_nm": rms_id, "rms_torque_sim_nm": rms_sim,
            "peak_speed_rad_s": speed, "peak_power_w": power,
            "duration_s": float(t[-1] - t[0]),
            "margin_pct": float("nan") if margin is None else float(margin),
            "pass": ("PASS" if s["pass"] else "FAIL") if "pass" in s else "",
            "limiting": s.get("limiting") or "",
            "verdict": verdict,
            "run_dir": str(run_dir),
        })
    return rows


def variant_rows(variant: Variant, run_dir: str | Path) -> list[dict[str, Any]]:
    """Rows of sweep.csv for one variant whose run folder was written (one per joint): the
    arrays from ``trajectory.npz``, the margins from ``sizing.json`` when there is one."""
    traj = load_trajectory(run_dir)
    summary = load_summary(run_dir)
    n = traj["tau"].shape[1]
    names = list(summary.get("joints") or [f"j{k + 1}" for k in range(n)])
    sizing_path = Path(run_dir) / SIZING_JSON
    sized: dict[str, dict[str, Any]] = {}
    if sizing_path.is_file():
        try:
            sized = {j["joint"]: j for j in json.loads(sizing_path.read_text()).get("joints", [])}
        except (json.JSONDecodeError, KeyError, TypeError):
            sized = {}
    return rows_from(variant, traj, names, summary.get("verdict", ""), sized, str(run_dir))


def _outcome(variant: Variant, got: Any, wall_s: float) -> Outcome:
    """The outcome of what a runner returned: metrics computed in memory, or a run folder to
    read the rows from."""
    if got is None:
        raise CellsimError("the runner returned no run folder")
    if isinstance(got, VariantMetrics):  # computed in memory (a run folder or none)
        return Outcome(variant, got.run_dir, tuple(got.rows), selection=got.selection,
                       wall_s=wall_s, timings_s=dict(got.timings_s))
    return Outcome(variant, str(got), tuple(variant_rows(variant, got)), wall_s=wall_s)


def run_variant(runner: Callable[[Variant], Any], variant: Variant) -> Outcome:
    """Run one variant and read its results; never raises (errors go into the outcome, as
    text, so that unpicklable exceptions cannot break the process pool)."""
    t0 = time.perf_counter()
    try:
        return _outcome(variant, runner(variant), time.perf_counter() - t0)
    except BaseException as exc:  # noqa: BLE001 - reported per variant
        if isinstance(exc, KeyboardInterrupt):
            raise
        msg = f"{type(exc).__name__}: {exc}".splitlines()[0]
        return Outcome(variant, None, (), msg, traceback.format_exc(),
                       wall_s=time.perf_counter() - t0)


@dataclass
class SweepResult:
    """A finished sweep.

    Attributes:
        outcomes: One per variant, in variant order.
        workers: Worker processes used (1 = serial, in this process).
        wall_s: Wall-clock time of the runs, s.
        files: Files written, by name.
    """

    outcomes: list[Outcome]
    workers: int
    wall_s: float
    files: dict[str, Path] = field(default_factory=dict)

    @property
    def rows(self) -> list[dict[str, Any]]:
        return [r for o in self.outcomes for r in o.rows]

    @property
    def failures(self) -> list[Outcome]:
        return [o for o in self.outcomes if o.error is not None]


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
        write: Write ``sweep.csv``, ``sweep.md``, ``sweep.json``, ``sweep.png``.
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
        _import_ray()
        if address not in (None, "auto"):
            _check_reachable(address)
    from sim.simulation import runfolder

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
    with runfolder.RunLock(out_dir):
        runfolder.remove_stale(out_dir)
        tmp = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.", dir=out_dir.parent))
        try:
            runfolder.write_marker(tmp, state="writing")
            variants = make_variants(base_scenario, payloads, speed_scales, tmp)
            n_workers = min(workers or os.cpu_count() or 1, len(variants))
            result = _run_variants(runner, variants, n_workers, mp_context, engine, address,
                                   batch, progress)
            result = _moved(result, tmp, out_dir)
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
                    failed = Path(tempfile.mkdtemp(prefix=failed.name + "-",
                                                   dir=out_dir.parent))
                    failed.rmdir()
                os.replace(tmp, failed)
                result = _moved(result, out_dir, failed)
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


def _run_variants(runner: Callable[[Variant], Any], variants: list[Variant], workers: int,
                  mp_context: str, engine: str, address: str | None, batch: Any,
                  progress: bool) -> SweepResult:
    """Run every variant (a batch, Ray, this process or a process pool)."""
    from tqdm import tqdm

    bar = tqdm(total=len(variants), desc="sweep", unit="run", disable=None if progress else True)
    t0 = time.perf_counter()
    results: list[Outcome | None] = [None] * len(variants)
    try:
        if batch is not None:
            _run_batch(batch, variants, results)
            bar.update(len(variants))
        elif engine == "ray":
            _run_on_ray(runner, variants, results, address, workers, bar)
        elif workers == 1:  # in this process, a speed scale's variants one after the other
            for group in task_groups(variants, 1):
                for v in group:
                    results[v.index] = run_variant(runner, v)
                    bar.update()
        else:
            ctx = multiprocessing.get_context(mp_context)
            with ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as pool:
                futures = {pool.submit(run_group, runner, g): g
                           for g in task_groups(variants, workers)}
                for fut in as_completed(futures):
                    group = futures[fut]
                    try:
                        for o in fut.result():
                            results[o.variant.index] = o
                    except Exception as exc:  # the worker died (BrokenProcessPool, pickling)
                        for v in group:
                            results[v.index] = Outcome(v, None, (), f"{type(exc).__name__}: {exc}")
                    bar.update(len(group))
    finally:
        bar.close()
    return SweepResult(outcomes=[r for r in results if r is not None], workers=workers,
                       wall_s=time.perf_counter() - t0)


def _moved(result: SweepResult, old: Path, new: Path) -> SweepResult:
    """``result`` with every path under ``old`` (run folders, in outcomes and rows) under
    ``new``: the sweep is written in a hidden sibling and then moved into place."""
    import dataclasses

    a, b = str(old), str(new)

    def path(p: Any) -> Any:
        return b + p[len(a):] if isinstance(p, str) and (p == a or p.startswith(a + os.sep)) \
            else p

    outcomes = [dataclasses.replace(
        o, run_dir=path(o.run_dir),
        variant=dataclasses.replace(o.variant, run_dir=Path(path(str(o.variant.run_dir)))),
        rows=tuple({k: path(v) for k, v in r.items()} for r in o.rows)) for o in result.outcomes]
    return dataclasses.replace(result, outcomes=outcomes)


#: Where variants run: a process pool on this machine, or Ray (a local instance or a cluster).
ENGINES: tuple[str, ...] = ("pool", "ray")


def _import_ray() -> Any:
    try:
        import ray
    except ImportError:
        raise SweepError("--engine ray needs Ray: pip install 'cellsim[ray]' (or use "
                         "--engine pool)") from None
    return ray


def task_groups(variants: Sequence[Variant], workers: int) -> list[list[Variant]]:
    """The variants cut into tasks for ``workers`` parallel workers: the variants of one speed
    scale run together, in one worker, one after the other (a plan depends on the speed scale,
    not on the payload, so the worker plans once and reuses it), split into enough tasks that
    every worker has at least two to take. The results do not depend on the grouping (they
    are gathered by variant index)."""
    by_speed: dict[float, list[Variant]] = {}
    for v in variants:
        by_speed.setdefault(v.speed_scale, []).append(v)
    per_speed = max(1, math.ceil(2 * max(workers, 1) / len(by_speed)))
    groups: list[list[Variant]] = []
    for members in by_speed.values():
        size = max(1, math.ceil(len(members) / per_speed))
        groups.extend(members[k:k + size] for k in range(0, len(members), size))
    return groups


def run_group(runner: Callable[[Variant], Any], variants: Sequence[Variant]) -> list[Outcome]:
    """Run variants one after the other in this process (a task of a parallel sweep)."""
    return [run_variant(runner, v) for v in variants]


def _run_batch(batch: Callable[[Sequence[Variant]], Sequence[Any]],
               variants: Sequence[Variant], results: list[Outcome | None]) -> None:
    """One batched call for every variant; an error stops them all (it is reported for each)."""
    t0 = time.perf_counter()
    try:
        got = list(batch(variants))
    except BaseException as exc:  # noqa: BLE001 - reported per variant
        if isinstance(exc, KeyboardInterrupt):
            raise
        msg = f"{type(exc).__name__}: {exc}".splitlines()[0]
        tb = traceback.format_exc()
        for v in variants:
            results[v.index] = Outcome(v, None, (), msg, tb)
        return
    if len(got) != len(variants):
        msg = (f"InternalError: the batch returned {len(got)} results for {len(variants)} "
               "variants")
        for v in variants:
            results[v.index] = Outcome(v, None, (), msg)
        return
    share = (time.perf_counter() - t0) / max(len(variants), 1)
    for v, item in zip(variants, got):
        try:
            results[v.index] = _outcome(v, item, share)
        except Exception as exc:  # noqa: BLE001 - reported per variant
            results[v.index] = Outcome(v, None, (), f"{type(exc).__name__}: {exc}".splitlines()[0],
                                       traceback.format_exc(), wall_s=share)


def _check_reachable(address: str, timeout_s: float = 5.0) -> None:
    """Refuse a cluster address nobody answers at (Ray itself would retry for minutes)."""
    import socket

    where = address.split("://", 1)[-1]
    host, _, port = where.rpartition(":")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise SweepError(f"--address {address!r}: expected auto or HOST:PORT (the Ray head "
                         "node's GCS port, 6379 by default)")
    try:
        with socket.create_connection((host.strip("[]"), int(port)), timeout=timeout_s):
            pass
    except OSError as exc:
        raise SweepError(f"--address {address}: cannot connect to Ray: "
                         f"{exc.strerror or exc}") from None


def _run_on_ray(runner: Callable[[Variant], Any], variants: Sequence[Variant],
                results: list[Outcome | None], address: str | None, workers: int,
                bar: Any) -> None:
    """Run the variants as Ray tasks (one CPU each) and put their outcomes in ``results``
    (variant order, whatever the completion order).

    With ``address`` None a local Ray instance with ``workers`` CPUs is started and shut down
    afterwards; otherwise cellsim connects to that cluster (which must have the same cellsim
    installed on every node) and leaves it running. A task that dies (a worker killed, a node
    lost) becomes that variant's error; the others go on.
    """
    import logging

    ray = _import_ray()
    started = not ray.is_initialized()
    if started:
        kwargs: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False,
                                  "logging_level": logging.ERROR, "configure_logging": False}
        if address is None:
            kwargs["num_cpus"] = workers
        try:
            ray.init(address=address, **kwargs)
        except (ConnectionError, RuntimeError, ValueError) as exc:
            first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            raise SweepError(f"--address {address}: cannot connect to Ray: {first}"
                             if address else f"cannot start a local Ray instance: {first}"
                             ) from None
    try:
        task = ray.remote(num_cpus=1, max_retries=0)(run_group)
        cpus = workers if address is None else int(ray.cluster_resources().get("CPU", workers))
        pending = {task.remote(runner, g): g for g in task_groups(variants, cpus)}
        while pending:
            done, _ = ray.wait(list(pending), num_returns=1)
            for ref in done:
                group = pending.pop(ref)
                try:
                    for o in ray.get(ref):
                        results[o.variant.index] = o
                except Exception as exc:  # noqa: BLE001 - a lost worker or node
                    first = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
                    for v in group:
                        results[v.index] = Outcome(v, None, (), f"{type(exc).__name__}: {first}")
                bar.update(len(group))
    finally:
        if started:
            ray.shutdown()


# --------------------------------------------------------------------------------------------
# Outputs
# --------------------------------------------------------------------------------------------

def _pivot(rows: Sequence[dict[str, Any]], key: str, joints: Sequence[str]) -> list[list[str]]:
    table: dict[tuple[float, float], dict[str, float]] = {}
    for r in rows:
        table.setdefault((r["payload_kg"], r["speed_scale"]), {})[r["joint"]] = r[key]
    out = []
    for (p, s), vals in table.items():
        cells = [f"{vals[j]:.4g}" if j in vals and np.isfinite(vals[j]) else "n/a" for j in joints]
        out.append([f"{p:g}", f"{s:g}", *cells])
    return out


def sweep_markdown(result: SweepResult, chart: str | None = "sweep.png") -> str:
    """Text of ``sweep.md``: pivot tables (variant rows, joint columns), failures, chart."""
    rows = result.rows
    joints = list(dict.fromkeys(r["joint"] for r in rows))
    ok = len(result.outcomes) - len(result.failures)
    parts = ["# Sweep", "",
             f"{len(result.outcomes)} variants ({ok} succeeded), {result.workers} worker(s), "
             f"{result.wall_s:.1f} s wall-clock. Speed scale s divides the knot times "
             "(s = 2: twice as fast). Torques are the larger of inverse dynamics and simulation.",
             ""]
    head = ["payload kg", "speed scale", *joints]

    def table(title: str, key: str) -> None:
        parts.extend([f"## {title}", "",
                      "| " + " | ".join(head) + " |", "|" + "---|" * len(head)])
        parts.extend("| " + " | ".join(r) + " |" for r in _pivot(rows, key, joints))
        parts.append("")

    if rows:
        table("Peak |torque| (N m)", "peak_torque_nm")
        table("RMS torque (N m)", "rms_torque_nm")
        if any(np.isfinite(r["margin_pct"]) for r in rows):
            table("Sizing margin (%)", "margin_pct")
    if result.failures:
        parts += ["## Failed variants", ""]
        parts += [f"- {o.variant.label}: {o.error}" for o in result.failures]
        parts.append("")
    if chart and rows:
        parts += ["## Chart", "", f"![peak and RMS torque]({chart})", ""]
    return "\n".join(parts)


def sweep_chart(result: SweepResult) -> bytes:
    """PNG: per joint (rows), peak (solid) and RMS (dashed) torque against payload (left, one
    line per speed scale) and against speed scale (right, one line per payload)."""
    import matplotlib
    from matplotlib.figure import Figure

    rows = result.rows
    joints = list(dict.fromkeys(r["joint"] for r in rows))
    payloads = sorted({r["payload_kg"] for r in rows})
    scales = sorted({r["speed_scale"] for r in rows})
    idx = {(r["payload_kg"], r["speed_scale"], r["joint"]): r for r in rows}
    fig = Figure(figsize=(10, 2.3 * len(joints) + 0.8), layout="constrained")
    axes = fig.subplots(len(joints), 2, squeeze=False)
    cmap = matplotlib.colormaps["viridis"]

    def lines(ax, xs, series_keys, label_fmt, make_key):
        for i, other in enumerate(series_keys):
            color = cmap(i / max(len(series_keys) - 1, 1))
            for key, style in (("peak_torque_nm", "-o"), ("rms_torque_nm", "--s")):
                pts = [(x, idx[make_key(x, other)][key]) for x in xs if make_key(x, other) in idx]
                if pts:
                    x, y = zip(*pts)
                    ax.plot(x, y, style, color=color, ms=3.5, lw=1.2,
                            label=label_fmt(other) if key == "peak_torque_nm" else None)

    for k, j in enumerate(joints):
        ax_p, ax_s = axes[k]
        lines(ax_p, payloads, scales, lambda s: f"speed x{s:g}", lambda x, s: (x, s, j))
        lines(ax_s, scales, payloads, lambda p: f"{p:g} kg", lambda x, p: (p, x, j))
        ax_p.set_ylabel(f"{j} torque (N m)")
        for ax in (ax_p, ax_s):
            ax.grid(alpha=0.3)
        if k == 0:
            ax_p.set_title("against payload (solid: peak, dashed: RMS)", fontsize=9)
            ax_s.set_title("against speed scale (solid: peak, dashed: RMS)", fontsize=9)
            ax_p.legend(fontsize=7)
            ax_s.legend(fontsize=7)
    axes[-1][0].set_xlabel("payload (kg)")
    axes[-1][1].set_xlabel("speed scale")
    return figure_png(fig)


def write_sweep(out_dir: str | Path, result: SweepResult) -> dict[str, Path]:
    """Write ``sweep.csv``, ``sweep.json``, ``sweep.png`` (when any variant succeeded) and
    ``sweep.md`` into ``out_dir`` (atomically). Returns the paths by name."""
    out = Path(out_dir)
    files: dict[str, Path] = {}
    rows = result.rows
    files["csv"] = write_atomic(out / "sweep.csv", csv_text(SWEEP_COLUMNS, rows))
    payload = {
        "workers": result.workers, "wall_s": result.wall_s,
        "variants": [{"payload_kg": o.variant.payload_kg, "speed_scale": o.variant.speed_scale,
                      "run_dir": o.run_dir, "error": o.error, "wall_s": o.wall_s}
                     for o in result.outcomes],
        "rows": [{k: (v if not isinstance(v, float) or math.isfinite(v) else None)
                  for k, v in r.items()} for r in rows],
    }
    files["json"] = write_atomic(out / "sweep.json", json.dumps(payload, indent=2) + "\n")
    chart = None
    if rows:
        files["png"] = write_atomic(out / "sweep.png", sweep_chart(result))
        chart = "sweep.png"
    files["md"] = write_atomic(out / "sweep.md", sweep_markdown(result, chart))
    return files
