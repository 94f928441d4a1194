"""Recorded world points in the frame of a body of the run's own model (a positioner's mount):
the independent way the tests measure a weld relative to a part a mechanism moves (MuJoCo's
body pose from the recorded qpos, not cellsim's mechanism kinematics)."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def in_body_frame(run_dir: Path, body: str | None, qpos: np.ndarray, p: np.ndarray
                  ) -> np.ndarray:
    """World points ``p`` (N, 3) in the frame ``body`` had at each recorded ``qpos`` (N, nq),
    posed by ``run_dir/model.xml``; a copy of ``p`` for ``body = None`` (a fixed frame)."""
    if body is None:
        return p.copy()
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(run_dir / "model.xml"))
    data = mujoco.MjData(model)
    b = model.body(body).id
    out = np.zeros_like(p)
    for i, (q, x) in enumerate(zip(qpos, p, strict=True)):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        out[i] = data.xmat[b].reshape(3, 3).T @ (x - data.xpos[b])
    return out
