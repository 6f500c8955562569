"""Benchmarks of the physics core: accuracy and speed, as ratios against targets and against
a tight-tolerance reference measured in the same run.

Run: ``make bench`` (or ``python bench/run.py``). Prints a table; exits 0 whatever the numbers:
targets are reported, never asserted.
"""

from __future__ import annotations

import resource
import statistics
import time
import tracemalloc

import numpy as np

from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.integrate import simulate, simulate_batch
from landing_gear_sim.model.parameters import load_parameters
from landing_gear_sim.model.reference import reference_solution

TARGET_RMS_PCT = 0.1  # wheel-speed RMS error, % of initial wheel speed
TARGET_RUN_S = 0.030  # one 15 s braking run at 1 kHz
TARGET_VS_REFERENCE = 100.0
TARGET_BATCH_S = 1.0  # 64 parameter sets


def _timed(call, repeat: int = 1) -> tuple[float, object]:
    times, value = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        value = call()
        times.append(time.perf_counter() - start)
    return statistics.median(times), value


def _row(name: str, value: str, target: str, ratio: float | None = None) -> None:
    verdict = "" if ratio is None else ("ok" if ratio >= 1.0 else "MISSED")
    ratio_text = "" if ratio is None else f"{ratio:8.2f}x"
    print(f"{name:46s} {value:>14s}   target {target:>10s} {ratio_text:>10s} {verdict}")


def main() -> None:
    params = load_parameters()
    cases = {
        "constant 30 bar": sc.constant_pressure_test(params, 30e5),
        "oscillating (Fig. 14a)": sc.rig_test(params, sc.oscillating(**sc.OSC_LOW)),
    }
    simulate(params, cases["constant 30 bar"])  # compile (or load the cache) first
    wheel0 = params.number("rig_test.initial_speed_m_s") / params.number("wheel.unloaded_radius_m")
    print("landing_gear_sim physics benchmark (ratios > 1 beat the target)\n")
    for name, scenario in cases.items():
        run_s, result = _timed(lambda s=scenario: simulate(params, s), repeat=15)
        ref_s, ref = _timed(lambda s=scenario, r=result: reference_solution(
            params, s, end_s=float(r.time_s[-1])))
        error = result.wheel_speed_rad_s - ref["wheel_speed_rad_s"]
        rms_pct = 100 * float(np.sqrt(np.mean(error ** 2))) / wheel0
        duration = float(result.time_s[-1])
        print(f"-- {name}: {duration:.2f} s braking run, {len(result)} samples")
        _row("wheel-speed RMS error vs Radau rtol 1e-9", f"{rms_pct:.2e} %",
             f"<= {TARGET_RMS_PCT} %", TARGET_RMS_PCT / rms_pct)
        _row("wall time of one run", f"{run_s * 1e3:.2f} ms",
             f"<= {TARGET_RUN_S * 1e3:.0f} ms", TARGET_RUN_S / run_s)
        _row("real-time factor", f"{duration / run_s:.0f}x", ">= 500x", duration / run_s / 500)
        _row("speed-up over the Radau reference", f"{ref_s / run_s:.0f}x",
             f">= {TARGET_VS_REFERENCE:.0f}x", ref_s / run_s / TARGET_VS_REFERENCE)
        print(f"   (Radau reference took {ref_s:.2f} s)")

    rng = np.random.default_rng(0)
    sets = [params.replace({"friction.theta1": float(rng.uniform(0.8, 1.1)),
                            "brake.gain_n_m_per_pa": float(rng.uniform(1.3e-3, 1.7e-3))})
            for _ in range(64)]
    scenario = cases["constant 30 bar"]
    simulate_batch(sets[:2], scenario)  # compile the parallel kernel
    serial_s, _ = _timed(lambda: [simulate(p, scenario) for p in sets])
    tracemalloc.start()
    batch_s, _ = _timed(lambda: simulate_batch(sets, scenario))
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    print("-- batch of 64 parameter sets, constant 30 bar")
    _row("wall time, parallel batch", f"{batch_s:.3f} s", f"<= {TARGET_BATCH_S:.0f} s",
         TARGET_BATCH_S / batch_s)
    _row("  the same 64 runs one by one", f"{serial_s:.3f} s", "-")
    _row("peak traced memory of the batch call", f"{peak / 2**20:.0f} MiB", "-")
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    _row("peak RSS of this benchmark process", f"{rss:.0f} MiB", "-")


if __name__ == "__main__":
    main()
