"""A MUJOCO_GL that mujoco refuses breaks only rendering, with one line saying so."""

from __future__ import annotations

import os
import sys

import pytest
from support.limits import run_limited


def _cellsim(args, tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "PYOPENGL_PLATFORM")}
    env["MUJOCO_GL"] = "bogus"
    return run_limited([sys.executable, "-m", "sim", *args], env=env, cwd=tmp_path,
                          capture_output=True, text=True, cpu_s=300, check=False)


@pytest.mark.slow  # the fast share's ten minutes (issue 29): four commands in child processes
def test_commands_that_do_not_render_ignore_a_bogus_mujoco_gl(tmp_path):
    assert _cellsim(["list"], tmp_path).returncode == 0
    assert _cellsim(["ik", "lrmate100ib", "660.56", "0", "5.17"], tmp_path).returncode == 0
    res = _cellsim(["run", "kacso_lrmate100ib_sequence1", "--no-video", "--no-plots", "--quiet",
                    "--out", str(tmp_path / "run")], tmp_path)
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "run" / "summary.json").is_file()


def test_rendering_with_a_bogus_mujoco_gl_says_what_to_set(tmp_path):
    res = _cellsim(["run", "kacso_lrmate100ib_sequence1", "--no-plots", "--quiet",
                    "--out", str(tmp_path / "run")], tmp_path)
    assert res.returncode == 2
    err = res.stderr.strip()
    assert "\n" not in err and "MUJOCO_GL='bogus'" in err and "egl" in err, err
    assert "Traceback" not in res.stderr
    assert not (tmp_path / "run").exists()
