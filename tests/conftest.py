"""Shared pytest configuration for cellsim."""

from __future__ import annotations

import os

# Headless rendering: choose EGL by default before anything imports mujoco; sim.gl may
# override this with a working backend.
os.environ.setdefault("MUJOCO_GL", "egl")
