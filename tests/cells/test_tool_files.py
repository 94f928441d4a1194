"""The shipped tools are tool files (``models/tools``) read by the reader users' tools go
through (:mod:`sim.cells.toolfile`): each compiles to exactly the model the Python builders it
replaced gave; the keys it needs (per-shape masses, a body name, a ``[suction]`` table) are
checked like every other key; a user's own suction gripper picks a part."""

from __future__ import annotations

import re
from pathlib import Path

import mujoco
import numpy as np
import pytest

from sim.cells.toolfile import load_tool_file
from sim.cells.tools import CUP_BODY, SUCTION_ACTUATOR, TOOLS, build_tool, tools_dir
from sim.core.resources import scenarios_dir

#: The MJCF the Python builders gave (``dm_control``'s text, 17 significant digits), recorded
#: before they were replaced by the files.
ORACLE = Path(__file__).resolve().parents[1] / "data" / "tools"


@pytest.mark.parametrize("name", ["mig_torch", "mig_torch_long", "vacuum_gripper"])
def test_a_shipped_tool_file_gives_the_old_builders_model(name):
    spec = TOOLS[name]
    assert spec.shipped and spec.source == (tools_dir() / f"{name}.toml").resolve()
    assert build_tool(spec).to_xml_string() == (ORACLE / f"{name}.xml").read_text()


def test_the_shipped_tools_keep_their_specs():
    torch, long_, cup = TOOLS["mig_torch"], TOOLS["mig_torch_long"], TOOLS["vacuum_gripper"]
    assert list(TOOLS) == ["mig_torch", "mig_torch_long", "vacuum_gripper"]
    assert (torch.mass_kg, torch.length_m, torch.kind, torch.work_geoms) == (
        1.0, 0.145, "torch", ("wire",))
    assert (long_.mass_kg, long_.length_m) == (1.7, 0.3)
    assert (torch.stickout_m, torch.touch_depth_m, torch.max_payload_kg) == (0.015, 0.0005, None)
    assert (cup.mass_kg, cup.length_m, cup.kind, cup.suction_gain_n) == (
        0.25, 0.1, "gripper", 40.0)
    assert cup.work_geoms == tuple(f"lip{k}" for k in range(8))
    assert cup.max_payload_kg == 40.0 / (9.80665 * 2.0)
    assert all(t.straight for t in TOOLS.values())


#: A user's own suction gripper: a stem and a cup of six lips on a 14 mm ring, 120 mm out.
MY_GRIPPER = """\
name = "my_cup"
kind = "gripper"
mass_kg = 0.3
tcp_mm = [0, 0, 120]
[[shapes]]
shape = "cylinder"
radius_mm = 20
from_mm = [0, 0, 0]
to_mm = [0, 0, 100]
[suction]
gain_n = 30
lip_count = 6
lip_ring_radius_mm = 14
[[suction.shapes]]
name = "bellows"
shape = "cylinder"
radius_mm = 15
from_mm = [0, 0, 100]
to_mm = [0, 0, 115]
"""


def test_a_users_suction_gripper_file(tmp_path):
    (tmp_path / "g.toml").write_text(MY_GRIPPER)
    tool = load_tool_file(tmp_path / "g.toml")
    assert not tool.shipped and tool.kind == "gripper" and tool.suction_gain_n == 30.0
    assert tool.work_geoms == tuple(f"lip{k}" for k in range(6))
    assert tool.max_payload_kg == pytest.approx(30.0 / (2 * 9.80665))
    root = build_tool(tool)
    m = mujoco.MjModel.from_xml_string(root.to_xml_string(), root.get_assets())
    assert m.body_subtreemass[0] == pytest.approx(0.3)
    a = m.actuator(SUCTION_ACTUATOR)
    assert m.actuator_trnid[a.id, 0] == m.body(CUP_BODY).id
    assert m.actuator_gainprm[a.id, 0] == 30.0
    for k in range(6):  # the lip spheres' bottoms lie in the tcp plane
        g = m.geom(f"lip{k}")
        assert g.pos[2] + g.size[0] == pytest.approx(0.12)
        assert np.hypot(*g.pos[:2]) == pytest.approx(0.014)
        assert m.geom_gap[g.id] == 0.003 and m.geom_margin[g.id] == 0.0


#: Hostile values for the keys the shipped tools brought: (replace, with, what the line says).
HOSTILE = {
    "gain": ("gain_n = 30", "gain_n = -5", "suction.gain_n: must be between 0.001 and 100000 N"),
    "gain nan": ("gain_n = 30", "gain_n = nan", "suction.gain_n: must be a finite number"),
    "gain text": ("gain_n = 30", 'gain_n = "30"', "suction.gain_n"),
    "lip count": ("lip_count = 6", "lip_count = 100000", "suction.lip_count"),
    "ring": ("lip_ring_radius_mm = 14", "lip_ring_radius_mm = 1e300",
             "suction.lip_ring_radius_mm: must be between"),
    "ring inside lip": ("lip_ring_radius_mm = 14", "lip_ring_radius_mm = 2",
                        "suction.lip_ring_radius_mm: must exceed lip_radius_mm"),
    "solref": ("lip_count = 6", "lip_count = 6\nsolref = [0, 1]",
               "suction.solref[0]: must be between 0.0001 and 10 s"),
    "solimp": ("lip_count = 6", "lip_count = 6\nsolimp = [0.9, 0.95, 0.001, 0.5, 1e9]",
               "suction.solimp[4]: must be between 1 and 100"),
    "solimp short": ("lip_count = 6", "lip_count = 6\nsolimp = [0.9, 0.95]", "suction.solimp"),
    "friction": ("lip_count = 6", "lip_count = 6\nfriction = [1, inf, 0]",
                 "suction.friction[1]: must be a finite number"),
    "gap": ("lip_count = 6", "lip_count = 6\ngap_mm = -1", "suction.gap_mm: must be between"),
    "unknown": ("lip_count = 6", "lip_count = 6\nlip_cnt = 3", "suction.lip_cnt: unknown key"),
    "shape mass": ("radius_mm = 20", "radius_mm = 20\nmass_kg = -1",
                   "shapes[0].mass_kg: must be between"),
    "some masses": ("radius_mm = 20", "radius_mm = 20\nmass_kg = 0.2",
                    "give a mass on every shape"),
    "masses off": ('radius_mm = 20', 'radius_mm = 20\nmass_kg = 0.28',
                   "mass_kg: the shapes' masses add up to 0.296 kg"),
    "group": ("radius_mm = 20", "radius_mm = 20\ngroup = 9", "shapes[0].group"),
    "body": ('kind = "gripper"', 'kind = "gripper"\nbody = "a b"', "body"),
    "torch cup": ('kind = "gripper"', 'kind = "torch"', "suction: only a gripper"),
    "lip name": ('name = "bellows"', 'name = "lip3"', "'lip3' is used twice (or is reserved"),
}


@pytest.mark.parametrize("case", sorted(HOSTILE))
def test_hostile_tool_keys_are_one_line_exit_2(case, tmp_path, capsys):
    from sim.cli import main

    old, new, want = HOSTILE[case]
    text = MY_GRIPPER.replace(old, new, 1)
    if case == "masses off":  # every shape and the lip given masses that miss the total
        text = text.replace('to_mm = [0, 0, 115]', 'to_mm = [0, 0, 115]\nmass_kg = 0.01')
        text = text.replace("lip_count = 6", "lip_count = 6\nlip_mass_kg = 0.001")
    assert text != MY_GRIPPER
    (tmp_path / "g.toml").write_text(text)
    scenario = (scenarios_dir() / "lrmate200ic_pick_place.toml").read_text()
    (tmp_path / "s.toml").write_text(scenario.replace('tool = "vacuum_gripper"',
                                                      'tool = "g.toml"', 1))
    rc = main(["check", str(tmp_path / "s.toml")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert "g.toml" in err and want in err, err


def test_a_users_suction_gripper_picks_a_part(tmp_path):
    """The pick cell's first part, picked with a user's gripper file: the part rises with the
    cup (held by the file's adhesion and lip contacts only)."""
    from sim.pipeline.run import RunOptions, evaluate_scenario
    from sim.scenario import load_scenario

    (tmp_path / "g.toml").write_text(MY_GRIPPER)
    src = (scenarios_dir() / "lrmate200ic_pick_place.toml").read_text()
    head = src[:src.index("[[actions]]")].replace('tool = "vacuum_gripper"', 'tool = "g.toml"')
    head = re.sub(r"\[video\]\n(?:[^\n]+\n)*", "", head)
    start = src.index('[[phases]]\nname = "above_part0"')
    phases = src[start:src.index('[[phases]]\nname = "above_slot0"')]
    text = head + '[[actions]]\naction = "suction_on"\nphase = "grip0"\n\n' + phases
    (tmp_path / "s.toml").write_text(text)
    ev = evaluate_scenario(load_scenario(tmp_path / "s.toml"),
                           RunOptions(video=False, plots=False, progress=False))
    parts = np.asarray(ev.record.arrays["part_pos"])
    rise = parts[-1, 0, 2] - parts[0, 0, 2]
    assert rise == pytest.approx(0.080, abs=0.004)  # lifted with the cup: -150 -> -70 mm
    others = np.linalg.norm(parts[-1, 1:] - parts[0, 1:], axis=1)
    assert others.max() < 1e-3  # the other parts stay where they lie
