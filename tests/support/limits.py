"""Bounds on the child processes a test starts, in CPU time, never in wall-clock time.

A test that waits with a wall-clock limit fails on a loaded machine (a 20 s alarm once failed
the whole suite in a fresh clone). A child started with :func:`run_limited` instead gets a CPU-time
limit (``RLIMIT_CPU``): a child that loops forever is killed by ``SIGXCPU`` once it has used
``cpu_s`` seconds of CPU, however slowly the machine runs it. :func:`wait_until` waits for a
condition while the child runs, bounded by the child's own CPU time.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from typing import Any

#: Runs argv[2:] with the CPU-time limit argv[1] (seconds: SIGXCPU, then SIGKILL 10 s later);
#: exec keeps the pid and the pipes.
_LAUNCHER = ("import os, resource, sys; n = int(sys.argv[1]); "
             "resource.setrlimit(resource.RLIMIT_CPU, (n, n + 10)); "
             "os.execvp(sys.argv[2], sys.argv[2:])")


def cpu_limited(cmd: Sequence[Any], cpu_s: float) -> list[str]:
    """``cmd`` started through a launcher that limits its CPU time to ``cpu_s`` seconds."""
    return [sys.executable, "-c", _LAUNCHER, str(max(1, int(cpu_s))), *(str(c) for c in cmd)]


def run_limited(cmd: Sequence[Any], *, cpu_s: float,
                **kwargs: Any) -> subprocess.CompletedProcess[Any]:
    """:func:`subprocess.run` of ``cmd`` with a CPU-time limit of ``cpu_s`` seconds."""
    return subprocess.run(cpu_limited(cmd, cpu_s), **kwargs)  # noqa: PLW1510 - callers check


def popen_limited(cmd: Sequence[Any], *, cpu_s: float, **kwargs: Any) -> subprocess.Popen[Any]:
    """:class:`subprocess.Popen` of ``cmd`` with a CPU-time limit of ``cpu_s`` seconds."""
    return subprocess.Popen(cpu_limited(cmd, cpu_s), **kwargs)


def cpu_seconds(pid: int) -> float:
    """CPU time a process has used (user + system, with its waited-for children), s."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            fields = fh.read().rsplit(")", 1)[1].split()
    except OSError:
        return 0.0
    ticks = sum(int(f) for f in fields[11:15])  # utime, stime, cutime, cstime
    return ticks / os.sysconf("SC_CLK_TCK")


def wait_until(cond: Callable[[], bool], proc: subprocess.Popen[Any], *, cpu_s: float = 120.0,
               poll_s: float = 0.05) -> None:
    """Waits until ``cond()`` holds while ``proc`` runs.

    Raises:
        AssertionError: ``proc`` ended first, or used ``cpu_s`` seconds of CPU first.
    """
    while not cond():
        if proc.poll() is not None:
            raise AssertionError(f"the process ended (exit {proc.returncode}) before the "
                                 "condition held")
        if cpu_seconds(proc.pid) > cpu_s:
            raise AssertionError(f"the condition did not hold within {cpu_s:g} s of the "
                                 "process's CPU time")
        time.sleep(poll_s)
