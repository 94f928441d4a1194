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


def _knot_ticks(ax) -> np.ndarray:
    """x of the knot ticks: the one LineCollection of short verticals on the time axis."""
    (ticks,) = [c for c in ax.collections if c.__class__.__name__ == "LineCollection"]
    segs = ticks.get_segments()
    assert all(seg[0, 0] == seg[1, 0] and seg[1, 1] - seg[0, 1] < 0.05 for seg in segs)
    return np.sort([seg[0, 0] for seg in segs])


def test_joint_figure_shows_q_qd_qdd_qddd_in_degrees_with_knot_ticks(run_dir: Path) -> None:
    """Position to jerk in the scenario's unit (deg); knots as short ticks on the time axis,
    none closer than 1/80 of the axis, every knot within that of a tick; no markers on the
    curves."""
    record = load_run(run_dir)
    t = record.t
    knots = np.sort(record.get("knot_t"))
    for j in range(len(JOINTS)):
        fig = joint_figure(record, j)
        axes = fig.get_axes()
        assert len(axes) == 4
        for ax, key, unit in zip(axes, ("q_ref", "qd_ref", "qdd_ref", "qddd_ref"),
                                 ("[deg]", "[deg/s]", "[deg/s²]", "[deg/s³]")):
            ref, *rest = ax.get_lines()
            np.testing.assert_array_equal(ref.get_xdata(), t)
            np.testing.assert_allclose(ref.get_ydata(), np.degrees(record.get(key)[:, j]))
            assert unit in ax.get_ylabel()
            assert not [line for line in rest if line.get_marker() not in ("None", None, "")]
            ticks = _knot_ticks(ax)
            span = np.subtract(*ax.get_xlim()[::-1])
            assert np.all(np.diff(ticks) >= span / 80 - 1e-9)
            assert np.all(np.min(np.abs(knots[:, None] - ticks[None, :]), axis=1)
                          < span / 80 + 1e-9)
        simulated = [line for line in axes[0].get_lines() if line.get_label() == "simulated"]
        np.testing.assert_allclose(simulated[0].get_ydata(), np.degrees(record.get("q")[:, j]))


def test_tool_path_figure_in_mm_with_equal_axes(run_dir: Path) -> None:
    record = load_run(run_dir)
    fig = tool_path_figure(record)
    ax3d, ax2d = fig.get_axes()
    lines = {line.get_label(): line for line in ax3d.get_lines()}
    ref_x, ref_y, ref_z = lines["reference"].get_data_3d()
    np.testing.assert_allclose(np.stack([ref_x, ref_y, ref_z], 1),
                               1000.0 * record.get("tcp_pos_ref"))
    seam = lines["seam (arc on)"].get_data_3d()
    arc = record.get("arc_on")
    np.testing.assert_allclose(np.stack(seam, 1), 1000.0 * record.get("tcp_pos")[arc])
    spans = [np.subtract(*lim[::-1]) for lim in (ax3d.get_xlim(), ax3d.get_ylim(),
                                                 ax3d.get_zlim())]
    assert max(spans) == pytest.approx(min(spans))  # one scale on every axis
    assert "[mm]" in ax3d.get_xlabel()
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
        deg = ea.get_lines()[0].get_ydata()
        np.testing.assert_allclose(np.radians(deg),
                                   record.get("q")[:, j] - record.get("q_ref")[:, j])
        assert JOINTS[j] in ea.get_ylabel() and "[deg]" in ea.get_ylabel()
        id_line, sim_line = ta.get_lines()[:2]
        np.testing.assert_array_equal(id_line.get_ydata(), record.get("tau_id")[:, j])
        np.testing.assert_array_equal(sim_line.get_ydata(), record.get("tau")[:, j])


@pytest.mark.parametrize("durations", [
    [1.0, 1.0, 1.0], [10.0, 0.05, 0.05, 0.05, 0.05, 10.0], [0.2] * 40,
    [30.0, 0.3, 0.2, 1.5, 0.4, 0.1, 54.0, 1.2, 2.5]])
def test_phase_labels_never_overlap(durations) -> None:
    """However short the phases, no two phase labels overlap once drawn."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from sim.analysis.plots import shade_phases

    t = np.concatenate([[0.0], np.cumsum(durations)])
    phases = [{"name": f"phase_{k}_name", "t0": t[k], "t1": t[k + 1]}
              for k in range(len(durations))]
    fig = Figure(figsize=(10, 3), dpi=100, layout="constrained")
    ax = fig.subplots()
    ax.plot(t, t)
    texts = shade_phases(ax, phases, label=True)
    FigureCanvasAgg(fig).draw()
    boxes = [tx.get_window_extent() for tx in texts]
    assert texts  # at least the long phases are named
    for a in range(len(boxes)):
        for b in range(a + 1, len(boxes)):
            assert not boxes[a].overlaps(boxes[b]), (texts[a].get_text(), texts[b].get_text())
        inside = ax.get_window_extent()
        assert inside.x0 - 1 <= boxes[a].x0 and boxes[a].x1 <= inside.x1 + 1


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
