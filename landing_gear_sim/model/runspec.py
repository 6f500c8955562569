"""What to run: a profile name and its options, turned into a :class:`Scenario`.

One description serves the ``simulate`` command, every node of the graph (plant,
profile, loading device each build the same scenario from the same ``run.*``
parameters) and the ``rig`` launcher, so an offline run and a graph run of the same
:class:`RunSpec` get the same input sample for sample.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

from landing_gear_sim.errors import ScenarioError
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from msg_tools.units import PA_PER_BAR

if TYPE_CHECKING:
    from landing_gear_sim.model import scenario as sc
    from msg_tools.run import Run

CONTACT_CHOICES = ("auto", "rig", "actuator")
"""``auto``: the profile's own test (braking profiles on the flywheel, actuator
profiles with the wheel off); ``rig`` / ``actuator`` force one."""


@dataclass(frozen=True)
class RunSpec:
    """One run of the rig, independent of how it is executed.

    Attributes:
        profile: a name of :data:`PROFILES`, ``file`` (recorded current) or
            ``external`` (the current comes from a controller node; rig test).
        pressure_pa: ``constant`` profile: steady brake pressure to aim at.
        current_a: ``constant`` profile: the current instead (NaN: use pressure_pa).
        file: ``file`` profile: run (CSV or bag) whose logged current to replay.
        contact: one of :data:`CONTACT_CHOICES`.
        duration_s: input duration (0: the profile's default).
        rate_hz: sample and exchange rate (0: ``simulation.output_rate_hz``).
    """

    profile: str = "constant"
    pressure_pa: float = 30 * PA_PER_BAR
    current_a: float = math.nan
    file: str = ""
    contact: str = "auto"
    duration_s: float = 0.0
    rate_hz: float = 0.0

    def __post_init__(self) -> None:
        if self.profile not in (*PROFILES, "file", "external"):
            raise ScenarioError(f"unknown profile {self.profile!r}; choose from "
                                f"{', '.join([*PROFILES, 'file', 'external'])}")
        if self.contact not in CONTACT_CHOICES:
            raise ScenarioError(f"contact must be one of {', '.join(CONTACT_CHOICES)}")
        if self.profile == "file" and not self.file:
            raise ScenarioError("profile 'file' needs a run file")
        if self.duration_s < 0 or self.rate_hz < 0:
            raise ScenarioError("duration and rate must be >= 0 (0 = default)")

    @property
    def replays_file(self) -> bool:
        """The current comes from a recorded run (``file``), which the caller reads."""
        return self.profile == "file"

    @property
    def name(self) -> str:
        if self.profile == "file":
            return Path(self.file).stem + "_sim"
        if self.profile == "constant":
            if math.isnan(self.current_a):
                return f"brake_const_{self.pressure_pa / PA_PER_BAR:g}bar"
            return f"brake_const_{self.current_a:g}A"
        return self.profile.replace("-", "_")


Builder = Callable[[RunSpec, RigParameters], "sc.Profile"]


def _sc() -> ModuleType:
    """The scenario module, read when a run is built: the CLI's parser reads this one for
    the profile names, and the numerical stack costs it a second (issue 32)."""
    from landing_gear_sim.model import scenario

    return scenario


def _constant(spec: RunSpec, params: RigParameters) -> sc.Profile:
    sc = _sc()
    if not math.isnan(spec.current_a):
        return sc.constant(spec.current_a)
    return sc.constant(sc.current_for_pressure(params, spec.pressure_pa))


# profile name -> (builder, wheel on the flywheel?, actuator-test duration [s])
PROFILES: dict[str, tuple[Builder, bool, float]] = {
    "constant": (_constant, True, 0.0),
    "osc-low": (lambda s, p: _sc().oscillating(**_sc().OSC_LOW), True, 0.0),
    "osc-high": (lambda s, p: _sc().oscillating(**_sc().OSC_HIGH), True, 0.0),
    "ramp": (lambda s, p: _sc().quasi_static_ramp(p.number(K.ACTUATOR_MAX_CURRENT_A)),
             False, 20.0),
    "steps": (lambda s, p: _sc().steps(), False, 8.0),
    "sweep": (lambda s, p: _sc().sine_sweep(), False, 20.0),
    "steps-sweep": (lambda s, p: _sc().steps_then_sweep(), False, 28.0),
}


def build_scenario(spec: RunSpec, params: RigParameters, recorded: Run | None = None
                   ) -> sc.Scenario:
    """The scenario of ``spec`` under ``params``; ``recorded`` is the run of the ``file``
    profile (read from ``spec.file`` by the caller: the model reads no files).

    Raises:
        ScenarioError: the profile cannot be built (e.g. a pressure outside the valve range,
            a ``file`` profile without its recorded run).
    """
    sc = _sc()
    rate = spec.rate_hz or None
    if spec.profile == "external":
        return sc.rig_test(params, sc.constant(0.0), "external", rate)
    if spec.profile == "file":
        if recorded is None:
            raise ScenarioError(f"profile 'file' needs the recorded run of {spec.file!r}")
        profile, duration = sc.from_run(recorded)
        contact = spec.contact != "actuator"
    else:
        build, contact, duration = PROFILES[spec.profile]
        profile = build(spec, params)
        contact = (contact or spec.contact == "rig") and spec.contact != "actuator"
    duration = spec.duration_s or duration
    if not contact:
        return sc.actuator_test(params, profile, duration or 10.0, spec.name, rate)
    if spec.profile == "file":  # a recorded run already holds its braking start
        times = sc.sample_times(duration, rate or params.number(K.SIMULATION_OUTPUT_RATE_HZ))
        return sc.Scenario(spec.name, profile(times), 1.0 / (times[1] - times[0]), True,
                           params.number(K.RIG_TEST_INITIAL_SPEED_M_S),
                           params.number(K.RIG_TEST_STOP_SPEED_M_S), "replayed current")
    return sc.rig_test(params, profile, spec.name, rate)
