"""Tests of sim.analysis.report: the files a user hands to a colleague (sizing.csv/json/md, report.html)."""

from __future__ import annotations

import csv
import json
import math
import os
from html.parser import HTMLParser

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.window_oracle import sustained_peak

from sim.analysis.report import REQUIRED_COLUMNS, write_atomic, write_sizing
from sim.analysis.sizing import PEAK_WINDOW_S, size_trajectory
from sim.robots.registry import Drive

JOINTS = ("j1", "j2", "j3")
DRIVE = Drive(gear_ratio=100.0, efficiency=0.9, rotor_inertia=1e-4, rated_torque=1.5,
              peak_torque=4.0, max_speed_rpm=5000.0)


def make_result(seed: int = 0, forcerange: float = 100.0):
    rng = np.random.default_rng(seed)
    t = np.concatenate([[0.0], np.sort(rng.uniform(0, 3.0, 1500)), [3.0]])
    amp = np.array([30.0, 70.0, 15.0])
    tau_id = amp * np.sin(2 * np.pi * t / 3.0)[:, None]
    tau = tau_id + rng.normal(0, 0.5, tau_id.shape)
    qd = np.array([0.4, 0.8, 1.2]) * np.cos(2 * np.pi * t / 3.0)[:, None]
    qdd = -np.array([0.4, 0.8, 1.2]) * (2 * np.pi / 3.0) * np.sin(2 * np.pi * t / 3.0)[:, None]
    traj = dict(t=t, q_ref=qd * 0, qd_ref=qd, qdd_ref=qdd, q=qd * 0, qd=qd, qdd=qdd, tau=tau,
                tau_id=tau_id)
    phases = [{"name": "approach", "kind": "move", "t0": 0.0, "t1": 1.0},
              {"name": "weld", "kind": "weld", "t0": 1.0, "t1": 2.0},
              {"name": "return", "kind": "move", "t0": 2.0, "t1": 3.0}]
    res = size_trajectory(traj, JOINTS, drives=[DRIVE] * 3,
                          forcerange=[[-forcerange, forcerange]] * 3, speed_limits=[2.0] * 3,
                          armature=[DRIVE.reflected_inertia] * 3, robot="robot_5r",
                          scenario="weld_demo", phases=phases)
    return res, traj


def write_summary(run_dir):
    (run_dir / "summary.json").write_text(json.dumps({
        "scenario": "weld_demo", "robot": "robot_5r", "joints": list(JOINTS),
        "phases": [], "duration_s": 3.0}))


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    run_dir = tmp_path_factory.mktemp("run")
    write_summary(run_dir)
    (run_dir / "video.mp4").write_bytes(b"\x00\x00\x00\x18ftypmp42")
    res, traj = make_result()
    files = write_sizing(run_dir, res)
    return run_dir, res, traj, files


def test_csv_has_required_columns_and_values_recomputed_from_arrays(written) -> None:
    run_dir, res, traj, _ = written
    with open(run_dir / "sizing.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["joint"] for r in rows] == list(JOINTS)
    for col in REQUIRED_COLUMNS:
        assert col in rows[0], col
    t = traj["t"]
    for k, r in enumerate(rows):
        # Independent: numpy max, a trapezoid written out by hand over the samples, and the
        # simulated torque sustained over 5 ms (window_oracle)
        pk_id = np.abs(traj["tau_id"][:, k]).max()
        pk_sim = sustained_peak(t, traj["tau"][:, k], PEAK_WINDOW_S)
        assert float(r["peak_torque_id_nm"]) == pytest.approx(pk_id, rel=1e-8)
        assert float(r["peak_torque_sim_nm"]) == pytest.approx(pk_sim, rel=1e-8)
        assert float(r["peak_torque_nm"]) == pytest.approx(max(pk_id, pk_sim), rel=1e-8)
        sq = traj["tau"][:, k] ** 2
        area = sum((t[i + 1] - t[i]) * (sq[i] + sq[i + 1]) / 2 for i in range(t.size - 1))
        assert float(r["rms_torque_sim_nm"]) == pytest.approx(math.sqrt(area / 3.0), rel=1e-8)
        assert float(r["peak_speed_rad_s"]) == pytest.approx(np.abs(traj["qd"][:, k]).max())
        p = traj["tau_id"][:, k] * traj["qd_ref"][:, k]
        assert float(r["peak_power_id_w"]) == pytest.approx(np.abs(p).max(), rel=1e-8)
        limit = 100.0
        m = (limit - max(pk_id, pk_sim)) / limit * 100
        assert float(r["joint_torque_margin_pct"]) == pytest.approx(m, rel=1e-6)
        assert r["pass"] == ("PASS" if res.joints[k].passed else "FAIL")
        assert float(r["margin_pct"]) <= float(r["joint_torque_margin_pct"]) + 1e-9
        assert float(r["gear_ratio"]) == DRIVE.gear_ratio


def test_json_is_strict_and_matches_result(written) -> None:
    run_dir, res, _, _ = written

    def no_constants(name):
        raise AssertionError(f"non-standard JSON constant {name}")

    data = json.loads((run_dir / "sizing.json").read_text(), parse_constant=no_constants)
    assert data["hardest_joint"] == res.hardest.joint
    assert data["pass"] == res.passed
    assert [j["joint"] for j in data["joints"]] == list(JOINTS)
    assert data["joints"][1]["joint_side"]["id"]["peak_torque"] == pytest.approx(
        res.joints[1].stats["id"].peak_torque)


def test_markdown_has_table_verdict_and_existing_chart_links(written) -> None:
    run_dir, res, _, _ = written
    md = (run_dir / "sizing.md").read_text()
    assert res.verdict in md
    assert res.hardest.joint in res.verdict
    assert "| joint |" in md
    links = [line.split("](")[1].rstrip(")") for line in md.splitlines() if line.startswith("![")]
    assert len(links) == 1 + len(JOINTS)
    for link in links:
        png = (run_dir / link).read_bytes()
        assert png.startswith(b"\x89PNG\r\n\x1a\n")


class _Refs(HTMLParser):
    def __init__(self):
        super().__init__()
        self.refs: list[tuple[str, str, str]] = []
        self.tags: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        for name, value in attrs:
            if name in ("src", "href", "data", "poster", "srcset"):
                self.refs.append((tag, name, value or ""))


@pytest.mark.parametrize("with_video", [True, False])
def test_html_is_self_contained(tmp_path, with_video: bool) -> None:
    write_summary(tmp_path)
    if with_video:
        (tmp_path / "video.mp4").write_bytes(b"\x00")
    res, _ = make_result(seed=1)
    write_sizing(tmp_path, res)
    text = (tmp_path / "report.html").read_text()
    parser = _Refs()
    parser.feed(text)
    external = [r for r in parser.refs if not r[2].startswith("data:")]
    assert all(r[2] == "video.mp4" for r in external), external
    assert bool(external) == with_video
    images = [r for r in parser.refs if r[0] == "img"]
    assert len(images) == 1 + len(JOINTS)
    assert all(r[2].startswith("data:image/png;base64,") for r in images)
    assert "link" not in parser.tags and "script" not in parser.tags
    assert "url(" not in text  # no CSS fetches
    assert "weld_demo" in text and "robot_5r" in text
    import html as html_mod
    assert html_mod.escape(res.verdict) in text


def test_failing_run_says_fail_everywhere(tmp_path) -> None:
    res, _ = make_result(forcerange=50.0)  # j2 swings 70 N m against 50
    assert not res.passed
    write_sizing(tmp_path, res, charts=False)
    md = (tmp_path / "sizing.md").read_text()
    assert "FAIL" in res.verdict and "j2" in res.verdict
    assert res.verdict in md
    with open(tmp_path / "sizing.csv", newline="") as fh:
        rows = {r["joint"]: r for r in csv.DictReader(fh)}
    assert rows["j2"]["pass"] == "FAIL" and rows["j2"]["limiting"] == "joint_torque"
    assert float(rows["j2"]["margin_pct"]) < -30


def test_write_atomic_leaves_old_file_and_no_temp_on_failure(tmp_path, monkeypatch) -> None:
    target = tmp_path / "sizing.csv"
    write_atomic(target, "old\n")
    assert target.read_text() == "old\n"

    def boom(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", boom)
    with pytest.raises(OSError):
        write_atomic(target, "new\n")
    assert target.read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sizing.csv"]


def test_no_temporary_files_left_after_write(written) -> None:
    run_dir, *_ = written
    leftovers = [p for p in run_dir.rglob("*") if p.name.startswith(".") or p.suffix == ".tmp"]
    assert leftovers == []


@settings(max_examples=300, deadline=None)
@given(x=st.floats(min_value=-1e15, max_value=1e15, allow_nan=False),
       digits=st.integers(min_value=1, max_value=6))
def test_report_numbers_keep_their_digits_and_no_exponent_below_a_trillion(x, digits):
    """A report's number (num_text): the value to ``digits`` significant digits, read back
    within half a unit of its last digit, and no exponent for |x| from 1 up to 1e12 (a
    trial's report.html read "6e+03 rpm" for a motor's 6000 rpm)."""
    from sim.analysis.report_text import num_text

    text = num_text(x, digits)
    back = float(text)
    if x != 0:
        assert abs(back - x) <= 0.5 * 10 ** (math.floor(math.log10(abs(x))) + 1 - digits) \
            * (1 + 1e-9) + 1e-300
    if 1 <= abs(back) < 1e12:
        assert "e" not in text, text
    assert num_text(float("nan"), digits) == "n/a" and num_text(float("inf"), digits) == "n/a"
