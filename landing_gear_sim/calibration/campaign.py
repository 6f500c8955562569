"""The project's own rig generator: a synthetic calibration campaign (documented as synthetic).

It simulates the standard runs of a rig campaign with a parameter set that
deviates from the datasheet by a few percent, adds sensor noise, and writes the
runs as contract CSVs. The generating parameters are written beside them for
tests and benchmarks; identification and diagnosis never read that file.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from landing_gear_sim.calibration.logger import Logger
from landing_gear_sim.calibration.measured import run_parameters
from landing_gear_sim.calibration.wheel_angle import BRAKE_RUNOUT_KEYS, has_brake_runout
from landing_gear_sim.model import keys as K
from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.integrate import simulate
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import at_static_load
from landing_gear_sim.model.sensors import RUNOUT_KEYS, SensorModel
from msg_tools.csv_io import write_csv
from msg_tools.units import PA_PER_BAR

DEVIATING = (K.FLYWHEEL_INERTIA_KG_M2, K.DRAG_COEFF_N_S2_PER_M2, K.FRICTION_THETA1,
             K.FRICTION_THETA2, K.FRICTION_THETA3, K.BRAKE_GAIN_N_M_PER_PA,
             K.ACTUATOR_MAP_K1_PA_PER_A, K.ACTUATOR_NATURAL_FREQUENCY_HZ,
             K.ACTUATOR_DAMPING_RATIO)
"""Parameters on which a real rig differs from its datasheet."""

NOISE = {K.SENSORS_PRESSURE_NOISE_PA: 1.5e4, K.SENSORS_SPEED_NOISE_RAD_S: 0.1,
         K.SENSORS_FORCE_NOISE_N: 100.0}
GENERATING_FILE = "generating-parameters.yaml"
LIGHT_LOAD = 0.7
LIGHT_BAR = (14, 21, 28)
STANDARD_RUNS = ("actuator_ramp", "actuator_steps_sweep",
                 *(f"brake_const_{bar}bar" for bar in (10, 20, 30, 40)), "brake_osc_low",
                 "brake_osc_high", *(f"brake_const_{bar}bar_light" for bar in LIGHT_BAR))
"""The standard runs' names in the order their noise is drawn."""
LIGHT_SPEED_M_S = 45.0
"""The light stops (``light=True``): constant-pressure stops at a lighter static load
(× LIGHT_LOAD). On the rig the load follows the speed (F_z0 − k_L v²), so only runs at
another static load tell a law in load (a tyre's load sensitivity) from one in speed. Their
pressures are the 20, 30 and 40 bar stops' × LIGHT_LOAD: the same brake torque per newton of
load, so the same slips, on a slippery surface as on a grippy one (two light stops at the
full pressures shared too few slips with the others: the comparison went unchecked on a
slippery rig). They start slower, where the lift leaves the lighter tyre most of its load.
Not in the default campaign (issue 15's 15 s is for the example campaigns' eight runs): a
null campaign of eight diagnosed in 11 s here, of eleven in 21 s."""


def rig_like(datasheet: RigParameters, rng: np.random.Generator,
             deviation: float = 0.03) -> RigParameters:
    """A 'real rig': every DEVIATING parameter off by up to ±``deviation`` (uniform)."""
    changes = {k: datasheet.number(k) * (1 + rng.uniform(-deviation, deviation))
               for k in DEVIATING}
    return datasheet.replace({**changes, **NOISE}, "rig generator")


def standard_scenarios(p: RigParameters, light: bool = False,
                       names: Sequence[str] | None = None) -> dict[str, sc.Scenario]:
    """The runs of a calibration campaign: those of the example campaigns (same names), and
    with ``light`` the constant-pressure stops at a lighter static load (`_light`, see
    LIGHT_BAR); only ``names`` when given (a slow valve's 12 bar holds no 20 bar stop)."""
    max_current = p.number(K.ACTUATOR_MAX_CURRENT_A)
    made: dict[str, Callable[[], sc.Scenario]] = {
        "actuator_ramp": lambda: sc.actuator_test(p, sc.quasi_static_ramp(max_current), 20.0,
                                                  "actuator_ramp"),
        "actuator_steps_sweep": lambda: sc.actuator_test(p, sc.steps_then_sweep(), 28.0,
                                                         "actuator_steps_sweep"),
        **{f"brake_const_{bar}bar": functools.partial(sc.constant_pressure_test, p,
                                                      bar * PA_PER_BAR)
           for bar in (10, 20, 30, 40)},
        "brake_osc_low": lambda: sc.rig_test(p, sc.oscillating(**sc.OSC_LOW), "brake_osc_low"),
        "brake_osc_high": lambda: sc.rig_test(p, sc.oscillating(**sc.OSC_HIGH),
                                              "brake_osc_high"),
    }
    standard = {name: make() for name, make in made.items() if names is None or name in names}
    if not light:
        return standard
    return standard | {f"brake_const_{bar}bar_light": sc.rig_test(
        _light(p), sc.constant(sc.current_for_pressure(p, bar * PA_PER_BAR)),
        f"brake_const_{bar}bar_light") for bar in LIGHT_BAR
        if names is None or f"brake_const_{bar}bar_light" in names}


def _campaign_order(braking: Sequence[str]) -> dict[str, float]:
    """Each braking run's place in run order (file-name order), about the middle one."""
    ordered = sorted(braking)
    return {name: rank - (len(ordered) - 1) / 2 for rank, name in enumerate(ordered)}


def _start_angle(params: RigParameters, rng: np.random.Generator) -> RigParameters:
    """A run starts with the wheel at an angle of its own: an encoder's ripple with the
    angle and a disc's run-out have a phase of their own in each run."""
    if not (SensorModel.of(params).ripples or has_brake_runout(params)):
        return params
    start = rng.uniform(0.0, 2.0 * np.pi)
    phases = {key: params.number(key) + order * start for order, key in
              zip((1, 2, 1, 2), (*RUNOUT_KEYS[1::2], *BRAKE_RUNOUT_KEYS[1::2]), strict=True)}
    return params.replace(phases, "the run's start angle")


def _light(params: RigParameters) -> RigParameters:
    """The set of a `_light` run: LIGHT_LOAD of the static load, from LIGHT_SPEED_M_S."""
    return at_static_load(params, LIGHT_LOAD * params.number(K.LOADING_STATIC_LOAD_N)).replace(
        {K.RIG_TEST_INITIAL_SPEED_M_S: LIGHT_SPEED_M_S}, "a light run")


def _loaded(params: RigParameters, name: str) -> RigParameters:
    """The set a run brakes with (a `_light` run's, see LIGHT_BAR)."""
    return _light(params) if name.endswith("_light") else params


def generate_campaign(folder: Path, rig: RigParameters, seed: int = 0,
                      names: Sequence[str] | None = None, light: bool = False,
                      logger: Logger | None = None, shuffled: bool = False) -> list[Path]:
    """Simulate and write the standard runs of ``rig`` (or those in ``names``), with
    ``light`` the light stops too (see LIGHT_BAR), into ``folder``, as ``logger`` writes
    them (default: at the rig's output rate, nothing beyond the sensors' noise); returns
    the CSV paths. ``shuffled``: the runs were made in an order drawn from ``seed``, their
    files named ``run01_<name>`` ... in it (a brake that wears, wears in that order; the
    standard names put the constant stops in rising pressure)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    logger = logger or Logger()
    written = []
    rig.to_yaml(folder / GENERATING_FILE)
    if logger.rate_hz is not None:
        rig = rig.replace({K.SIMULATION_OUTPUT_RATE_HZ: logger.rate_hz}, "the logger's rate")
    scenarios = standard_scenarios(rig, light, names)
    files = {name: name for name in scenarios}
    if shuffled:
        made = np.random.default_rng([seed, 2]).permutation(list(scenarios))
        files = {str(name): f"run{k:02d}_{name}" for k, name in enumerate(made, start=1)}
    order = _campaign_order([files[n] for n, s in scenarios.items() if s.contact])
    for name, scenario in scenarios.items():
        i = STANDARD_RUNS.index(name)  # a run's noise is its own, whichever others are made
        params = _loaded(run_parameters(rig, order.get(files[name], 0.0)), name)
        written.append(_write(folder / f"{files[name]}.csv", params, scenario, logger, seed, i))
    return written


OWN_RUN = len(STANDARD_RUNS)
"""The noise index of a run made alone (:func:`generate_run`): none of the standard runs'."""


def generate_run(folder: Path, rig: RigParameters, scenario: sc.Scenario, seed: int = 0,
                 logger: Logger | None = None) -> Path:
    """One run of ``scenario`` as ``rig`` makes it (the run a diagnosis proposes to settle
    what a campaign left open), logged as ``logger`` logs, written to
    ``folder/next_<scenario name>.csv`` (a run of the campaign's own kind, a 10 bar stop
    again, is diagnosed beside it under another name); returns its path. Its noise is drawn
    from ``seed``, as a campaign's runs are; the rig, like a campaign's middle run, has worn
    no further."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    logger = logger or Logger()
    rig.to_yaml(folder / GENERATING_FILE)
    return _write(folder / f"next_{scenario.name}.csv", rig, scenario, logger, seed, OWN_RUN)


def _write(path: Path, params: RigParameters, scenario: sc.Scenario, logger: Logger,
           seed: int, index: int) -> Path:
    """The run of ``scenario`` under ``params`` (started at an angle of its own), logged
    and written to ``path``; its noise drawn from ``seed`` and its ``index``."""
    params = _start_angle(params, np.random.default_rng([seed, index]))
    result = simulate(params, scenario)
    run = logger.write(result, result.to_run(noise=seed * 100 + index),
                       np.random.default_rng([seed, index, 1]))
    write_csv(run, path)
    return path
