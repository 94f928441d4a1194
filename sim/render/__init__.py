"""Render layer: headless OpenGL, frames, overlays and videos of recorded runs.

May import: planners and every layer up to :mod:`sim.analysis` (it reads runs through
:mod:`sim.simulation.runfolder`).

Modules (none imports mujoco at import time, so :func:`sim.render.gl.configure_gl` can still choose
the OpenGL backend after they are imported):

* :mod:`sim.render.gl`: the OpenGL backend (EGL, OSMesa), chosen before mujoco is imported;
* :mod:`sim.render.video`: :func:`write_video` (H.264 through imageio-ffmpeg);
* :mod:`sim.render.interp`: ``qpos`` at video frame times (lerp / quaternion slerp);
* :mod:`sim.render.overlay`: tool-point trails, weld bead, caption;
* :mod:`sim.render.frames`: :class:`FrameRenderer` (one OpenGL context, cameras tiled);
* :mod:`sim.render.synthetic`: a small demo cell and run folder for tests and benchmarks.

The run folder format is :mod:`sim.simulation.runfolder`; plots are
:func:`sim.analysis.plots.write_plots`.
"""

