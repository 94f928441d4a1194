"""Planted faults for the video's worker processes (tests/render/test_video_workers.py).

Each function has the signature of :func:`sim.render.workers.render_chunk` and renders the
chunk as it should, except for one fault. They are module-level functions of an importable
module because a worker process receives its chunk renderer by name (pickled).
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterator, Sequence
from typing import Any

import numpy as np

from sim.render.workers import render_chunk

#: The frame each fault strikes at.
AT = 5


def duplicate(frames: Any, times: np.ndarray, indices: Sequence[int]
              ) -> Iterator[tuple[int, np.ndarray]]:
    """Sends frame AT twice."""
    for k, frame in render_chunk(frames, times, indices):
        yield k, frame
        if k == AT:
            yield k, frame


def skip(frames: Any, times: np.ndarray, indices: Sequence[int]
         ) -> Iterator[tuple[int, np.ndarray]]:
    """Leaves frame AT out (the next frame of its chunk follows, or the chunk ends)."""
    for k, frame in render_chunk(frames, times, indices):
        if k != AT:
            yield k, frame


def unasked(frames: Any, times: np.ndarray, indices: Sequence[int]
            ) -> Iterator[tuple[int, np.ndarray]]:
    """Sends a frame after the chunk's last that nobody asked for."""
    for k, frame in render_chunk(frames, times, indices):
        yield k, frame
    if indices[0] <= AT <= indices[-1]:
        yield indices[-1] + 1000, frame


def fails(frames: Any, times: np.ndarray, indices: Sequence[int]
          ) -> Iterator[tuple[int, np.ndarray]]:
    """Raises at frame AT (as a broken driver or a bug in the overlay would)."""
    for k, frame in render_chunk(frames, times, indices):
        if k == AT:
            raise ValueError(f"planted failure at frame {k}\nsecond line")
        yield k, frame


def dies(frames: Any, times: np.ndarray, indices: Sequence[int]
         ) -> Iterator[tuple[int, np.ndarray]]:
    """The process ends at frame AT with a line on stderr and no reply (a crash in the driver,
    an OOM kill)."""
    for k, frame in render_chunk(frames, times, indices):
        if k == AT:
            sys.stderr.write(f"some warning\nplanted crash at frame {k}\n\n")
            sys.stderr.flush()
            os._exit(7)
        yield k, frame


def skip_last(frames: Any, times: np.ndarray, indices: Sequence[int]
              ) -> Iterator[tuple[int, np.ndarray]]:
    """Leaves out the last frame of the chunk that holds frame AT, then ends the chunk."""
    for k, frame in render_chunk(frames, times, indices):
        if not (k == indices[-1] and indices[0] <= AT <= indices[-1]):
            yield k, frame
