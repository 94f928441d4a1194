"""Payload study: how the drives' margins shrink as the payload grows.

    python examples/payload_study.py [SCENARIO] [KG ...]

The default is the LR Mate 200iC/5L's pick-and-place cycle at 0 to 5 kg (its rating). Each
payload is evaluated in memory (nothing is written); the busiest joint and its margin come
from the typed result, with the shoulder's motor RMS torque and
the checks that failed.
"""

import sys

import sim


def main(scenario: str, payloads_kg: list[float]) -> list[sim.RunResult]:
    base = sim.load_scenario(scenario)
    results = [sim.evaluate(base.scaled(payload_kg=kg)) for kg in payloads_kg]
    for kg, r in zip(payloads_kg, results, strict=True):
        hardest = min(r.sizing.values(), key=lambda j: j.margin_pct)
        rms = r.sizing[r.joints[1]].check("motor_rms_torque")  # the shoulder carries the load
        print(f"{kg:5.2f} kg  {r.verdict}  hardest {hardest.joint} ({hardest.limiting}, "
              f"{hardest.margin_pct:4.1f} %)  J2 motor RMS "
              + (f"{rms.used:.3f} N m ({rms.margin_pct:4.1f} %)" if rms else "-")
              + "  failed: " + (", ".join(f"{c.name} {c.joint}".strip()
                                           for c in r.failed_checks) or "none"))
    return results


if __name__ == "__main__":
    args = sys.argv[1:]
    main(args[0] if args else "lrmate200ic_pick_place",
         [float(a) for a in args[1:]] or [0.0, 1.0, 2.5, 5.0])
