"""The stages of a run and their wall times: progress a person can follow.

:class:`Stages` times each stage of :func:`sim.pipeline.run.run_scenario` (``build``, ``plan``,
``simulate``, ``checks``, ``sizing``, ``plots``, ``video``, ``write``). On a terminal it shows the
stage being worked on as a status line (the simulation and the video add their own progress
bars); otherwise it prints one line per finished stage to standard error (``cellsim: simulate
1.37 s``), so a log shows where the time went. ``timings`` holds every stage's wall time, s, for
``summary.json`` (``"timings_s"``) and the run's closing line.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TextIO

#: The stages in the order a run goes through them.
STAGES = ("build", "plan", "simulate", "checks", "sizing", "plots", "video", "replay", "write")


class Stages:
    """Times the stages of a run and reports them (module docstring).

    Args:
        enabled: Report progress at all (``--quiet`` turns it off; timings are kept anyway).
        stream: Where progress goes (standard error by default).
    """

    def __init__(self, enabled: bool = True, stream: TextIO | None = None) -> None:
        self.enabled = enabled
        self.stream = stream if stream is not None else sys.stderr
        self.timings: dict[str, float] = {}
        self._start = time.perf_counter()

    @property
    def terminal(self) -> bool:
        try:
            return bool(self.stream.isatty())
        except (AttributeError, ValueError):
            return False

    @contextmanager
    def stage(self, name: str) -> Iterator[None]:
        """Time one stage (its times add up when it is entered again)."""
        if self.enabled and self.terminal:
            k = STAGES.index(name) + 1 if name in STAGES else 0
            self.stream.write(f"\r\033[Kcellsim: [{k}/{len(STAGES)}] {name} ...")
            self.stream.flush()
        start = time.perf_counter()
        try:
            yield
        finally:
            dt = time.perf_counter() - start
            self.timings[name] = self.timings.get(name, 0.0) + dt
            if self.enabled:
                if self.terminal:
                    self.stream.write("\r\033[K")
                else:
                    self.stream.write(f"cellsim: {name} {dt:.2f} s\n")
                self.stream.flush()

    @property
    def total_s(self) -> float:
        """Wall time since the stages started, s."""
        return time.perf_counter() - self._start



def timings_line(timings: dict[str, float], total_s: float) -> str:
    """``wall 12.3 s (build 0.4, plan 0.5, simulate 1.4, ...)``: a run's closing line."""
    parts = ", ".join(f"{k} {v:.2g}" if v < 10 else f"{k} {v:.0f}" for k, v in timings.items())
    return f"wall {total_s:.1f} s ({parts})"
