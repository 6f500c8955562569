"""Sensitivity benchmark (issue 61): a Jacobian from the plant's dual pass against one from
forward differences (1 + k plain simulations), measured in the same run.

Run: ``python bench/sensitivity.py``. A 30 bar stop and an oscillating one of the reference
rig, and the example campaign's actuator sweep profile; k parameters of the wheel, the tyre
and the valve. "ratio" is the differences' time over the dual pass's: above 1 the plant's
own derivatives are cheaper. Each count of keys compiles once (cached on disk): the first
call of each is excluded.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from landing_gear_sim.model import keys as K
from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.integrate import simulate
from landing_gear_sim.model.parameters import RigParameters, load_parameters
from landing_gear_sim.model.sensitivity import simulate_with_sensitivities

KEYS = (K.BRAKE_GAIN_N_M_PER_PA, K.FRICTION_THETA1, K.FRICTION_THETA2, K.FRICTION_THETA3,
        K.ACTUATOR_NATURAL_FREQUENCY_HZ, K.ACTUATOR_DAMPING_RATIO, K.WHEEL_INERTIA_KG_M2,
        K.DRAG_COEFF_N_S2_PER_M2)
REPEATS = 5


def _best(work: Callable[[], object]) -> float:
    work()  # compiled (or loaded) and warm
    times = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        work()
        times.append(time.perf_counter() - start)
    return min(times)


def _differences(params: RigParameters, scenario: sc.Scenario, keys: tuple[str, ...]) -> None:
    simulate(params, scenario)
    for key in keys:
        simulate(params.replace({key: params.number(key) * (1 + 1e-4)}), scenario)


def main() -> None:
    params = load_parameters()
    cases = {
        "stop at 30 bar": sc.constant_pressure_test(params, 30e5),
        "oscillating stop": sc.rig_test(params, sc.oscillating(0.55, 0.2, 3.0)),
        "actuator sweep": sc.actuator_test(params, sc.steps_then_sweep(), 20.0),
    }
    print("Jacobian of a run: forward differences (1 + k simulations) against one dual pass")
    print(f"{'run':18s} {'k':>2s} {'differences':>12s} {'dual pass':>10s} {'ratio':>6s} "
          f"{'pass / plain':>13s}")
    for name, scenario in cases.items():
        plain = _best(lambda scenario=scenario: simulate(params, scenario))
        for k in (1, 2, 3, 4, 6, 8):
            keys = KEYS[:k]
            differences = _best(lambda keys=keys, s=scenario: _differences(params, s, keys))
            dual = _best(lambda keys=keys, s=scenario: simulate_with_sensitivities(
                params, s, keys))
            print(f"{name:18s} {k:2d} {differences * 1e3:9.1f} ms {dual * 1e3:7.1f} ms "
                  f"{differences / dual:5.2f}x {dual / plain:10.2f}x", flush=True)


if __name__ == "__main__":
    main()
