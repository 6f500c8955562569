"""Benchmark of the anti-skid controllers: reference rig, 60 m/s to stop, three surfaces.

Run: ``make bench`` (or ``python bench/controllers.py``). Each controller is compared with a
constant-pressure stop just below the skid pressure, computed in the same run; targets
(14 CFR 25.109: 0.80 for threshold logic, 0.92 for a demonstrated fully modulating
system; no wheel lock above 5 m/s) are reported, never asserted.
"""

from __future__ import annotations

import time

from antiskid.closed_loop import (
    closed_loop,
    constant_pressure_baseline,
    make_controller,
    with_surface,
)
from antiskid.metrics import braking_metrics
from landing_gear_sim.model.parameters import load_parameters

TARGETS = {"threshold": 0.80, "slip": 0.92}
SURFACES = ("dry", "wet", "snow")


def main() -> None:
    reference = load_parameters()
    print("anti-skid benchmark: 60 m/s to stop (ratios > 1 beat the target)\n")
    print(f"{'surface':7s} {'controller':24s} {'efficiency':>10s} {'target':>7s} {'ratio':>7s} "
          f"{'locks>5m/s':>10s} {'stop m':>7s} {'cycling':>8s}  note")
    for surface in SURFACES:
        rig = with_surface(reference, surface)
        pressure, baseline = constant_pressure_baseline(rig)
        base = braking_metrics(baseline.to_run(), rig)
        print(f"{surface:7s} {f'constant {pressure / 1e5:.1f} bar':24s} "
              f"{base.braking_efficiency:10.3f} {'-':>7s} {'':>7s} {base.lock_events:10d} "
              f"{base.stopping_distance_m:7.0f} {'':>8s}")
        for kind, target in TARGETS.items():
            started = time.perf_counter()
            result = closed_loop(rig, make_controller(kind, rig, 1e-3))
            wall = time.perf_counter() - started
            m = braking_metrics(result.to_run(), rig)
            verdict = "ok" if m.braking_efficiency >= target and m.lock_events == 0 else "MISSED"
            note = (f"cycles near the {m.gear_walk_frequency_hz:.1f} Hz gear walk"
                    if m.cycling_near_gear_walk else "")
            print(f"{surface:7s} {kind:24s} {m.braking_efficiency:10.3f} {target:7.2f} "
                  f"{m.braking_efficiency / target:6.2f}x {m.lock_events:10d} "
                  f"{m.stopping_distance_m:7.0f} {m.cycling_frequency_hz:6.2f}Hz  {verdict} {note}"
                  f" ({float(result.time_s[-1]) / wall:.0f}x real time offline)")


if __name__ == "__main__":
    main()
