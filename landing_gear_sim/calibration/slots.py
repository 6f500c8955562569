"""The equations' generic slots (``model.basis``) read from a braking run's measured signals.

The plant evaluates each slot at the signals its equation sees; the calibration reads
around a slot the model has (the torque balance takes the wheel's off the brake's torque,
the friction samples take the tyre's off μ, a run's static load adds the loading device's),
and the diagnosis regresses an equation's error on its library, both on the same signals
measured: :func:`signals` builds them, :data:`SEES` says which each equation sees (the
others are 0, as in the plant).
"""

from __future__ import annotations

import enum

import numpy as np

from landing_gear_sim.model import basis
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.elements import slip_ratio
from landing_gear_sim.model.parameters import INDEX, RigParameters
from landing_gear_sim.model.quantities import friction_at, rolling_radius_at


class Slot(str, enum.Enum):
    """An equation with a generic slot (its value names it: its keys' section, or the
    section and the equation where a section holds two)."""

    WHEEL = "wheel"
    TYRE = "friction"
    LOADING = "loading"
    FX_CHANNEL = "sensors"
    VALVE = "actuator"
    FLYWHEEL = "flywheel"
    STATIC_MAP = "actuator_map"
    PRESSURE_CHANNEL = "sensors_p"

    @property
    def keys(self) -> tuple[tuple[str, str], ...]:
        """Its (code, coefficient) keys."""
        return {"wheel": K.WHEEL_TERMS, "friction": K.TYRE_TERMS,
                "loading": K.LOADING_TERMS, "sensors": K.FX_TERMS,
                "actuator": K.VALVE_TERMS, "flywheel": K.FLYWHEEL_TERMS,
                "actuator_map": K.MAP_TERMS, "sensors_p": K.PRESSURE_TERMS}[self.value]

    def value_of(self, params: RigParameters, measured: np.ndarray) -> np.ndarray:
        """The slot of ``params`` at each row of ``measured`` (:func:`signals`)."""
        if all(params.number(coeff) == 0.0 for _, coeff in self.keys):
            return np.zeros(measured.shape[0])
        return basis.slot_values(params.vector(), INDEX[self.keys[0][0]], seen(self, measured))

    def occupied(self, params: RigParameters) -> int:
        """How many of its terms ``params`` fills."""
        return sum(params.number(coeff) != 0.0 for _, coeff in self.keys)


SEES: dict[Slot, tuple[int, ...]] = {
    Slot.WHEEL: (basis.OMEGA, basis.SPEED, basis.PRESSURE, basis.LOAD, basis.SLIP,
                 basis.BRAKE_ENERGY, basis.WHEEL_ANGLE),
    Slot.TYRE: (basis.SPEED, basis.LOAD, basis.SLIP, basis.CURVE),
    Slot.LOADING: (basis.SPEED, basis.CONTACT_TIME),
    Slot.FX_CHANNEL: (basis.LOAD, basis.RUN_TIME),
    Slot.VALVE: (basis.PRESSURE, basis.PRESSURE_RATE, basis.VALVE_ERROR),
    Slot.FLYWHEEL: (basis.SPEED, basis.LOAD),
    Slot.STATIC_MAP: (basis.VALVE_CURRENT,),
    Slot.PRESSURE_CHANNEL: (basis.PRESSURE, basis.RUN_TIME),
}
"""The signals each equation's slot sees in the plant (``model.elements``)."""


def map_signals(excess_a: np.ndarray) -> np.ndarray:
    """The static map's signals at the map's variables ``excess_a`` (e = I − I0 [A])."""
    out = np.zeros((np.size(excess_a), basis.N_SIGNALS))
    out[:, basis.VALVE_CURRENT] = excess_a
    return out


def seen(slot: Slot, measured: np.ndarray) -> np.ndarray:
    """``measured`` with the signals ``slot`` does not see at 0, contiguous."""
    out = np.zeros_like(measured)
    visible = list(SEES[slot])
    out[:, visible] = measured[:, visible]
    return np.ascontiguousarray(out)


def signals(time_s: np.ndarray, wheel_rad_s: np.ndarray, speed_m_s: np.ndarray,
            pressure_pa: np.ndarray, load_n: np.ndarray, energy_j: np.ndarray,
            params: RigParameters) -> np.ndarray:
    """Every signal of ``model.basis`` from a run's measured ones (n, N_SIGNALS): the slip
    at the loaded radius, the wheel's angle integrated from the run's start, the time since
    the model's touch-down (0 before it), the model's friction curve at the slip."""
    radius = rolling_radius_at(params, load_n)
    out = np.zeros((time_s.size, basis.N_SIGNALS))  # A(s)'s states: the valve's, not read here
    out[:, basis.OMEGA] = wheel_rad_s
    out[:, basis.SPEED] = speed_m_s
    out[:, basis.PRESSURE] = pressure_pa
    out[:, basis.LOAD] = load_n
    out[:, basis.SLIP] = np.abs(slip_ratio(speed_m_s, wheel_rad_s, radius))
    out[:, basis.BRAKE_ENERGY] = energy_j
    dt = np.diff(time_s, prepend=time_s[0])
    out[:, basis.WHEEL_ANGLE] = np.cumsum(wheel_rad_s * dt)
    out[:, basis.CONTACT_TIME] = np.maximum(
        time_s - params.number(K.RIG_TEST_TOUCHDOWN_S), 0.0)
    out[:, basis.CURVE] = friction_at(params, out[:, basis.SLIP])
    out[:, basis.RUN_TIME] = time_s - time_s[0]
    return out
