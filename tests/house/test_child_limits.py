"""The suite's children are bounded by CPU time, not wall-clock time (tests/support/limits.py).

A test must not fail because the machine is loaded, and must not hang because a child loops:
children that the tests start run under a CPU-time limit, and no test passes a wall-clock
``timeout=`` to a child process or waits on ``time.monotonic()``.
"""

from __future__ import annotations

import re
import signal
import subprocess
import sys
from pathlib import Path

from support.limits import cpu_seconds, popen_limited, run_limited, wait_until

TESTS = Path(__file__).resolve().parents[1]


def test_a_child_that_loops_forever_is_stopped_by_its_cpu_limit():
    r = run_limited([sys.executable, "-c", "while True: pass"], cpu_s=1, capture_output=True)
    assert r.returncode == -signal.SIGXCPU


def test_a_child_within_its_limit_keeps_its_exit_status_and_output():
    r = run_limited([sys.executable, "-c", "import sys; print('hi'); sys.exit(3)"], cpu_s=30,
                    capture_output=True, text=True)
    assert (r.returncode, r.stdout) == (3, "hi\n")


def test_waiting_on_a_busy_child_is_bounded_by_its_cpu_time():
    proc = popen_limited([sys.executable, "-c", "while True: pass"], cpu_s=60)
    try:
        try:
            wait_until(lambda: False, proc, cpu_s=1.0)
        except AssertionError as exc:
            assert "CPU time" in str(exc)
        else:
            raise AssertionError("wait_until returned for a condition that never holds")
        assert cpu_seconds(proc.pid) >= 1.0
    finally:
        proc.kill()
        proc.wait()


def test_no_test_sets_a_wall_clock_limit_on_a_child_or_a_wait():
    pattern = re.compile(r"\btimeout\s*=|time\.monotonic\(|signal\.alarm\(|SIGALRM")
    found = []
    for path in sorted(TESTS.rglob("*.py")):
        if path.resolve() == Path(__file__).resolve():
            continue
        for n, line in enumerate(path.read_text().splitlines(), 1):
            if pattern.search(line) and "subprocess.TimeoutExpired" not in line:
                found.append(f"{path.relative_to(TESTS)}:{n}: {line.strip()}")
    assert not found, "\n".join(found)


def test_the_wait_sees_the_child_end():
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    try:
        wait_until(lambda: False, proc, cpu_s=60)
    except AssertionError as exc:
        assert "ended" in str(exc)
    else:
        raise AssertionError("wait_until returned for a condition that never holds")
