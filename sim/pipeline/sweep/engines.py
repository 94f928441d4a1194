"""Where a sweep's variants run: this process, a process pool on this machine, Ray tasks (a
local instance or a cluster), or one batched call (MuJoCo Warp). Whatever the engine, the
outcomes are gathered in variant order, and a variant that fails (or whose worker dies) is
reported as that variant's error while the others go on."""

from __future__ import annotations

import contextlib
import gc
import logging
import multiprocessing
import multiprocessing.util
import os
import socket
import sys
import threading
import time
import traceback
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Any

from sim.errors import SweepError
from sim.pipeline.sweep.variants import (
    Outcome,
    SweepResult,
    Variant,
    outcome_of,
    run_variant,
)

#: Where variants run: a process pool on this machine, or Ray (a local instance or a cluster).
ENGINES: tuple[str, ...] = ("pool", "ray")

def import_ray() -> Any:
    try:
        import ray
    except ImportError:
        raise SweepError("--engine ray needs Ray: pip install 'cellsim[ray]' (or use "
                         "--engine pool)") from None
    return ray


def task_groups(variants: Sequence[Variant], workers: int) -> list[list[Variant]]:
    """The variants cut into tasks for ``workers`` parallel workers. The variants of one speed
    scale follow each other (a plan depends on the speed scale, not on the payload, so a worker
    plans once for the variants of a task and reuses the plan and its reference's collision
    scan), the slowest speed scale first (the longest cycles: a pool hands out tasks in order,
    so the longest go first and the short ones fill the workers' ends, whatever order the
    speed scales were given in). With at least twice as many speed scales as workers each
    speed scale is a task; else the speed-major list is cut into ``2 x workers`` tasks of sizes
    that differ by one at most, so that every worker has at least two to take (6 variants of
    one plan on 2 workers: 2, 2, 1, 1, so that each worker runs 3; 2 payloads x 3 speed
    scales: a task per speed scale's pair of payloads and one per payload of the third, so
    that no two workers make the same plan at once). The results do not depend on the
    grouping (they are gathered by variant index)."""
    by_speed: dict[float, list[Variant]] = {}
    for v in sorted(variants, key=lambda v: v.speed_scale):  # stable: payload order kept
        by_speed.setdefault(v.speed_scale, []).append(v)
    if not by_speed or len(by_speed) >= 2 * max(workers, 1):
        return list(by_speed.values())
    ordered = [v for members in by_speed.values() for v in members]
    n = min(2 * max(workers, 1), len(ordered))
    size, extra = divmod(len(ordered), n)
    cuts = [k * size + min(k, extra) for k in range(n + 1)]
    return [ordered[a:b] for a, b in zip(cuts[:-1], cuts[1:], strict=True)]


def warm_worker(scenario: Any = None) -> None:
    """A pool worker's initializer: import what every variant needs (cellsim's pipeline,
    MuJoCo) and load the base scenario once, so that the first variant does not pay for it."""
    import dm_control.mjcf  # noqa: F401 - composing a cell (with lxml, absl)
    import mujoco  # noqa: F401
    import mujoco.rollout  # noqa: F401
    import tqdm  # noqa: F401 - the simulation's progress bar (silent in a worker)

    import planners.adnia  # noqa: F401 - the planners package imports these lazily
    import planners.cartesian  # noqa: F401
    import planners.limits  # noqa: F401
    import sim.pipeline.run  # noqa: F401
    import sim.pipeline.sweep.evaluation  # noqa: F401
    import sim.pipeline.sweep.reuse  # noqa: F401
    import sim.robots.drives  # noqa: F401
    import sim.robots.kinematics.jacobian  # noqa: F401
    import sim.robots.kinematics.mujoco_fk  # noqa: F401
    import sim.simulation.collision_reuse  # noqa: F401
    import sim.simulation.seam_orientation  # noqa: F401
    import sim.simulation.singularity_cache  # noqa: F401

    # the worker's last step: leave without tearing the interpreter down (the parent waits
    # for its workers' exits while it writes the report)
    multiprocessing.util.Finalize(None, _leave_now, exitpriority=-(2**31))
    if isinstance(scenario, (str, os.PathLike)):
        from pathlib import Path

        from sim.scenario import load_scenario

        try:
            load_scenario(scenario if isinstance(scenario, str) else Path(scenario))
        except Exception:  # noqa: BLE001 - the variants report it, each as its error
            pass
    # what was imported and loaded stays for the worker's life: out of the collector's full
    # passes (each walks every object there: about 0.04 s, once in a worker's first variant)
    gc.freeze()


def _leave_now() -> None:
    """A pool worker's exit once the pool let it go (multiprocessing's last finalizer, after
    its own): its streams flushed, then ``os._exit(0)``, without the interpreter's teardown of
    MuJoCo, dm_control, SciPy and their modules (about 0.1 s of CPU per worker, spent while the
    parent writes the sweep's report). Every result was sent and every file a variant wrote
    was closed before; a worker leaving on an error exits as Python does (its traceback,
    exit code 1)."""
    if sys.exc_info()[0] is not None:
        return
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError, AttributeError):
            pass
    os._exit(0)


def _noop() -> int:
    return os.getpid()


def pool_startup_s(workers: int, mp_context: str = "spawn", scenario: Any = None) -> float:
    """Wall time to start a sweep's pool of ``workers`` (each warmed by :func:`warm_worker`)
    and run one no-op on each, s: what a sweep pays before its first variant."""
    ctx = multiprocessing.get_context(mp_context)
    t0 = time.perf_counter()
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=warm_worker,
                             initargs=(scenario,)) as pool:
        for fut in [pool.submit(_noop) for _ in range(workers)]:
            fut.result()
    return time.perf_counter() - t0


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
    for v, item in zip(variants, got, strict=True):
        try:
            results[v.index] = outcome_of(v, item, share)
        except Exception as exc:  # noqa: BLE001 - reported per variant
            results[v.index] = Outcome(v, None, (), f"{type(exc).__name__}: {exc}".splitlines()[0],
                                       traceback.format_exc(), wall_s=share)


def check_reachable(address: str, timeout_s: float = 5.0) -> None:
    """Refuse a cluster address nobody answers at (Ray itself would retry for minutes)."""
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
    ray = import_ray()
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


def run_variants(runner: Callable[[Variant], Any], variants: list[Variant], workers: int,
                  mp_context: str, engine: str, address: str | None, batch: Any,
                  progress: bool, closing: contextlib.ExitStack | None = None) -> SweepResult:
    """Run every variant (a batch, Ray, this process or a process pool).

    With ``closing``, a process pool's workers are let go as soon as the last variant is in
    and joined when ``closing`` closes: they exit while the caller writes the report."""
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
                for o in run_group(runner, group):
                    results[o.variant.index] = o
                    bar.update()
        else:
            ctx = multiprocessing.get_context(mp_context)
            # started once per sweep, each worker warmed once; the variants of a plan follow
            # each other (task_groups) so a worker reuses the plan and its reference scan
            pool = ProcessPoolExecutor(max_workers=workers, mp_context=ctx,
                                       initializer=warm_worker,
                                       initargs=(variants[0].scenario,))
            try:
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
            except BaseException:
                pool.shutdown(wait=True)  # as leaving a `with` block would
                raise
            if closing is None:
                pool.shutdown(wait=True)
            else:  # every result is in: the workers leave (os._exit) while the report is written
                leaving = threading.Thread(target=pool.shutdown, name="sweep-pool-shutdown",
                                           daemon=True)
                leaving.start()
                closing.callback(leaving.join)
    finally:
        bar.close()
    return SweepResult(outcomes=[r for r in results if r is not None], workers=workers,
                       wall_s=time.perf_counter() - t0)


__all__ = ["ENGINES", "check_reachable", "import_ray", "pool_startup_s", "run_group",
           "run_variants", "task_groups", "warm_worker"]
