"""PNG plots of a run: files, sizes, and that each plot shows the run's data."""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np
import pytest

from sim.analysis.plots import (
    FIGURE_SIZES,
    joint_figure,
    png_size,
    tool_path_figure,
    torque_figure,
    tracking_error_figure,
    write_plots,
)
from sim.render.synthetic import JOINTS, write_synthetic_run
from sim.simulation.runfolder import RunFolderError, RunRecord, load_run


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_synthetic_run(tmp_path_factory.mktemp("plots") / "run", duration=2.0, rate=50.0)


def _png_header(path: Path) -> tuple[int, int]:
    """(width, height) from the PNG signature and IHDR chunk, its CRC checked."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path.name} is not a PNG"
    length, ctype = struct.unpack(">I4s", data[8:16])
    assert ctype == b"IHDR" and length == 13
    body = data[16 : 16 + length]
    (crc,) = struct.unpack(">I", data[16 + length : 20 + length])
    assert zlib.crc32(ctype + body) == crc
    assert data.endswith(b"IEND\xaeB`\x82")
    width, height = struct.unpack(">II", body[:8])
    return width, height


def test_write_plots_one_png_per_kind_of_the_expected_size(run_dir: Path) -> None:
    import imageio.v3 as iio

    paths = write_plots(run_dir)
    names = [p.name for p in paths]
    assert names == [f"joint_{j}.png" for j in JOINTS] + [
        "tool_path.png", "tracking_error.png", "torques.png"]
    assert all(p.parent == run_dir / "plots" and p.is_file() for p in paths)
    for path in paths:
        kind = "joint" if path.name.startswith("joint_") else path.stem
        assert _png_header(path) == png_size(kind)
        w, h = FIGURE_SIZES[kind]
        image = iio.imread(path)
        assert image.shape[:2] == (round(h * 100), round(w * 100))
        assert image[..., :3].std() > 10  # something is drawn


def test_joint_figure_shows_q_qd_qdd_qddd_and_knots(run_dir: Path) -> None:
    record = load_run(run_dir)
    t = record.t
    knots = record.get("knot_t")
    for j in range(len(JOINTS)):
        fig = joint_figure(record, j)
        axes = fig.get_axes()
        assert len(axes) == 4
        for ax, key in zip(axes, ("q_ref", "qd_ref", "qdd_ref", "qddd_ref")):
            ref, *rest = ax.get_lines()
            np.testing.assert_array_equal(ref.get_xdata(), t)
            np.testing.assert_array_equal(ref.get_ydata(), record.get(key)[:, j])
            marker = next(line for line in rest if line.get_label() == "knots")
            np.testing.assert_allclose(marker.get_xdata(), knots)
            expected = np.interp(knots, t, record.get(key)[:, j])
            np.testing.assert_allclose(marker.get_ydata(), expected)
            # knot lines: one vertical segment per knot (a single LineCollection)
            (knot_lines,) = [c for c in ax.collections
                             if c.__class__.__name__ == "LineCollection"]
            xs = sorted(seg[0, 0] for seg in knot_lines.get_segments())
            assert all(seg[0, 0] == seg[1, 0] for seg in knot_lines.get_segments())
            np.testing.assert_allclose(xs, np.sort(knots))
        simulated = [line for line in axes[0].get_lines() if line.get_label() == "simulated"]
        np.testing.assert_array_equal(simulated[0].get_ydata(), record.get("q")[:, j])


def test_tool_path_figure_draws_reference_actual_seam_and_error(run_dir: Path) -> None:
    record = load_run(run_dir)
    fig = tool_path_figure(record)
    ax3d, ax2d = fig.get_axes()
    lines = {line.get_label(): line for line in ax3d.get_lines()}
    ref_x, ref_y, ref_z = lines["reference"].get_data_3d()
    np.testing.assert_allclose(np.stack([ref_x, ref_y, ref_z], 1), record.get("tcp_pos_ref"))
    seam = lines["seam (arc on)"].get_data_3d()
    arc = record.get("arc_on")
    np.testing.assert_allclose(np.stack(seam, 1), record.get("tcp_pos")[arc])
    (err,) = ax2d.get_lines()
    expected = 1000.0 * np.linalg.norm(record.get("tcp_pos") - record.get("tcp_pos_ref"), axis=1)
    np.testing.assert_allclose(err.get_ydata(), expected)
    assert expected.max() > 1.0  # the synthetic actual path lags the reference


def test_tracking_error_and_torque_figures(run_dir: Path) -> None:
    record = load_run(run_dir)
    err_axes = [ax for ax in tracking_error_figure(record).get_axes() if ax.get_visible()]
    trq_axes = [ax for ax in torque_figure(record).get_axes() if ax.get_visible()]
    assert len(err_axes) == len(trq_axes) == len(JOINTS)
    for j, (ea, ta) in enumerate(zip(err_axes, trq_axes)):
        mrad = ea.get_lines()[0].get_ydata()
        np.testing.assert_allclose(mrad / 1000.0, record.get("q")[:, j] - record.get("q_ref")[:, j])
        assert JOINTS[j] in ea.get_ylabel() and "mrad" in ea.get_ylabel()
        id_line, sim_line = ta.get_lines()[:2]
        np.testing.assert_array_equal(id_line.get_ydata(), record.get("tau_id")[:, j])
        np.testing.assert_array_equal(sim_line.get_ydata(), record.get("tau")[:, j])


def test_plots_need_their_arrays(run_dir: Path, tmp_path: Path) -> None:
    base = load_run(run_dir)
    arrays = {k: v for k, v in base.arrays.items() if k not in ("tau_id", "qddd_ref")}
    record = RunRecord.from_arrays(arrays, joints=base.joints, model_path=base.model_path)
    with pytest.raises(RunFolderError, match="lacks qddd_ref, tau_id"):
        write_plots(record, tmp_path)
    with pytest.raises(ValueError, match="out_dir is required"):
        write_plots(RunRecord.from_arrays(base.arrays, joints=base.joints))
    with pytest.raises(RunFolderError, match="does not exist"):
        write_plots(tmp_path / "missing")
