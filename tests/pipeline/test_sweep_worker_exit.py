"""A sweep pool worker's exit (issue 29): once the pool lets it go, a worker leaves with
``os._exit(0)`` after multiprocessing's own finalizers, without the interpreter's teardown of
MuJoCo, dm_control and SciPy (about 0.1 s of CPU each, spent while the parent writes the
report). Specification: a worker warmed by :func:`warm_worker` exits with code 0 once shut
down, its results all delivered; :func:`_leave_now` flushes the streams and exits with 0 when
no exception is in flight, and returns (Python's own exit: traceback, code 1) when one is."""

from __future__ import annotations

import multiprocessing
import os
import sys
from concurrent.futures import ProcessPoolExecutor

import pytest

from sim.pipeline.sweep import engines


class _Exited(Exception):
    pass


def test_a_warmed_worker_exits_with_code_0_after_its_results() -> None:
    ctx = multiprocessing.get_context("spawn")
    pool = ProcessPoolExecutor(max_workers=1, mp_context=ctx, initializer=engines.warm_worker)
    pids = [pool.submit(engines._noop).result() for _ in range(3)]
    procs = list(pool._processes.values())  # type: ignore[attr-defined]
    pool.shutdown(wait=True)
    assert len(set(pids)) == 1 and pids[0] != os.getpid()
    assert [p.exitcode for p in procs] == [0]


def test_leave_now_flushes_then_exits_with_0(monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[object] = []

    class Stream:
        def flush(self) -> None:
            calls.append("flush")

    def fake_exit(code: int) -> None:
        calls.append(code)
        raise _Exited

    monkeypatch.setattr(sys, "stdout", Stream())
    monkeypatch.setattr(sys, "stderr", Stream())
    monkeypatch.setattr(os, "_exit", fake_exit)
    with pytest.raises(_Exited):
        engines._leave_now()
    assert calls == ["flush", "flush", 0]


def test_leave_now_leaves_a_failing_worker_to_python(monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[int] = []
    monkeypatch.setattr(os, "_exit", calls.append)
    with pytest.raises(ValueError):
        try:
            raise ValueError("the worker's run failed")
        finally:
            engines._leave_now()  # as multiprocessing's finalizer runs, in a finally
    assert calls == []
    engines._leave_now()  # planted: nothing in flight, so it exits (here: recorded)
    assert calls == [0]
