"""``cellsim export`` of a joint phase that does not move (a hold where a program must start
with a move, or a robot waiting for another): it was written ``J P[1] 1% FINE``, which runs
back in about a millisecond, so ``two_robot_tee_weld``'s 2.6 s stagger between its robots was
lost (found by a new-user trial); it is now ``J P[n] t sec FINE``, ``t`` the phase's duration.
Specification, on generated holds and moves of the LR Mate 100iB: the program holds each still
phase for its duration (read back by :mod:`sim.scenario.program`: the phase starts and ends
where the original's do, to the program's 6 digits) and a moving phase's J is unchanged; the
shipped two-robot weld runs back with its robots' arc starts 2.6 s apart, as the original."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from sim.errors import ScenarioError
from sim.pipeline.export import write_program
from sim.scenario import load_scenario
from sim.simulation.compile import build
from sim.simulation.motion.build import build_motion

HEAD = '''name = "{name}"
description = "generated"
robot = "lrmate100ib"
{program}
[simulation]
enforce_speed_limits = false
enforce_accel_limits = false
'''


def _joint(name: str, q1: list[float], duration: float) -> str:
    """A joint phase from where the last one ended (the home pose first) to ``q1``."""
    row = "[" + ", ".join(f"{v:.3f}" for v in q1) + "]"
    return (f'\n[[phases]]\nname = "{name}"\nplanner = "434"\ndurations_s = [{duration!r}]\n'
            f"joints_deg = [{row}]\n")


def _plan(path: Path):  # type: ignore[no-untyped-def]
    sc = load_scenario(path)
    return build_motion(sc, build(sc).context)


@settings(max_examples=6, deadline=None, phases=[Phase.explicit, Phase.reuse, Phase.generate],
          suppress_health_check=[HealthCheck.too_slow,
                                                                 HealthCheck.function_scoped_fixture])
@given(hold=st.floats(0.05, 5.0), later=st.floats(0.05, 3.0),
       pose=st.lists(st.floats(-20.0, 20.0), min_size=5, max_size=5),
       move=st.lists(st.floats(-20.0, 20.0), min_size=5, max_size=5))
def test_a_still_joint_phase_is_held_for_its_time(tmp_path: Path, hold: float, later: float,
                                                   pose: list[float], move: list[float]) -> None:
    start = "[" + ", ".join(f"{v:.3f}" for v in move) + "]"
    text = HEAD.format(name="hold", program="") + (  # a first phase that holds at `move`
        f'\n[[phases]]\nname = "start"\nplanner = "434"\ntime_s = [0.0, {hold!r}]\n'
        f"joints_deg = [{start}, {start}]\n") + \
        _joint("go", pose, 1.0) + _joint("wait", pose, later) + _joint("back", move, 1.0)
    src = tmp_path / "hold.toml"
    src.write_text(text)
    out = tmp_path / f"p{len(list(tmp_path.iterdir()))}.ls"
    write_program(load_scenario(src), out)
    ls = out.read_text()
    assert f"J P[1] {float(f'{hold:.6g}'):g}sec FINE" in ls
    assert f"{float(f'{later:.6g}'):g}sec FINE" in ls
    back = tmp_path / "back.toml"
    back.write_text(HEAD.format(name="back", program=f'program = "{out.name}"'))
    orig, again = _plan(src), _plan(back)
    ends = [[round(p.t1, 4) for p in m.phases] for m in (orig, again)]
    # the still phases end where the original's do; the moves' J % are rounded up (faster)
    assert abs(again.phases[0].t1 - hold) <= 1e-5 * hold
    got_wait = again.phases[2].t1 - again.phases[2].t0
    assert abs(got_wait - later) <= 1e-5 * later, ends
    for m in (orig, again):  # the poses are the same at the phases' ends
        assert np.allclose(np.rad2deg(m.at(m.phases[2].t1).q[0]), np.round(pose, 3), atol=1e-9)


def test_the_two_robot_weld_keeps_its_stagger(tmp_path: Path) -> None:
    out = tmp_path / "tee.ls"
    write_program(load_scenario("two_robot_tee_weld"), out)
    mask = os.umask(0o022)
    os.umask(mask)
    for f in (out, tmp_path / "tee_r2.ls"):  # the umask's mode, not a temporary file's 0o600
        assert f.stat().st_mode & 0o777 == 0o666 & ~mask
    with pytest.raises(ScenarioError, match="exists; cellsim export never replaces a file"):
        write_program(load_scenario("two_robot_tee_weld"), out)
    back = tmp_path / "tee_tp.toml"
    back.write_text('name = "tee_tp"\ndescription = "x"\nrobot = "lrmate200ic5l"\ncell = "two_robot_tee"\n'
                    'tool = "mig_torch"\nprogram = "tee.ls"\n[robots.r2]\n'
                    'program = "tee_r2.ls"\n')
    arcs = []
    shipped = load_scenario("two_robot_tee_weld")
    for m in (build_motion(shipped, build(shipped).context), _plan(back)):
        r1 = next(t for t, a in m.actions if a == "arc_on")
        r2 = next(t for t, a in dict(m.lanes)["r2"].actions if a == "arc_on")
        arcs.append(r2 - r1)
    assert abs(arcs[0] - 2.6) < 1e-9
    assert abs(arcs[1] - arcs[0]) < 1e-6, arcs
