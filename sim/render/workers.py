"""A run's video frames rendered by several processes and delivered in order.

:class:`FramePool` starts ``jobs`` worker processes, each a fresh interpreter (``python -c``,
the parent's ``sys.path``; no OpenGL context, MuJoCo model or Mesa state is inherited, and,
unlike multiprocessing's ``spawn``, the parent's main script is not run again: a script without
an ``if __name__ == "__main__"`` guard may render too). A worker adopts the parent's OpenGL
backend (:func:`sim.render.gl.adopt_backend`, no second probe) before anything imports
mujoco, opens its own :class:`~sim.render.frames.FrameRenderer` (its own offscreen context) on
the run, and renders the chunks of frame indices the parent sends it, sending each frame back
through its pipe. The run reaches a worker as a copy of the record with only the arrays the
frames read (:func:`render_record`: a few MB where a whole recording is about a hundred); a
record read from a folder or built by the pipeline names its ``model.xml`` by path.

The parent hands out chunks in index order, each to the worker with the least work queued,
at most ``in_flight`` frames ahead of the next one it delivers, so that its reorder buffer
stays bounded; :meth:`FramePool.frames` yields ``(index, frame)`` for ``index = 0 .. n - 1``,
each exactly once, as soon as each is there. A worker must send the frames of its chunk, in
order, then say the chunk is done: a frame twice, one missing or one not asked for is a
:class:`~sim.errors.RenderError`, as is a worker that fails (its error's message; a cellsim
error, such as an unknown camera, keeps its class and message) or dies (its exit code and the
last line it wrote: a worker's standard error goes to a temporary file, so that a crash is
still one line).

Closing the pool (always: use it as a context manager) stops the workers: the parent closes
its ends of their pipes (a worker waiting for work or sending a frame then ends, closing its
renderer), waits for them, and terminates, then kills, any that does not end in time. A
worker whose parent died sees its pipe closed and ends too. Workers run in their own process
group, so a Ctrl-C at the terminal interrupts the parent only, which then stops them.

Mesa's llvmpipe starts one rasterizer thread per core in every process. With ``jobs > 1``
and no ``LP_NUM_THREADS`` in the environment, the workers get ``LP_NUM_THREADS=1``: the
processes share the cores instead of each splitting every frame across all of them
(``benchmarks/bench_video.py --lp-threads`` measures both).
"""

from __future__ import annotations

import multiprocessing as mp
import os
import subprocess
import sys
import tempfile
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, replace
from multiprocessing.connection import Connection, wait
from typing import Any

import numpy as np

from sim.errors import RenderError
from sim.render.overlay import OverlayStyle
from sim.simulation.runfolder import RunRecord

#: Arrays a frame reads (state, trails, bead); a cell's other robots' as ``<name>_<key>``.
RENDER_ARRAYS: tuple[str, ...] = ("t", "qpos", "phase", "arc_on", "tcp_pos", "tcp_pos_ref")
_PER_ROBOT = ("_tcp_pos", "_tcp_pos_ref", "_arc_on")

#: Frames per chunk a worker is sent at a time (two chunks may wait for it).
CHUNK = 4
#: Most bytes of frames rendered ahead of the one the encoder waits for.
MAX_BUFFER_BYTES = 256 << 20
#: Seconds a worker gets to end after its pipe is closed before it is terminated.
JOIN_S = 10.0

#: ``chunk_renderer(frames, times, indices)`` yields ``(index, frame)`` for the chunk's
#: indices, in order: :func:`render_chunk`, or a test's planted fault.
ChunkRenderer = Callable[[Any, np.ndarray, Sequence[int]], Iterator[tuple[int, np.ndarray]]]


def usable_cores() -> int:
    """Cores this process may run on (its CPU affinity), at least 1."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # no sched_getaffinity (macOS)
        return max(1, os.cpu_count() or 1)


def render_record(record: RunRecord) -> RunRecord:
    """``record`` with only the arrays frames read (:data:`RENDER_ARRAYS`, and each other
    robot's tool point and arc), for a worker: what a frame shows does not change."""
    keep = {name: value for name, value in record.arrays.items()
            if name in RENDER_ARRAYS or name.endswith(_PER_ROBOT)}
    return replace(record, arrays=keep)


def render_chunk(frames: Any, times: np.ndarray, indices: Sequence[int]
                 ) -> Iterator[tuple[int, np.ndarray]]:
    """The frames of one chunk (no caption: the parent draws it), in order."""
    for k in indices:
        yield k, frames.render(float(times[k]), caption=False)


@dataclass(frozen=True)
class FrameJob:
    """What every worker renders.

    Attributes:
        record: The run (:func:`render_record` trims it).
        times: Frame times, s; frame ``k`` is the state at ``times[k]``.
        cameras: Camera names, tiled left to right.
        width: Tile width, pixels.
        height: Tile height, pixels.
        gl: The OpenGL backend the parent chose (``"egl"``, ``"osmesa"``).
        overlay: Draw trails and bead.
        style: Overlay colours and sizes.
    """

    record: RunRecord
    times: np.ndarray
    cameras: tuple[str, ...]
    width: int
    height: int
    gl: str
    overlay: bool = True
    style: OverlayStyle | None = None

    @property
    def frame_shape(self) -> tuple[int, int, int]:
        """Shape of one frame, (height, width * n_cameras, 3)."""
        return (self.height, self.width * len(self.cameras), 3)


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


#: What a worker process runs (``python -c``; argv[1]: its end of the pipe): the parent's
#: ``sys.path`` first, then :func:`serve`.
_BOOT = ("import sys\n"
         "from multiprocessing.connection import Connection\n"
         "conn = Connection(int(sys.argv[1]))\n"
         "sys.path[:] = conn.recv()\n"
         "from sim.render.workers import serve\n"
         "serve(conn)\n")


def serve(conn: Connection) -> None:
    """A worker's life: the job, then chunks until told to stop or the pipe closes."""
    try:
        job, chunk_renderer = conn.recv()
        from sim.render.gl import adopt_backend

        adopt_backend(job.gl)  # before mujoco is imported
        from sim.render.frames import FrameRenderer

        with FrameRenderer(job.record, cameras=job.cameras, width=job.width, height=job.height,
                           overlay=job.overlay, caption=False, gl=job.gl,
                           style=job.style) as frames:
            while True:
                task = conn.recv()
                if task is None:
                    return
                chunk_id, indices = task
                for k, frame in chunk_renderer(frames, job.times, indices):
                    conn.send(("frame", int(k)))
                    flat = np.ascontiguousarray(frame, dtype=np.uint8).reshape(-1)
                    conn.send_bytes(flat.data)
                conn.send(("done", chunk_id))
    except (EOFError, BrokenPipeError, ConnectionResetError):
        return  # the parent closed the pipe (stopped early) or is gone
    except BaseException as exc:  # noqa: BLE001 - reported to the parent as one line
        try:
            conn.send(("error", type(exc).__name__, _first_line(exc)))
        except OSError:
            pass
    finally:
        conn.close()


def _worker_error(who: str, cls: str, message: str) -> Exception:
    """A worker's error in the parent: a cellsim error keeps its class and message (the same
    line as in one process), anything else is a RenderError naming the worker."""
    import sim.errors as errors

    known = getattr(errors, cls, None)
    if isinstance(known, type) and issubclass(known, errors.CellsimError):
        return known(message)
    return RenderError(f"video {who} failed: {cls}: {message}")


class FramePool:
    """Worker processes rendering one job's frames; see the module docstring.

    Args:
        job: The frames to render.
        jobs: Worker processes (at most one per frame).
        chunk_renderer: How a worker renders a chunk (a module-level function: it is sent to
            the workers by name); :func:`render_chunk` unless a test plants a fault.
        chunk: Frames per chunk.
    """

    def __init__(self, job: FrameJob, jobs: int, *, chunk_renderer: ChunkRenderer | None = None,
                 chunk: int = CHUNK) -> None:
        n = len(job.times)
        self.job = replace(job, record=render_record(job.record))
        self.jobs = max(1, min(int(jobs), n))
        self.shape = job.frame_shape
        frame_bytes = max(1, int(np.prod(self.shape)))
        self.in_flight = max(2 * self.jobs,
                             min(3 * chunk * self.jobs, MAX_BUFFER_BYTES // frame_bytes))
        self.chunk = max(1, min(chunk, self.in_flight // (2 * self.jobs)))
        self.chunk_renderer = chunk_renderer or render_chunk
        self.processes: list[subprocess.Popen[bytes]] = []
        self.conns: list[Connection] = []
        self.logs: list[Any] = []  # each worker's stderr (the last line explains a crash)
        self._done = False

    # -- life cycle ---------------------------------------------------------------------
    def start(self) -> None:
        """Starts the workers and sends each the job."""
        env = dict(os.environ)
        if self.jobs > 1:
            env.setdefault("LP_NUM_THREADS", "1")
        for _ in range(self.jobs):
            parent, child = mp.Pipe(duplex=True)
            log = tempfile.TemporaryFile()
            try:
                process = subprocess.Popen(
                    [sys.executable, "-c", _BOOT, str(child.fileno())], env=env,
                    pass_fds=(child.fileno(),), stdin=subprocess.DEVNULL, stderr=log,
                    process_group=0)
            except BaseException:
                parent.close()
                log.close()
                raise
            finally:
                child.close()  # the parent's copy: a worker that ends closes the pipe
            self.processes.append(process)
            self.conns.append(parent)
            self.logs.append(log)
        for w, conn in enumerate(self.conns):  # each reads it once its interpreter is up
            try:
                conn.send(list(sys.path))
                conn.send((self.job, self.chunk_renderer))
            except OSError:
                raise RenderError(f"video {self._who(w)} did not start{self._said(w)}"
                                  ) from None

    def close(self) -> None:
        """Stops every worker (idempotent): pipes closed, waited for, terminated if need be."""
        for conn in self.conns:
            try:
                if self._done:
                    conn.send(None)
            except OSError:
                pass
            conn.close()
        for process in self.processes:
            for stop in (None, process.terminate, process.kill):
                if stop is not None:
                    stop()
                try:
                    process.wait(JOIN_S)
                    break
                except subprocess.TimeoutExpired:
                    continue
        for log in self.logs:
            log.close()
        self.processes, self.conns, self.logs = [], [], []

    def __enter__(self) -> FramePool:
        try:
            self.start()
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- frames -------------------------------------------------------------------------
    def _who(self, w: int) -> str:
        return f"worker {w + 1} of {self.jobs}"

    def frames(self) -> Iterator[tuple[int, np.ndarray]]:
        """``(index, frame)`` for every frame, in index order, each once.

        Raises:
            RenderError: A worker failed, died, or sent a frame twice, out of order, or not
                at all (a cellsim error of a worker is raised as itself).
        """
        n = len(self.job.times)
        self._queued: list[deque[tuple[int, deque[int]]]] = [deque() for _ in self.conns]
        self._seen = np.zeros(n, dtype=bool)
        self._buffer: dict[int, np.ndarray] = {}
        self._next_chunk = 0
        out = 0
        while out < n:
            self._dispatch(out)
            while out in self._buffer:
                yield out, self._buffer.pop(out)
                out += 1
                self._dispatch(out)
            if out < n:
                self._receive()
        self._done = True

    def _dispatch(self, out: int) -> None:
        """Hands out chunks while the window ahead of frame ``out`` has room."""
        n = len(self.job.times)
        while self._next_chunk < n and self._next_chunk - out < self.in_flight:
            loads = [sum(len(c) for _, c in q) if len(q) < 2 else None for q in self._queued]
            free = [w for w, load in enumerate(loads) if load is not None]
            if not free:
                return
            w = min(free, key=lambda i: loads[i] or 0)
            start = self._next_chunk
            stop = min(n, start + self.chunk, out + self.in_flight)
            indices = list(range(start, stop))
            self._queued[w].append((start, deque(indices)))
            self.conns[w].send((start, indices))
            self._next_chunk = stop

    def _receive(self) -> None:
        """Waits for at least one message from a worker and handles what came."""
        for conn in wait(self.conns):
            w = self.conns.index(conn)  # type: ignore[arg-type]
            while self.conns[w].poll():
                self._handle(w)

    def _handle(self, w: int) -> None:
        """One message of worker ``w``: a frame (checked against its chunk), a chunk's end, or
        its error."""
        conn = self.conns[w]
        try:
            message = conn.recv()
        except (EOFError, ConnectionResetError):  # reset: it ended with work still unread
            raise RenderError(f"video {self._who(w)} ended unexpectedly{self._said(w)}"
                              ) from None
        kind = message[0] if isinstance(message, tuple) and message else None
        if kind == "error":
            raise _worker_error(self._who(w), str(message[1]), str(message[2]))
        queue = self._queued[w]
        if kind == "frame":
            k = int(message[1])
            expected = queue[0][1][0] if queue and queue[0][1] else None
            if k != expected:
                raise RenderError(self._misfit(w, k, expected))
            frame = np.empty(self.shape, np.uint8)
            try:
                size = conn.recv_bytes_into(frame.reshape(-1).data)
            except (EOFError, ConnectionResetError):
                raise RenderError(f"video {self._who(w)} ended while sending frame {k}"
                                  ) from None
            if size != frame.nbytes:
                raise RenderError(f"video {self._who(w)} sent frame {k} of {size} bytes, "
                                  f"expected {frame.nbytes}")
            queue[0][1].popleft()
            self._seen[k] = True
            self._buffer[k] = frame
        elif kind == "done":
            if not queue or queue[0][0] != message[1] or queue[0][1]:
                missing = queue[0][1][0] if queue and queue[0][1] else message[1]
                raise RenderError(f"video {self._who(w)} ended a chunk without frame {missing}")
            queue.popleft()
        else:
            raise RenderError(f"video {self._who(w)} sent an unexpected message "
                              f"{str(message)[:80]}")

    def _said(self, w: int) -> str:
        """`` (exit code N: <its last line on stderr>)`` of an ended worker."""
        try:
            code: int | None = self.processes[w].wait(JOIN_S)
        except subprocess.TimeoutExpired:
            code = None
        last = ""
        try:
            log = self.logs[w]
            log.seek(max(0, log.seek(0, os.SEEK_END) - 4096))
            lines = [ln.strip() for ln in log.read().decode(errors="replace").splitlines()]
            last = next((ln for ln in reversed(lines) if ln), "")
        except (OSError, IndexError):
            pass
        return f" (exit code {code}{': ' + last[:200] if last else ''})"

    def _misfit(self, w: int, k: int, expected: int | None) -> str:
        """Why frame ``k`` from worker ``w`` is refused (``expected``: the one it owed)."""
        if 0 <= k < len(self._seen) and self._seen[k]:
            return f"video {self._who(w)} sent frame {k} twice"
        queue = self._queued[w]
        if expected is not None and queue and k in queue[0][1]:
            return f"video {self._who(w)} skipped frame {expected} (sent {k} after it)"
        return f"video {self._who(w)} sent frame {k}, which it was not asked for"
