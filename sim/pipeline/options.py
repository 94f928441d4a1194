"""The kind of each of a run's options (:class:`~sim.pipeline.run.RunOptions`), checked as
they are made.

A script's ``RunOptions(video="yes")`` was taken, ``feedforward="no"`` ran with the
feed-forward on (the text is true), ``video_args={"fsp": 5}`` and ``video_args=[1, 2]`` met a
``TypeError`` or ``AttributeError`` once the run was simulated: found by a new-user trial.
Each option now takes its kind or is refused in one line naming it
(:class:`~sim.errors.UsageError`).
"""

from __future__ import annotations

import inspect
from collections.abc import Mapping
from typing import Any

from sim.core.arguments import choice_argument, flag_argument, got, optional_path_argument
from sim.errors import UsageError

#: The run's simulation backends (:mod:`sim.simulation.warp_batch` for ``"warp"``).
BACKENDS = ("mujoco", "warp")
#: Options that are ``True`` or ``False``.
FLAGS = ("video", "plots", "sizing", "progress", "csv")


def video_keys() -> tuple[str, ...]:
    """The settings ``video_args`` takes: :func:`sim.render.video.write_video`'s keyword
    arguments."""
    from sim.render.video import write_video

    return tuple(name for name, p in inspect.signature(write_video).parameters.items()
                 if p.kind is inspect.Parameter.KEYWORD_ONLY)


def check_run_options(options: Any) -> None:
    """Refuse an option of the wrong kind: one line naming ``RunOptions.<field>``.

    Raises:
        UsageError: A flag that is not ``True``/``False`` (``feedforward`` may be None too),
            an ``out_dir`` that is not a path, ``video_args`` that is not a mapping of
            :func:`video_keys`, an unknown ``backend``.
    """
    for name in FLAGS:
        flag_argument(getattr(options, name), f"RunOptions.{name}")
    flag_argument(options.feedforward, "RunOptions.feedforward", optional=True)
    optional_path_argument(options.out_dir, "RunOptions.out_dir")
    choice_argument(options.backend, "RunOptions.backend", BACKENDS)
    _check_selection(options.selection)
    args = options.video_args
    if not isinstance(args, Mapping):
        raise UsageError("RunOptions.video_args: expected a mapping of video settings like "
                         f"{{'fps': 15, 'width': 640}}, got {got(args)}", key="video_args")
    if args:
        known = video_keys()
        for key in args:
            if key not in known:
                raise UsageError(f"RunOptions.video_args: unknown setting {key!r}; known: "
                                 f"{', '.join(known)}", key="video_args")


def _check_selection(selection: Any) -> None:
    """``RunOptions.selection``: None (the scenario's ``[sizing] select`` decides), True or
    False, a catalogue file's path, or the loaded settings
    (:class:`~sim.analysis.selection.SelectionOptions`); else one line naming it."""
    import os

    from sim.analysis.selection import SelectionOptions

    if selection is None or isinstance(selection, (bool, str, os.PathLike, SelectionOptions)):
        if isinstance(selection, str) and not selection.strip():
            raise UsageError("RunOptions.selection: an empty catalogue path",
                             key="selection")
        return
    raise UsageError("RunOptions.selection: expected True or False, a catalogue file's path "
                     f"or None (the scenario's [sizing] select decides), got {got(selection)}",
                     key="selection")


def changed_options(options: Any, changes: Mapping[str, Any]) -> Any:
    """``options`` with ``changes`` (fields of :class:`~sim.pipeline.run.RunOptions`), each
    checked; an unknown field is refused in one line listing the known ones."""
    import dataclasses

    known = [f.name for f in dataclasses.fields(options)]
    for key in changes:
        if key not in known:
            raise UsageError(f"{key}: not an option of a run; known: {', '.join(known)}",
                             key=key)
    return dataclasses.replace(options, **changes)


__all__ = ["BACKENDS", "FLAGS", "changed_options", "check_run_options", "video_keys"]
