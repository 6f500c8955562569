"""Model parameters: the schema, the params-file loader and validation.

The numbers live in ROS 2 params files (``config/*.yaml``); this module declares
each key once (:data:`SPECS`: unit, meaning, admissible range), loads and layers
files, validates every value, and packs a parameter set into the flat float64
vector the compiled physics reads (:data:`INDEX` gives each key's position).
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Generic, TypeVar

import yaml

from landing_gear_sim.errors import ParameterError
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.bundled import default_config_files
from landing_gear_sim.model.params_file import flatten, params_text

if TYPE_CHECKING:
    import numpy as np

ELEMENTS: tuple[str, ...] = ("gear_walk", "load_dependent_radius", "actuator_dynamics", "drag",
                             "actuator_delay", "pressure_sensor_offset", "tire_relaxation",
                             "brake_fade")
"""Model elements that can be switched on or off (``elements.<name>``). The last ones are
extensions the reference rig does not have (off in its file)."""

CONFIGURATIONS: tuple[str, ...] = ("rig", "aircraft")
CODE_LIMIT = 256 * 257  # a slot's codes: two factors of model.basis (checked there)


@dataclass(frozen=True)
class ParamSpec:
    """One parameter: its key in the params file, unit, meaning and admissible range."""

    key: str
    unit: str
    description: str
    kind: str = "float"  # "float", "bool" or "choice"
    positive: bool = False  # strictly > 0 (else >= 0)
    signed: bool = False  # may be negative (an offset)
    choices: tuple[str, ...] = ()
    default: float | None = None
    """Value of a params file that lacks the key (terms added after files were written)."""


def _f(key: str, unit: str, description: str, positive: bool = True) -> ParamSpec:
    return ParamSpec(key, unit, description, positive=positive)


def _slot(key: str, unit: str, description: str) -> ParamSpec:
    """A term of an equation's generic slot (issue 29): either sign, 0 when a file lacks it."""
    return ParamSpec(key, unit, f"{description} (0: none)", signed=True, default=0.0)


def _slot_terms(keys: tuple[tuple[str, str], ...], unit: str, law: str
                ) -> tuple[ParamSpec, ...]:
    """An equation's generic slot (issue 41, ``model.basis``): per term the code of its basis
    function (a whole number) and its coefficient, in the equation's unit per φ's."""
    return tuple(spec for code, coeff in keys for spec in (
        ParamSpec(code, "-", f"code of a basis function phi_k of {law} (model.basis: one or "
                  "two factors, each a signal through a shape)", default=0.0),
        ParamSpec(coeff, f"{unit} per phi", f"coefficient c_k of {law} (0: none)",
                  signed=True, default=0.0)))


def _ripple(prefix: str, law: str, cause: str, read_from: str) -> tuple[ParamSpec, ...]:
    """A ripple with the wheel's angle once and twice per revolution: per order its
    relative amplitude and its phase at the run's first sample."""
    return tuple(spec for order in (1, 2) for spec in (
        ParamSpec(f"{prefix}_{order}", "-",
                  f"{law} (1 + e cos({order} theta + phi)): a ripple {order}x per wheel "
                  f"revolution, relative ({cause}; 0: none)", default=0.0),
        ParamSpec(f"{prefix}_{order}_phase_rad", "rad",
                  "phase phi of that ripple at the run's first sample (theta = 0 there; a "
                  f"measured run's own is read from {read_from})", signed=True, default=0.0)))


SPECS: tuple[ParamSpec, ...] = (
    ParamSpec(K.CONFIGURATION, "-", "rig (flywheel) or aircraft (eqs. 5-6)", "choice",
              choices=CONFIGURATIONS),
    *(ParamSpec(f"elements.{name}", "-", f"{name} element switched on", "bool")
      for name in ELEMENTS),
    _f(K.FLYWHEEL_RADIUS_M, "m", "flywheel radius R_f"),
    _f(K.FLYWHEEL_INERTIA_KG_M2, "kg m^2", "flywheel inertia J_f"),
    _f(K.DRAG_COEFF_N_S2_PER_M2, "N s^2/m^2", "drag coefficient alpha_d", positive=False),
    _f(K.WHEEL_UNLOADED_RADIUS_M, "m", "unloaded tyre radius r0"),
    _f(K.WHEEL_INERTIA_KG_M2, "kg m^2", "wheel inertia J_w"),
    _f(K.RADIUS_A_M_PER_N2, "m/N^2", "radius reduction, quadratic term a", positive=False),
    _f(K.RADIUS_B_M_PER_N, "m/N", "radius reduction, linear term b", positive=False),
    _f(K.RADIUS_C_M, "m", "radius reduction, constant term c", positive=False),
    _f(K.FRICTION_THETA1, "-", "Burckhardt theta1"),
    _f(K.FRICTION_THETA2, "-", "Burckhardt theta2"),
    _f(K.FRICTION_THETA3, "-", "Burckhardt theta3", positive=False),
    _f(K.GEAR_WALK_LENGTH_M, "m", "gear-walk lever L_gw"),
    _f(K.GEAR_WALK_INERTIA_KG_M2, "kg m^2", "gear inertia about the attachment"),
    _f(K.GEAR_WALK_STIFFNESS_N_M_PER_RAD, "N m/rad", "gear-walk stiffness k_theta"),
    _f(K.GEAR_WALK_DAMPING_N_M_S_PER_RAD, "N m s/rad", "gear-walk damping c_theta",
       positive=False),
    _f(K.AIRCRAFT_MASS_KG, "kg", "aircraft mass share on this wheel m_a"),
    _f(K.AIRCRAFT_WHEEL_MASS_KG, "kg", "wheel mass m_w", positive=False),
    _f(K.AIRCRAFT_GEAR_MASS_KG, "kg", "gear mass m_gw", positive=False),
    _f(K.BRAKE_GAIN_N_M_PER_PA, "N m/Pa", "brake gain k_b = mu_b A_p R_eff n_s"),
    _f(K.BRAKE_FADE_FRACTION, "-", "gain lost when fully faded (brake_fade)", positive=False),
    _f(K.BRAKE_FADE_ENERGY_J, "J", "brake energy scale of the fade (brake_fade)"),
    _f(K.TYRE_RELAXATION_LENGTH_M, "m", "tyre relaxation length (tire_relaxation)",
       positive=False),
    _f(K.ACTUATOR_MAX_CURRENT_A, "A", "valve current range upper limit"),
    _f(K.ACTUATOR_DEADBAND_CURRENT_A, "A", "static map dead-band I0", positive=False),
    _f(K.ACTUATOR_MAP_K1_PA_PER_A, "Pa/A", "static map linear gain k1"),
    _f(K.ACTUATOR_MAP_K2_PA_PER_A2, "Pa/A^2", "static map curvature k2", positive=False),
    _f(K.ACTUATOR_MAX_PRESSURE_PA, "Pa", "static map saturation P_max"),
    _f(K.ACTUATOR_GAIN, "-", "A(s) static gain"),
    _f(K.ACTUATOR_NATURAL_FREQUENCY_HZ, "Hz", "A(s) natural frequency"),
    _f(K.ACTUATOR_DAMPING_RATIO, "-", "A(s) damping ratio"),
    _f(K.ACTUATOR_DELAY_S, "s", "transport delay current -> pressure (actuator_delay)",
       positive=False),
    _f(K.LOADING_STATIC_LOAD_N, "N", "vertical load at zero speed F_z0"),
    _f(K.LOADING_LIFT_COEFF_N_S2_PER_M2, "N s^2/m^2", "lift coefficient k_L", positive=False),
    _f(K.LOADING_SERVO_TIME_CONSTANT_S, "s", "loading-device servo time constant"),
    _f(K.LOADING_TOUCHDOWN_RAMP_S, "s", "load ramp duration at touch-down", positive=False),
    _f(K.RIG_TEST_INITIAL_SPEED_M_S, "m/s", "flywheel rim speed at the start v0",
       positive=False),
    _f(K.RIG_TEST_TOUCHDOWN_S, "s", "touch-down time", positive=False),
    _f(K.RIG_TEST_BRAKE_START_S, "s", "braking starts t_brake", positive=False),
    _f(K.RIG_TEST_BRAKE_RAMP_S, "s", "current ramp-in at braking start", positive=False),
    _f(K.RIG_TEST_STOP_SPEED_M_S, "m/s", "run stops when the flywheel is slower",
       positive=False),
    _f(K.RIG_TEST_MAX_DURATION_S, "s", "longest run"),
    _f(K.SENSORS_PRESSURE_NOISE_PA, "Pa", "pressure transducer noise std", positive=False),
    _f(K.SENSORS_SPEED_NOISE_RAD_S, "rad/s", "encoder noise std", positive=False),
    _f(K.SENSORS_FORCE_NOISE_N, "N", "load-cell noise std", positive=False),
    ParamSpec(K.SENSORS_PRESSURE_OFFSET_PA, "Pa",
              "pressure transducer offset (pressure_sensor_offset)", signed=True),
    _f(K.SIMULATION_OUTPUT_RATE_HZ, "Hz", "output (and input hold) rate"),
    # new keys go last: the compiled physics caches each module with the indices it saw,
    # and a module that did not change is not recompiled (shifted indices = wrong physics)
    ParamSpec(K.BRAKE_GAIN_SLOPE_WHEEL_SPEED_S_PER_RAD, "s/rad",
              "relative change of k_b per rad/s of wheel speed (a term the catalogue lacks; "
              "0: none)", signed=True, default=0.0),
    ParamSpec(K.BRAKE_GAIN_SLOPE_PRESSURE_PER_PA, "1/Pa",
              "relative change of k_b per Pa of brake pressure (torque not linear in "
              "pressure; 0: none)", signed=True, default=0.0),
    ParamSpec(K.SENSORS_CROSSTALK_FX_PER_FZ, "-",
              "fraction of the vertical load the longitudinal load-cell channel reads "
              "(a channel that is not clean; 0: none)", signed=True, default=0.0),
    ParamSpec(K.SENSORS_WHEEL_SPEED_DELAY_S, "s",
              "the wheel-speed channel reads the wheel this much earlier than the others are "
              "read (a logger channel out of step; 0: none)", default=0.0),
    ParamSpec(K.FRICTION_CHANGE_SPEED_M_S, "m/s",
              "below this vehicle speed the tyre runs on a second surface, friction.after_* "
              "(a mu-jump mid-stop: a wet or icy patch; 0: one surface)", default=0.0),
    ParamSpec(K.FRICTION_AFTER_THETA1, "-", "Burckhardt theta1 of the second surface",
              default=0.0),
    ParamSpec(K.FRICTION_AFTER_THETA2, "-", "Burckhardt theta2 of the second surface",
              default=0.0),
    ParamSpec(K.FRICTION_AFTER_THETA3, "-", "Burckhardt theta3 of the second surface",
              default=0.0),
    ParamSpec(K.ACTUATOR_BACKLASH_A, "A",
              "play of the valve in current: the static map sees the current only once it "
              "has moved this much the other way (a hysteresis the catalogue lacks; 0: none)",
              default=0.0),
    ParamSpec(K.BRAKE_GAIN_DRIFT_PER_RUN, "-",
              "relative change of k_b from one braking run of a campaign to the next, in run "
              "order, about the middle run (wear; a campaign-level term: a run simulated on "
              "its own has the middle run's k_b; 0: none)", signed=True, default=0.0),
    ParamSpec(K.FRICTION_LOAD_SENSITIVITY_PER_N, "1/N",
              "relative change of mu per N of vertical load above friction.reference_load_n: "
              "mu = mu_B(slip) (1 - kappa (F_z - F_ref)) (a tyre's load sensitivity; 0: none)",
              signed=True, default=0.0),
    ParamSpec(K.FRICTION_REFERENCE_LOAD_N, "N",
              "vertical load at which the friction curve mu_B holds (0: at "
              "loading.static_load_n); a run at another static load keeps it", default=0.0),
    *_ripple("sensors.wheel_runout", "the wheel encoder reads omega", "run-out, an "
             "out-of-round code wheel", "its wheel channel"),
    ParamSpec(K.BRAKE_FADE_SHAPE, "-",
              "shape s of the fade (brake_fade): k_b (1 - fraction g(E/energy)), g(x) = 1 - (1 + "
              "s x)^(-1/s); 0: the exponential 1 - exp(-x), 1: the hyperbola x/(1 + x); the "
              "same first slope for every s", default=0.0),
    ParamSpec(K.SENSORS_PRESSURE_DELAY_S, "s",
              "the pressure channel reads the pressure this much earlier than the others are "
              "read (a logger channel out of step; 0: none)", default=0.0),
    *_ripple("brake.runout", "the brake torque is k_b P", "a disc's run-out, thickness "
             "variation", "its torque balance"),
    _slot(K.WHEEL_EXTRA_TORQUE_N_M, "N m", "torque T0 opposing the wheel's rotation beside the "
          "brake's (a bearing's friction, a released brake that drags)"),
    _slot(K.WHEEL_EXTRA_TORQUE_N_M_S_PER_RAD, "N m s/rad", "torque T1 omega opposing the "
          "wheel's rotation (a viscous bearing, a seal)"),
    _slot(K.FLYWHEEL_EXTRA_FORCE_N, "N", "force F0 opposing the flywheel's motion at its rim "
          "beside the drag (its bearings' friction)"),
    _slot(K.FLYWHEEL_EXTRA_FORCE_N_S_PER_M, "N s/m", "force F1 v opposing the flywheel's "
          "motion (eddy currents, a viscous bearing)"),
    _slot(K.LOADING_EXTRA_LOAD_N_S_PER_M, "N s/m", "load c v the loading device loses with "
          "the speed beside the lift law: F_z0 - k_L v^2 - c v"),
    _slot(K.ACTUATOR_EXTRA_MAP_PA_PER_A3, "Pa/A^3", "static map term k3 (I - I0)^3 beside "
          "k1, k2 (a map that bends: flow forces, a spring's progression)"),
    *_slot_terms(K.WHEEL_TERMS, "N m", "the wheel's torque balance: J_w dw/dt = r F_x - T_b - "
                 "sum c_k phi_k"),
    *_slot_terms(K.TYRE_TERMS, "-", "the tyre's friction law: mu = mu_B(slip) (load factor) "
                 "+ sum c_k phi_k"),
    *_slot_terms(K.LOADING_TERMS, "N", "the loading device's set point: F_z0 - k_L v^2 - "
                 "sum c_k phi_k"),
    *_slot_terms(K.FX_TERMS, "N", "the load cell's F_x channel: F_x,read = F_x + c F_z + "
                 "sum c_k phi_k"),
    *_slot_terms(K.VALVE_TERMS, "Pa", "the valve's dynamics A(s): P'' = w_n^2 (mu P_static "
                 "+ sum c_k phi_k - P) - 2 zeta w_n P'"),
    *_slot_terms(K.FLYWHEEL_TERMS, "N", "m_f dv/dt = -F_x - alpha_d v^2 - ... - sum c_k phi_k"),
    *_slot_terms(K.MAP_TERMS, "Pa", "P_static = k1 e + k2 e^2 + ... + sum c_k phi_k(e)"),
    *_slot_terms(K.PRESSURE_TERMS, "Pa", "P_read = P + offset + sum c_k phi_k(P, t)"),
)

INDEX: dict[str, int] = {spec.key: i for i, spec in enumerate(SPECS)}
N_PARAMS: int = len(SPECS)
SPEC_BY_KEY: dict[str, ParamSpec] = {spec.key: spec for spec in SPECS}
"""Each key's spec (its unit, bounds, whether it may be negative)."""
_OWNED_SECTIONS: frozenset[str] = frozenset(key.split(".")[0] for key in INDEX)

Value = float | bool | str


@dataclass(frozen=True)
class RigParameters:
    """A complete, validated parameter set.

    ``values`` maps every key of :data:`SPECS` to its value (SI, as in the files);
    ``sources`` names the files it came from, for messages and reports.
    """

    values: Mapping[str, Value]
    sources: tuple[str, ...] = field(default=())

    def __post_init__(self) -> None:
        _check_values(self.values, {}, self.sources)

    def __getitem__(self, key: str) -> Value:
        return self.values[key]

    def number(self, key: str) -> float:
        """A numeric parameter as float."""
        return float(self.values[key])

    def has(self, element: str) -> bool:
        """Whether a switchable element is on."""
        return bool(self.values[f"elements.{element}"])

    @property
    def configuration(self) -> str:
        return str(self.values[K.CONFIGURATION])

    def replace(self, overrides: Mapping[str, Value], source: str = "override") -> RigParameters:
        """A copy with some values changed (validated like a file)."""
        _check_known(overrides, source)
        return RigParameters({**self.values, **overrides}, (*self.sources, source))

    def without(self, *elements: str) -> RigParameters:
        """A copy with the named elements switched off (this set when none is named)."""
        if not elements:
            return self
        if unknown := [e for e in elements if e not in ELEMENTS]:
            raise ParameterError(
                f"unknown element {unknown[0]!r}; switchable elements: {', '.join(ELEMENTS)}")
        return self.replace({f"elements.{e}": False for e in elements},
                            f"--without {','.join(elements)}")

    def vector(self) -> np.ndarray:
        """The set packed for the compiled physics, shape ``(N_PARAMS,)``."""
        import numpy as np  # here: the CLI's parser reads this module, numpy costs 0.2 s

        out = np.empty(N_PARAMS)
        for spec in SPECS:
            value = self.values[spec.key]
            if spec.kind == "choice":
                out[INDEX[spec.key]] = spec.choices.index(str(value))
            else:
                out[INDEX[spec.key]] = float(value)
        return out

    def to_yaml(self, path: Path, node: str = "/**", header: Sequence[str] = (),
                notes: Mapping[str, str] | None = None) -> None:
        """Write the set as a ROS 2 params file loadable by :func:`load_parameters`, with
        ``header`` and ``notes`` (by key) as comments (:func:`~.params_file.params_text`)."""
        nested: dict[str, Any] = {}
        for spec in SPECS:
            section = nested
            *parents, leaf = spec.key.split(".")
            for part in parents:
                section = section.setdefault(part, {})
            value = self.values[spec.key]
            section[leaf] = float(value) if spec.kind == "float" else value
        Path(path).write_text(params_text(nested, node, header, notes), encoding="utf-8")


def load_parameters(
    files: Sequence[Path | str] | None = None,
    overrides: Mapping[str, Value] | None = None,
    over_reference: bool = False,
) -> RigParameters:
    """Load and validate a parameter set.

    Args:
        files: params files, later ones overriding earlier ones; ``None`` means
            the bundled reference rig. A file may hold only some keys (an overlay),
            but the union must define every key.
        overrides: final ``{key: value}`` changes (e.g. from ``--set``).
        over_reference: ``files`` layered over the bundled reference rig: a user's
            datasheet names only what differs (as the graph's nodes read a params file).

    Raises:
        ParameterError: a file is unreadable, or a value is missing, unknown,
            negative, non-finite or of the wrong type; the message names the key
            and the file.
    """
    given = [Path(f) for f in files or ()]
    paths = [*default_config_files(), *given] if over_reference or not given else given
    values: dict[str, Value] = {}
    origin: dict[str, str] = {}
    for path in paths:
        for key, value in read_params_file(path).items():
            values[key] = _as_ros_reads_it(key, value)
            origin[key] = str(path)
    sources = tuple(str(p) for p in paths)
    for spec in SPECS:
        if spec.default is not None and spec.key not in values:
            values[spec.key], origin[spec.key] = spec.default, "default"
    if overrides:
        _check_known(overrides, "--set")
        values.update({key: _as_ros_reads_it(key, value) for key, value in overrides.items()})
        origin.update(dict.fromkeys(overrides, "--set"))
        sources = (*sources, "--set")
    _check_values(values, origin, sources)
    return RigParameters(values, sources)


def read_params_file(path: Path) -> dict[str, Value]:
    """The flattened model keys of one ROS 2 params file.

    All node sections are merged in file order; sections the model does not own
    (e.g. a controller's) are ignored, unknown keys in the model's sections are
    an error (a typo would otherwise silently keep the default).
    """
    try:
        document = yaml.safe_load(Path(path).read_text(encoding="utf-8"))
    except OSError as exc:
        raise ParameterError(f"{path}: cannot read params file ({exc.strerror})") from None
    except UnicodeDecodeError as exc:
        raise ParameterError(f"{path}: not UTF-8 text (byte {exc.start}): save it as UTF-8, "
                             "as YAML asks") from None
    except yaml.YAMLError as exc:
        raise ParameterError(f"{path}: not valid YAML ({_one_line(exc)})") from None
    if not isinstance(document, dict):
        raise ParameterError(f"{path}: not a ROS 2 params file (expected 'node: ros__parameters:')")
    flat: dict[str, Value] = {}
    for node, body in document.items():
        if not isinstance(body, dict) or "ros__parameters" not in body:
            raise ParameterError(f"{path}: section {node!r} has no 'ros__parameters'")
        flat.update(flatten(body["ros__parameters"] or {}))
    owned = {k: v for k, v in flat.items() if k.split(".")[0] in _OWNED_SECTIONS}
    _check_known(owned, str(path))
    return owned


def _as_ros_reads_it(key: str, value: Value) -> Value:
    """PyYAML (YAML 1.1) reads ``6.9e5`` as text; ROS's parser reads a double: follow ROS."""
    if isinstance(value, str) and SPEC_BY_KEY[key].kind == "float":
        try:
            return float(value)
        except ValueError:
            return value
    return value


def _one_line(exc: Exception) -> str:
    return " ".join(str(exc).split())


def _check_known(values: Iterable[str], source: str) -> None:
    for key in values:
        if key not in SPEC_BY_KEY:
            hint = difflib.get_close_matches(key, INDEX, n=1)
            suggestion = f" (did you mean {hint[0]!r}?)" if hint else ""
            raise ParameterError(f"{source}: unknown parameter {key!r}{suggestion}")


_NEEDS_POSITIVE = {"tire_relaxation": K.TYRE_RELAXATION_LENGTH_M}
"""An element that is on needs this parameter > 0."""


def _check_values(values: Mapping[str, Any], origin: Mapping[str, str],
                  sources: Sequence[str]) -> None:
    for spec in SPECS:
        if spec.key not in values:
            raise ParameterError(
                f"parameter {spec.key!r} is missing (looked in {', '.join(sources)})"
            )
        problem = _problem(spec, values[spec.key])
        if problem:
            where = origin.get(spec.key) or ", ".join(sources) or "parameters"
            raise ParameterError(f"{where}: parameter {spec.key!r} {problem}")
    for element, key in _NEEDS_POSITIVE.items():
        if values[f"elements.{element}"] and values[key] <= 0:
            where = origin.get(key) or ", ".join(sources) or "parameters"
            raise ParameterError(f"{where}: parameter {key!r} must be > 0 when "
                                 f"elements.{element} is true")
    if values[K.BRAKE_FADE_FRACTION] >= 1:
        raise ParameterError(f"{origin.get('brake.fade_fraction') or ', '.join(sources)}: "
                             "parameter 'brake.fade_fraction' must be < 1")


def _problem(spec: ParamSpec, value: Any) -> str | None:
    """Why ``value`` is not admissible for ``spec``, or None."""
    if spec.kind == "bool":
        return None if isinstance(value, bool) else f"must be true or false, got {value!r}"
    if spec.kind == "choice":
        return None if value in spec.choices else (
            f"must be one of {', '.join(spec.choices)}, got {value!r}")
    if isinstance(value, bool) or not isinstance(value, int | float):
        return f"must be a number [{spec.unit}], got {value!r}"
    if not math.isfinite(value):
        return f"must be finite, got {value!r}"
    if value < 0 and not spec.signed:
        return f"must not be negative, got {value!r} [{spec.unit}]"
    if spec.positive and value == 0:
        return f"must be > 0, got {value!r} [{spec.unit}]"
    if spec.key.endswith("_code") and (value != int(value) or value >= CODE_LIMIT):
        return f"must be a basis function's code (a whole number below {CODE_LIMIT}), got " \
            f"{value!r}"
    return None


def parse_assignment(text: str) -> tuple[str, Value]:
    """Parse ``KEY=VALUE`` from the command line; the value is read as YAML."""
    key, sep, raw = text.partition("=")
    if not sep or not key:
        raise ParameterError(f"--set expects KEY=VALUE, got {text!r}")
    try:
        value = yaml.safe_load(raw)
    except yaml.YAMLError:
        value = raw
    return key.strip(), value


Computed = TypeVar("Computed")


class PerSet(Generic[Computed]):
    """What ``compute`` gives under each parameter set asked for, each set computed once:
    by identity, as sets are immutable (a diagnosis reads its models' simulations and their
    relation checks in several places)."""

    def __init__(self, compute: Callable[[RigParameters], Computed]) -> None:
        self._compute = compute
        self._done: list[tuple[RigParameters, Computed]] = []

    def of(self, params: RigParameters) -> Computed:
        """The value under ``params``."""
        for done, value in self._done:
            if done is params:
                return value
        value = self._compute(params)
        self._done.append((params, value))
        return value
