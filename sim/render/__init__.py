"""Headless rendering of recorded runs: run folders, state interpolation, overlays, frames.

Modules (none imports mujoco at import time, so :func:`sim.render.gl.configure_gl` can still choose
the OpenGL backend after they are imported):

* :mod:`sim.simulation.runfolder`: :class:`RunRecord`, :func:`load_run` (the run folder format);
* :mod:`sim.render.interp`: ``qpos`` at video frame times (lerp / quaternion slerp);
* :mod:`sim.render.overlay`: tool-point trails, weld bead, caption;
* :mod:`sim.render.frames`: :class:`FrameRenderer` (one OpenGL context, cameras tiled);
* :mod:`sim.render.synthetic`: a small demo cell and run folder for tests and benchmarks.

Videos: :func:`sim.render.video.write_video`; plots: :func:`sim.analysis.plots.write_plots`.
"""

from sim.simulation.runfolder import Phase, RunFolderError, RunRecord, load_run

__all__ = ["Phase", "RunFolderError", "RunRecord", "load_run"]
