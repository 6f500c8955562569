"""The actuator block: the valve's static map, then A(s), with an optional transport delay.

The static map is :func:`landing_gear_sim.model.elements.valve_map`; A(s) is the unit
second-order lag μ ω_n² / (s² + 2 ξ ω_n s + ω_n²) of eq. (10), written once as a state
space (:func:`second_order_system`) from which come the exact discretisation the
plant steps (:func:`actuator_matrices`), the frequency response identification fits
(:func:`second_order_response`) and the continuous equations of the reference solution.
State: pressure [Pa] and its rate [Pa/s], driven by the static-map pressure [Pa].

A(s) holds the valve's generic slot (``actuator.term_*``, ``model.basis``): a term
Σ c_k φ_k(P, Ṗ, ΔP) [Pa] beside the static pressure it is driven by,
P̈ = ω_n² (μ P_static + Σ c_k φ_k − P) − 2 ξ ω_n Ṗ, with ΔP = μ P_static − P: a spool's
friction (c sgn Ṗ; memoryless, so no stick-slip: at rest it chatters onto the map), a valve
stiffer at pressure (c P·ΔP). It acts undelayed, held over a step at the mean of its values
at the step's two ends, through the unit-gain input matrix.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import scipy.linalg
from numba import njit

from landing_gear_sim.model import basis
from landing_gear_sim.model import elements as el
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.dual_arrays import vector_like
from landing_gear_sim.model.parameters import INDEX, RigParameters

_ACT_GAIN = INDEX[K.ACTUATOR_GAIN]
_ACT_WN = INDEX[K.ACTUATOR_NATURAL_FREQUENCY_HZ]
_ACT_ZETA = INDEX[K.ACTUATOR_DAMPING_RATIO]
_ACT_DELAY = INDEX[K.ACTUATOR_DELAY_S]
_BACKLASH = INDEX[K.ACTUATOR_BACKLASH_A]
_VALVE_SLOT = INDEX[K.VALVE_TERMS[0][0]]
PLAY = 2  # actuator state: pressure, rate, the current the valve sees, static pressures


def second_order_system(natural_frequency_hz: float, damping_ratio: float, gain: float
                        ) -> tuple[np.ndarray, np.ndarray]:
    """A(s) as ẋ = a x + b u, x = (pressure [Pa], rate [Pa/s]), u the static-map pressure
    [Pa]; shapes (2, 2) and (2,)."""
    wn = 2.0 * math.pi * natural_frequency_hz
    a = np.array([[0.0, 1.0], [-wn * wn, -2.0 * damping_ratio * wn]])
    b = np.array([0.0, gain * wn * wn])
    return a, b


def second_order_response(frequency_hz: np.ndarray, natural_frequency_hz: float,
                          damping_ratio: float, gain: float) -> np.ndarray:
    """A(j 2π f) at each frequency [Hz] (complex, shape of ``frequency_hz``), from the same
    state space the plant steps."""
    a, b = second_order_system(natural_frequency_hz, damping_ratio, gain)
    s = 2j * np.pi * np.asarray(frequency_hz, dtype=float)
    resolvent = s[..., None, None] * np.eye(2) - a
    return np.linalg.solve(resolvent, np.broadcast_to(b, (*s.shape, 2))[..., None])[..., 0, 0]


def actuator_system(params: RigParameters) -> tuple[np.ndarray, np.ndarray]:
    """A(s) of a parameter set (see :func:`second_order_system`)."""
    return second_order_system(params.number(K.ACTUATOR_NATURAL_FREQUENCY_HZ),
                               params.number(K.ACTUATOR_DAMPING_RATIO),
                               params.number(K.ACTUATOR_GAIN))


def _zoh(a: np.ndarray, b: np.ndarray, span_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Φ = e^{A T}, Γ = ∫₀ᵀ e^{A s} ds B for an input held over ``span_s``."""
    augmented = np.zeros((3, 3))
    augmented[:2, :2], augmented[:2, 2] = a, b
    m = scipy.linalg.expm(augmented * span_s)
    return m[:2, :2], m[:2, 2]


ACT_DELAY_STEPS = 8  # position of the whole-step delay in the actuator matrices
ACT_SLOT = 9  # ... and of the slot's input matrix over a whole step (2 entries)


def actuator_matrices(params_vector: np.ndarray, step_s: float) -> np.ndarray:
    """Exact discretisation of A(s) with the held input delayed by ``actuator.delay_s``.

    With the delay d = (m + f)·h, the input seen over step k is u_{k−m−1} for f·h,
    then u_{k−m} for (1−f)·h, so x_{k+1} = Φ_h x_k + G0 u_{k−m} + G1 u_{k−m−1} with
    G0 = Γ_{(1−f)h} and G1 = Φ_{(1−f)h} Γ_{fh}. Returns
    ``[Φ00, Φ01, Φ10, Φ11, G0₀, G0₁, G1₀, G1₁, m, Γ₀, Γ₁]`` for the state (pressure [Pa],
    rate [Pa/s]) driven by the static-map pressure; Γ = Γ_h of the unit-gain input, the
    valve's slot's.
    """
    p = params_vector
    delay = float(p[_ACT_DELAY]) if p[el.HAS_ACTUATOR_DELAY] else 0.0
    return _matrices(float(p[_ACT_WN]), float(p[_ACT_ZETA]), float(p[_ACT_GAIN]), delay,
                     float(step_s)).copy()


@functools.lru_cache(maxsize=256)
def _matrices(natural_frequency_hz: float, damping_ratio: float, gain: float, delay_s: float,
              step_s: float) -> np.ndarray:
    # cached: a fit simulates the same actuator hundreds of times (the matrix exponentials
    # cost ~1 ms, 5-10 % of a run's simulation) while it varies wheel parameters
    a, b = second_order_system(natural_frequency_hz, damping_ratio, gain)
    steps = delay_s / step_s
    whole = math.floor(steps + 1e-9)
    fraction = steps - whole if steps - whole > 1e-9 else 0.0
    phi, gamma = _zoh(a, b, step_s)
    if fraction == 0.0:
        g0, g1 = gamma, np.zeros(2)
    else:
        phi_late, g0 = _zoh(a, b, (1.0 - fraction) * step_s)
        g1 = phi_late @ _zoh(a, b, fraction * step_s)[1]
    unit = _zoh(a, b / gain, step_s)[1] if gain != 0.0 else np.zeros(2)
    return np.concatenate([phi.ravel(), g0, g1, [float(whole)], unit])


@njit(cache=True)
def actuator_state(matrices):
    """Zero actuator state: pressure, rate, the current the valve sees (after its play),
    then the static pressures of recent steps."""
    return vector_like(matrices, PLAY + 1 + int(matrices[ACT_DELAY_STEPS]) + 2)


@njit(cache=True)
def valve_play(backlash_a, seen_a, current_a):
    """The current the valve sees after its play: it follows ``current_a`` only once that
    is more than half the backlash away (a play operator; ``seen_a`` is the last one)."""
    half = 0.5 * backlash_a
    return min(max(seen_a, current_a - half), current_a + half)


@njit(cache=True)
def actuator_step(p, matrices, xa, current_a):
    """Advance the actuator state ``xa`` one step with ``current_a`` held; return P [Pa]."""
    first = PLAY + 1
    for j in range(xa.size - 1, first, -1):  # shift register of static-map pressures
        xa[j] = xa[j - 1]
    seen = current_a
    if p[_BACKLASH] > 0.0:
        seen = valve_play(p[_BACKLASH], xa[PLAY], current_a)
        xa[PLAY] = seen
    xa[first] = el.valve_static_pressure(p, seen)
    whole = int(matrices[ACT_DELAY_STEPS])
    newer, older = xa[first + whole], xa[first + 1 + whole]
    if p[el.HAS_ACTUATOR_DYNAMICS] == 0.0:
        xa[0], xa[1] = p[_ACT_GAIN] * newer, 0.0
        return xa[0]
    m = matrices
    x0, x1 = xa[0], xa[1]
    y0 = m[0] * x0 + m[1] * x1 + m[4] * newer + m[6] * older
    y1 = m[2] * x0 + m[3] * x1 + m[5] * newer + m[7] * older
    # the slot's term held over the step at the mean of its ends (Heun): held at the step's
    # start it lags half a step, 5 % of what a stiffening term moves
    first_slot = valve_slot(p, x0, x1, newer)
    late = valve_slot(p, y0 + m[ACT_SLOT] * first_slot, y1 + m[ACT_SLOT + 1] * first_slot,
                      newer)
    slot = 0.5 * (first_slot + late)
    xa[0] = y0 + m[ACT_SLOT] * slot
    xa[1] = y1 + m[ACT_SLOT + 1] * slot
    return xa[0]


@njit(cache=True, inline="always")
def valve_slot(p, pressure_pa, rate_pa_s, static_pa):
    """The valve's generic slot [Pa] at its state, ``static_pa`` the (delayed) static-map
    pressure it is driven by (0 on the reference rig)."""
    if not basis.slot_acts(p, _VALVE_SLOT):
        return 0.0
    error = p[_ACT_GAIN] * static_pa - pressure_pa
    return basis.slot_value(p, _VALVE_SLOT, (0.0, 0.0, pressure_pa, 0.0, 0.0, 0.0, 0.0, 0.0,
                                             0.0, 0.0, rate_pa_s, error, 0.0))


@njit(cache=True, nogil=True)  # a fit's trial valves run side by side on threads
def settled_response(p, matrices, current):
    """Pressure [Pa] for a held current sequence, starting in steady state at the first
    current (A(s) is stable: the state settles on that level first)."""
    return settled_states(p, matrices, current)[:, 0]


@njit(cache=True)
def settled_state(p, matrices, current_a):
    """The actuator state settled on ``current_a`` held: where a part of a run cut in time,
    or a log that starts mid-hold, starts (zero for a current below the dead-band)."""
    xa = actuator_state(matrices)
    seen = current_a
    if p[_BACKLASH] > 0.0:
        seen = valve_play(p[_BACKLASH], 0.0, current_a)
        xa[PLAY] = seen
    # the delay's register full of the held level first: the settling is then the same
    # arithmetic with a delay as without (a delay shifts a run's pressure exactly), and
    # does not stop at once on a pressure resting until the delayed level arrives
    xa[PLAY + 1:] = el.valve_static_pressure(p, seen)
    for _ in range(100000):
        before = xa[0]
        actuator_step(p, matrices, xa, current_a)
        if abs(xa[0] - before) < 1e-9 and abs(xa[1]) < 1e-6:
            break
    return xa


@njit(cache=True)
def settled_states(p, matrices, current):
    """A(s)'s state for a held current sequence as :func:`settled_response` steps it, (n, 3):
    pressure [Pa], its rate [Pa/s], and the delayed static-map pressure [Pa] driving the
    step from each sample to the next (the valve's slot's signals)."""
    xa = settled_state(p, matrices, current[0])
    out = np.empty((current.size, 3))
    newest = PLAY + 1 + int(matrices[ACT_DELAY_STEPS])
    for k in range(current.size):
        out[k, 0], out[k, 1] = xa[0], xa[1]
        if k + 1 < current.size:
            actuator_step(p, matrices, xa, current[k])
        out[k, 2] = xa[newest]
    return out


def actuator_pressure(params: RigParameters, current_a: np.ndarray, rate_hz: float
                      ) -> np.ndarray:
    """Model pressure [Pa] for a held current sequence [A] at ``rate_hz``, from steady
    state at the first level; shape of ``current_a``."""
    vector = params.vector()
    return settled_response(vector, actuator_matrices(vector, 1.0 / rate_hz), current_a)
