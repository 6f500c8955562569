"""Closed-loop Monte Carlo: the compiled loop equals the block loop, the μ-jump surface,
draws that depend on the seed only, Dask runs on one or two workers that agree, and worst
cases that replay."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from antiskid.closed_loop import SURFACES, closed_loop, make_controller, with_surface
from antiskid.compiled import compiled_closed_loop
from antiskid.metrics import braking_metrics
from landing_gear_sim.campaigns.montecarlo import Plan, draw_case
from landing_gear_sim.cli import main
from landing_gear_sim.model.integrate import simulate
from landing_gear_sim.model.quantities import at_static_load, peak_friction
from landing_gear_sim.model.runspec import RunSpec
from landing_gear_sim.ros.graph import load_scenario
from msg_tools.io import read_run

GAIN = "brake.gain_n_m_per_pa"


@pytest.mark.parametrize("kind, delay_s, runout", [("threshold", 0.0, 0.0), ("slip", 0.0, 0.0),
                                                   ("threshold", 2.5e-3, 0.0),
                                                   ("slip", 2.5e-3, 0.01)])
def test_the_compiled_closed_loop_is_the_block_loop_to_the_last_bit(reference, kind, delay_s,
                                                                    runout):
    """What the graph steps (blocks) and what Monte Carlo runs (one compiled loop) agree,
    the wheel channel read out of step and rippling with the wheel's angle, and a
    load-sensitive tyre, included."""
    rig = with_surface(reference, "wet").replace({
        "friction.load_sensitivity_per_n": 1e-5 if runout else 0.0,
        "sensors.wheel_speed_delay_s": delay_s, "sensors.wheel_runout_1": runout,
        "sensors.wheel_runout_1_phase_rad": 0.7, "sensors.wheel_runout_2": runout / 2})
    blocks = closed_loop(rig, make_controller(kind, rig, 1e-3))
    compiled = compiled_closed_loop(rig, kind)
    assert compiled.stop_reason == blocks.stop_reason == "stop speed reached"
    np.testing.assert_array_equal(compiled.data, blocks.data)


def _jump(reference, change_speed_m_s: float):
    thetas = dict(zip(("theta1", "theta2", "theta3"), SURFACES["snow"], strict=True))
    return reference.replace({"friction.change_speed_m_s": change_speed_m_s}
                             | {f"friction.after_{k}": v for k, v in thetas.items()})


def test_a_mu_jump_puts_the_tyre_on_the_second_surface_below_its_speed(reference):
    rig = _jump(reference, 30.0)
    result = compiled_closed_loop(rig, "slip")
    mu = result.longitudinal_force_n / np.maximum(result.vertical_load_n, 1.0)
    braking = result.time_s > reference.number("rig_test.brake_start_s") + 0.5
    snow_peak, _ = peak_friction(with_surface(reference, "snow"))
    assert mu[braking & (result.speed_m_s > 32.0)].max() > 2 * snow_peak  # dry
    assert mu[braking & (result.speed_m_s < 28.0)].max() <= snow_peak + 1e-9  # snow
    no_jump = compiled_closed_loop(_jump(reference, 0.0), "slip")
    np.testing.assert_array_equal(no_jump.data, compiled_closed_loop(reference, "slip").data)


def test_efficiency_counts_each_sample_against_the_surface_under_the_tyre(reference):
    rig = _jump(reference, 30.0)
    metrics = braking_metrics(compiled_closed_loop(rig, "slip").to_run(), rig)
    assert 0.85 < metrics.braking_efficiency <= 1.0  # against the dry peak alone: ~0.4


def test_efficiency_counts_each_sample_against_the_friction_at_its_load(reference):
    """A load-sensitive tyre (μ 20 % up per 10 kN lighter) at 75 % static load: against the
    curve's peak at the reference load the slip controller would use more than all of it."""
    rig = at_static_load(reference.replace({"friction.load_sensitivity_per_n": 2e-5}),
                         0.75 * reference.number("loading.static_load_n"))
    run = compiled_closed_loop(rig, "slip").to_run()
    metrics = braking_metrics(run, rig)
    assert metrics.mean_friction > metrics.peak_friction  # the reference load's peak
    assert 0.85 < metrics.braking_efficiency <= 1.0


def test_a_case_depends_on_the_seed_and_its_index_only(reference):
    sigma = 0.02 * reference.number(GAIN)
    plan = Plan("slip", seed=11, cases=400, sigma=((GAIN, sigma),))
    cases = [draw_case(reference, plan, i) for i in range(400)]
    again = draw_case(reference, Plan("slip", seed=11, cases=5, sigma=((GAIN, sigma),)), 123)
    assert again == cases[123]
    assert draw_case(reference, Plan("slip", seed=12, sigma=((GAIN, sigma),)), 123) != again
    gains = np.array([c.overrides[GAIN] for c in cases])
    assert abs(gains.mean() / reference.number(GAIN) - 1) < 0.005
    assert 0.85 < gains.std() / sigma < 1.15
    kinds = {c.surface.split("-")[0] for c in cases}
    assert kinds == {"dry", "wet", "snow", "jump"}
    speeds = np.array([c.entry_speed_m_s for c in cases])
    assert speeds.min() >= 50.0 and speeds.max() <= 70.0


def _cases(folder: Path) -> list[dict[str, str]]:
    with (folder / "cases.csv").open(encoding="utf-8") as source:
        return list(csv.DictReader(source))


def test_one_worker_or_two_give_the_same_stops_and_a_rerun_redoes_nothing(tmp_path, capsys):
    args = ["montecarlo", "--controller", "threshold", "--cases", "30", "--seed", "5",
            "--worst", "2"]
    assert main([*args, "--workers", "1", "-o", str(tmp_path / "one")]) == 0
    assert main([*args, "--workers", "2", "-o", str(tmp_path / "two")]) == 0
    one, two = _cases(tmp_path / "one"), _cases(tmp_path / "two")
    assert len(one) == 30 and one == two
    summary = json.loads((tmp_path / "one" / "summary.json").read_text())
    assert summary["cases"] == 30 and 0.5 < summary["braking_efficiency"]["p50"] <= 1.0
    assert (tmp_path / "one" / "montecarlo.png").stat().st_size > 10_000
    capsys.readouterr()
    assert main([*args, "--workers", "1", "-o", str(tmp_path / "one")]) == 0
    assert "2 of 2 already done" in capsys.readouterr().err
    assert _cases(tmp_path / "one") == one


def test_a_worst_case_replays_as_the_stop_it_was(tmp_path, capsys, reference):
    out = tmp_path / "mc"
    assert main(["montecarlo", "--controller", "threshold", "--cases", "12", "--seed", "2",
                 "--surfaces", "jump", "--worst", "1", "--workers", "1", "-o", str(out)]) == 0
    replay = [line.split()[2:] for line in capsys.readouterr().out.splitlines()
              if line.startswith("replay:")]
    assert len(replay) == 1 and replay[0][:2] == ["rig", "--replay"]
    run_path, params_path = Path(replay[0][2]), Path(replay[0][4])
    from landing_gear_sim.model.parameters import load_parameters

    rig = load_parameters([params_path])
    recorded = read_run(run_path)
    # what `rig --replay` builds its graph's run from
    again = simulate(rig, load_scenario(RunSpec(profile="file", file=str(run_path)), rig))
    np.testing.assert_allclose(again.wheel_speed_rad_s[:len(recorded.time_s)],
                               recorded.wheel_speed_rad_s, atol=1e-6)
    worst = min(_cases(out), key=lambda r: (-float(r["lock_duration_s"]),
                                            float(r["braking_efficiency"])))
    assert braking_metrics(again.to_run(), rig).lock_events == int(worst["lock_events"])


@pytest.mark.parametrize("args, fragment", [
    (["--cases", "0"], "cases must be >= 1"),
    (["--surfaces", "ice"], "surfaces must be among"),
    (["--evidence", "nowhere.json"], "nowhere.json: cannot read"),
])
def test_bad_montecarlo_input_is_one_error_line(tmp_path, capsys, args, fragment):
    code = main(["montecarlo", "--controller", "slip", "-o", str(tmp_path / "x"), *args])
    err = capsys.readouterr().err
    assert code == 2 and fragment in err and "Traceback" not in err
