"""Model elements: one physical law each, compiled with numba. Each law is written here once.

The laws with explicit coefficients (:func:`burckhardt_mu`, :func:`slip_ratio`,
:func:`valve_map`, :func:`fade_factor`) take floats or numpy arrays alike — the same
compiled definition serves the plant's scalar loop and the array code of calibration,
metrics and plots. They are inlined into their callers (``inline="always"``): as separate
calls they made the plant's RK4 loop 24 % slower. The others take the packed parameter
vector ``p`` (see :mod:`landing_gear_sim.model.parameters`) and SI quantities, and are
pure. The plant (:mod:`landing_gear_sim.model.plant`) composes them; a switchable element
is skipped when its ``elements.<name>`` flag is 0. Equation numbers refer to the paper.
:mod:`landing_gear_sim.model.quantities` evaluates them on arrays for a parameter set.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from landing_gear_sim.model import basis
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import INDEX

GRAVITY_M_S2 = 9.80665
MIN_HUB_SPEED_M_S = 0.05  # slip is undefined at rest; the stop rule keeps runs above this

# Positions in the packed vector; numba freezes module globals as constants.
CONFIGURATION = INDEX[K.CONFIGURATION]
HAS_GEAR_WALK = INDEX[K.ELEMENTS_GEAR_WALK]
HAS_RADIUS = INDEX[K.ELEMENTS_LOAD_DEPENDENT_RADIUS]
HAS_ACTUATOR_DYNAMICS = INDEX[K.ELEMENTS_ACTUATOR_DYNAMICS]
HAS_DRAG = INDEX[K.ELEMENTS_DRAG]
HAS_ACTUATOR_DELAY = INDEX[K.ELEMENTS_ACTUATOR_DELAY]
HAS_RELAXATION = INDEX[K.ELEMENTS_TIRE_RELAXATION]
HAS_FADE = INDEX[K.ELEMENTS_BRAKE_FADE]
RELAXATION = INDEX[K.TYRE_RELAXATION_LENGTH_M]
FADE_FRACTION = INDEX[K.BRAKE_FADE_FRACTION]
FADE_ENERGY = INDEX[K.BRAKE_FADE_ENERGY_J]
FADE_SHAPE = INDEX[K.BRAKE_FADE_SHAPE]
BRAKE_RUNOUT_1 = INDEX[K.BRAKE_RUNOUT_1]
BRAKE_RUNOUT_1_PHASE = INDEX[K.BRAKE_RUNOUT_1_PHASE_RAD]
BRAKE_RUNOUT_2 = INDEX[K.BRAKE_RUNOUT_2]
BRAKE_RUNOUT_2_PHASE = INDEX[K.BRAKE_RUNOUT_2_PHASE_RAD]
GAIN_SLOPE_SPEED = INDEX[K.BRAKE_GAIN_SLOPE_WHEEL_SPEED_S_PER_RAD]
GAIN_SLOPE_PRESSURE = INDEX[K.BRAKE_GAIN_SLOPE_PRESSURE_PER_PA]
FLY_RADIUS = INDEX[K.FLYWHEEL_RADIUS_M]
FLY_INERTIA = INDEX[K.FLYWHEEL_INERTIA_KG_M2]
DRAG = INDEX[K.DRAG_COEFF_N_S2_PER_M2]
R0 = INDEX[K.WHEEL_UNLOADED_RADIUS_M]
WHEEL_INERTIA = INDEX[K.WHEEL_INERTIA_KG_M2]
RADIUS_A = INDEX[K.RADIUS_A_M_PER_N2]
RADIUS_B = INDEX[K.RADIUS_B_M_PER_N]
RADIUS_C = INDEX[K.RADIUS_C_M]
THETA1 = INDEX[K.FRICTION_THETA1]
THETA2 = INDEX[K.FRICTION_THETA2]
THETA3 = INDEX[K.FRICTION_THETA3]
CHANGE_SPEED = INDEX[K.FRICTION_CHANGE_SPEED_M_S]
AFTER_THETA1 = INDEX[K.FRICTION_AFTER_THETA1]
# each surface's (ϑ1, ϑ2, ϑ3) are read as three consecutive entries
assert INDEX[K.FRICTION_THETA3] == THETA1 + 2
assert INDEX[K.FRICTION_AFTER_THETA3] == AFTER_THETA1 + 2
GW_LENGTH = INDEX[K.GEAR_WALK_LENGTH_M]
GW_INERTIA = INDEX[K.GEAR_WALK_INERTIA_KG_M2]
GW_STIFFNESS = INDEX[K.GEAR_WALK_STIFFNESS_N_M_PER_RAD]
GW_DAMPING = INDEX[K.GEAR_WALK_DAMPING_N_M_S_PER_RAD]
AC_MASS = INDEX[K.AIRCRAFT_MASS_KG]
AC_WHEEL_MASS = INDEX[K.AIRCRAFT_WHEEL_MASS_KG]
AC_GEAR_MASS = INDEX[K.AIRCRAFT_GEAR_MASS_KG]
BRAKE_GAIN = INDEX[K.BRAKE_GAIN_N_M_PER_PA]
MAX_CURRENT = INDEX[K.ACTUATOR_MAX_CURRENT_A]
DEADBAND = INDEX[K.ACTUATOR_DEADBAND_CURRENT_A]
MAP_K1 = INDEX[K.ACTUATOR_MAP_K1_PA_PER_A]
MAP_K2 = INDEX[K.ACTUATOR_MAP_K2_PA_PER_A2]
MAX_PRESSURE = INDEX[K.ACTUATOR_MAX_PRESSURE_PA]
LOAD_STATIC = INDEX[K.LOADING_STATIC_LOAD_N]
LOAD_SENSITIVITY = INDEX[K.FRICTION_LOAD_SENSITIVITY_PER_N]
LOAD_REFERENCE = INDEX[K.FRICTION_REFERENCE_LOAD_N]
LIFT = INDEX[K.LOADING_LIFT_COEFF_N_S2_PER_M2]
LOAD_TAU = INDEX[K.LOADING_SERVO_TIME_CONSTANT_S]
TOUCHDOWN_RAMP = INDEX[K.LOADING_TOUCHDOWN_RAMP_S]
TOUCHDOWN_T = INDEX[K.RIG_TEST_TOUCHDOWN_S]
WHEEL_EXTRA_0 = INDEX[K.WHEEL_EXTRA_TORQUE_N_M]
WHEEL_EXTRA_1 = INDEX[K.WHEEL_EXTRA_TORQUE_N_M_S_PER_RAD]
FLY_EXTRA_0 = INDEX[K.FLYWHEEL_EXTRA_FORCE_N]
FLY_EXTRA_1 = INDEX[K.FLYWHEEL_EXTRA_FORCE_N_S_PER_M]
LOAD_EXTRA_1 = INDEX[K.LOADING_EXTRA_LOAD_N_S_PER_M]
MAP_EXTRA_3 = INDEX[K.ACTUATOR_EXTRA_MAP_PA_PER_A3]
WHEEL_SLOT = INDEX[K.WHEEL_TERMS[0][0]]
TYRE_SLOT = INDEX[K.TYRE_TERMS[0][0]]
LOADING_SLOT = INDEX[K.LOADING_TERMS[0][0]]
FLYWHEEL_SLOT = INDEX[K.FLYWHEEL_TERMS[0][0]]
MAP_SLOT = INDEX[K.MAP_TERMS[0][0]]
# a slot's (code, coefficient) pairs are read as consecutive entries
assert INDEX[K.WHEEL_TERMS[-1][1]] == WHEEL_SLOT + 2 * basis.SLOT_TERMS - 1
assert INDEX[K.TYRE_TERMS[-1][1]] == TYRE_SLOT + 2 * basis.SLOT_TERMS - 1
assert INDEX[K.LOADING_TERMS[-1][1]] == LOADING_SLOT + 2 * basis.SLOT_TERMS - 1
assert INDEX[K.FLYWHEEL_TERMS[-1][1]] == FLYWHEEL_SLOT + 2 * basis.SLOT_TERMS - 1
assert INDEX[K.MAP_TERMS[-1][1]] == MAP_SLOT + 2 * basis.SLOT_TERMS - 1


@njit(cache=True, inline="always")
def burckhardt_mu(theta1, theta2, theta3, slip):
    """Burckhardt friction coefficient μ = ϑ1 (1 − e^{−ϑ2 λ}) − ϑ3 λ, eq. (11), for λ ≥ 0."""
    return theta1 * (1.0 - np.exp(-theta2 * slip)) - theta3 * slip


@njit(cache=True, inline="always")
def load_factor(p, vertical_load_n):
    """μ's factor for the load: 1 − κ (F_z − F_ref), κ the tyre's load sensitivity, F_ref
    the reference load (the static load when 0). Branch-free: inside the plant's innermost
    call a never-taken branch cost 40 % of a stop's time."""
    reference = p[LOAD_STATIC] + (p[LOAD_REFERENCE] - p[LOAD_STATIC]) * (p[LOAD_REFERENCE] > 0.0)
    return 1.0 - p[LOAD_SENSITIVITY] * (vertical_load_n - reference)


@njit(cache=True)
def tyre_friction(p, slip, speed_m_s, vertical_load_n):
    """Friction coefficient of the tyre at slip λ, vehicle speed ``speed_m_s`` and vertical
    load [N]: μ(λ) of the surface under the tyre times :func:`load_factor`, extended odd for
    λ < 0 (wheel faster than hub). Below ``friction.change_speed_m_s`` (when > 0) the tyre
    is on the second surface: a stop decelerates monotonically, so a speed marks a place on
    the runway."""
    curve = tyre_curve(p, abs(slip), speed_m_s)
    mu = curve * load_factor(p, vertical_load_n) + tyre_slot(p, slip, speed_m_s,
                                                             vertical_load_n, curve)
    return mu if slip >= 0.0 else -mu


@njit(cache=True, inline="always")
def tyre_curve(p, slip, speed_m_s):
    """μ_B(λ) of the surface under the tyre at speed ``speed_m_s``, λ ≥ 0: the first
    surface's curve, or below ``friction.change_speed_m_s`` (when > 0) the second's."""
    first = THETA1
    if p[CHANGE_SPEED] > 0.0 and speed_m_s < p[CHANGE_SPEED]:
        first = AFTER_THETA1
    return burckhardt_mu(p[first], p[first + 1], p[first + 2], slip)


@njit(cache=True)
def tyre_curves(p, slip, speed_m_s):
    """:func:`tyre_curve` of each sample of two arrays (n,)."""
    out = np.empty(slip.shape[0])
    for i in range(out.shape[0]):
        out[i] = tyre_curve(p, slip[i], speed_m_s[i])
    return out


@njit(cache=True)
def tyre_frictions(p, slip, speed_m_s, vertical_load_n):
    """:func:`tyre_friction` of each sample of three arrays (n,)."""
    out = np.empty(slip.shape[0])
    for i in range(out.shape[0]):
        out[i] = tyre_friction(p, slip[i], speed_m_s[i], vertical_load_n[i])
    return out


@njit(cache=True, inline="always")
def tyre_slot(p, slip, speed_m_s, vertical_load_n, curve):
    """The tyre equation's generic slot (``model.basis``): Σ c_k φ_k(|λ|, v, F_z, μ_B)
    added to μ, μ_B the curve at |λ| (0 on the reference rig)."""
    if not basis.slot_acts(p, TYRE_SLOT):
        return 0.0
    return basis.slot_value(p, TYRE_SLOT, (0.0, speed_m_s, 0.0, vertical_load_n, abs(slip),
                                           0.0, 0.0, 0.0, curve, 0.0, 0.0, 0.0, 0.0))


@njit(cache=True)
def burckhardt_slope_max(p, max_load_n):
    """Largest |dμ/dλ| of the curves (at λ = 0) at loads up to ``max_load_n``: the tyre's
    stiffest point."""
    slope = p[THETA1] * p[THETA2] + p[THETA3]
    if p[CHANGE_SPEED] > 0.0:
        slope = max(slope, p[AFTER_THETA1] * p[AFTER_THETA1 + 1] + p[AFTER_THETA1 + 2])
    if p[LOAD_SENSITIVITY] != 0.0:
        slope *= max(load_factor(p, 0.0), load_factor(p, max_load_n), 1.0)
    return slope


@njit(cache=True)
def rolling_radius(p, vertical_load_n):
    """Rolling radius r = r0 − (a F_z² + b F_z + c), eq. (9); r0 when the element is off."""
    if p[HAS_RADIUS] == 0.0:
        return p[R0]
    fz = vertical_load_n
    return p[R0] - (p[RADIUS_A] * fz * fz + p[RADIUS_B] * fz + p[RADIUS_C])


@njit(cache=True)
def rolling_radii(p, vertical_load_n):
    """:func:`rolling_radius` of each load of an array (n,) [m]."""
    out = np.empty(vertical_load_n.shape[0])
    for i in range(out.shape[0]):
        out[i] = rolling_radius(p, vertical_load_n[i])
    return out


@njit(cache=True, inline="always")
def slip_ratio(hub_speed_m_s, wheel_speed_rad_s, radius_m):
    """Longitudinal slip λ = (v_h − ω r)/v_h, eq. (1); v_h floored at MIN_HUB_SPEED_M_S."""
    vh = np.maximum(hub_speed_m_s, MIN_HUB_SPEED_M_S)
    return (vh - wheel_speed_rad_s * radius_m) / vh


@njit(cache=True, inline="always")
def fade_factor(fade_fraction, brake_energy_j, fade_energy_j, shape):
    """Share of the brake gain left after absorbing ``brake_energy_j`` (the ``brake_fade``
    element): 1 − φ g(E/E_f), g(x) = 1 − (1 + s x)^(−1/s) — for s = 0 the exponential
    1 − e^{−x} (its limit), for s = 1 the hyperbola x/(1 + x), the same first slope
    g'(0) = 1 for every shape s (a fade's shape is the rig's: an independent rig's
    hyperbolic fade of 15 % read as 11 % through the exponential alone)."""
    x = brake_energy_j / fade_energy_j
    if shape <= 0.0:
        return 1.0 - fade_fraction * (1.0 - np.exp(-x))
    return 1.0 - fade_fraction * (1.0 - np.exp(-np.log1p(shape * x) / shape))


@njit(cache=True)
def brake_torque(p, pressure_pa, brake_energy_j, wheel_speed_rad_s, wheel_angle_rad):
    """Brake torque T_b = k_b P_b, eq. (8); a brake cannot push, so P_b < 0 gives 0.

    With ``brake_fade`` the gain falls as the brake heats: k_b·:func:`fade_factor`. The
    gain's slopes in wheel speed and pressure (0 on the reference rig) scale it by
    1 + s_ω ω + s_P P (never below 0), and a disc's run-out by 1 + Σ e_m cos(mθ + φ_m),
    m = 1, 2, θ the wheel's angle: terms outside the paper that a rig may have.
    """
    gain = p[BRAKE_GAIN]
    if p[HAS_FADE]:
        gain *= fade_factor(p[FADE_FRACTION], brake_energy_j, p[FADE_ENERGY], p[FADE_SHAPE])
    pressure = max(pressure_pa, 0.0)
    gain *= max(1.0 + p[GAIN_SLOPE_SPEED] * wheel_speed_rad_s
                + p[GAIN_SLOPE_PRESSURE] * pressure, 0.0)
    if p[BRAKE_RUNOUT_1] != 0.0 or p[BRAKE_RUNOUT_2] != 0.0:
        gain *= 1.0 + p[BRAKE_RUNOUT_1] * math.cos(wheel_angle_rad + p[BRAKE_RUNOUT_1_PHASE]) \
            + p[BRAKE_RUNOUT_2] * math.cos(2.0 * wheel_angle_rad + p[BRAKE_RUNOUT_2_PHASE])
    return gain * pressure


@njit(cache=True)
def brake_torques(p, pressure_pa, brake_energy_j, wheel_speed_rad_s, wheel_angle_rad):
    """:func:`brake_torque` of each sample of four arrays of one shape (n,) [N m]."""
    out = np.empty(pressure_pa.shape[0])
    for i in range(out.shape[0]):
        out[i] = brake_torque(p, pressure_pa[i], brake_energy_j[i], wheel_speed_rad_s[i],
                              wheel_angle_rad[i])
    return out


@njit(cache=True)
def relaxation_rate(p, hub_speed_m_s):
    """1/τ of the tyre force lag, v_h/σ (0 when the element is off)."""
    if p[HAS_RELAXATION] == 0.0:
        return 0.0
    return max(hub_speed_m_s, MIN_HUB_SPEED_M_S) / p[RELAXATION]


@njit(cache=True)
def drag_force(p, speed_m_s):
    """Drag α_d v² (flywheel bearing/windage on the rig, aerodynamic on the aircraft)."""
    if p[HAS_DRAG] == 0.0:
        return 0.0
    return p[DRAG] * speed_m_s * abs(speed_m_s)


@njit(cache=True)
def flywheel_extra_force(p, speed_m_s):
    """The flywheel equation's named slot: F₀ sgn v + F₁ v, a force opposing the motion
    beside the drag (0 on the reference rig; floats or arrays)."""
    return p[FLY_EXTRA_0] * np.sign(speed_m_s) + p[FLY_EXTRA_1] * speed_m_s


@njit(cache=True)
def flywheel_slot(p, speed_m_s, vertical_load_n):
    """The flywheel equation's generic slot (``model.basis``): Σ c_k φ_k(v, F_z) [N]
    opposing the motion: its bearings carry the load the tyre presses on the rim."""
    return basis.slot_value(p, FLYWHEEL_SLOT, (0.0, speed_m_s, 0.0, vertical_load_n, 0.0, 0.0,
                                               0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))


@njit(cache=True, inline="always")
def flywheel_bearing_force(p, speed_m_s, vertical_load_n):
    """The force of the flywheel equation's slots [N], opposing the motion beside the drag:
    the named F₀ sgn v + F₁ v and the generic Σ c_k φ_k(v, F_z)."""
    force = flywheel_extra_force(p, speed_m_s)
    if basis.slot_acts(p, FLYWHEEL_SLOT):  # a call, not inlined: inlined it cost 3 %
        force += flywheel_slot(p, speed_m_s, vertical_load_n)
    return force


@njit(cache=True, inline="always")
def flywheel_resistance(p, speed_m_s, vertical_load_n):
    """What resists the flywheel beside the tyre's F_x in its balance m_f·v̇ = −F_x − F_r
    [N]: the drag and the equation's slots. The one definition the plant, the calibration
    and the diagnosis read the flywheel's balance through. Inlined, as is
    :func:`flywheel_bearing_force`: as one more call inside the plant's RK4 step it made a
    stop 9 % slower (10.7 → 11.7 ms, best of 40)."""
    return drag_force(p, speed_m_s) + flywheel_bearing_force(p, speed_m_s, vertical_load_n)


@njit(cache=True)
def flywheel_resistances(p, speed_m_s, vertical_load_n, with_drag):
    """:func:`flywheel_resistance` of each sample of two arrays (n,) [N] (without the drag
    when ``with_drag`` is False: a fit of α_d reads the rest)."""
    out = np.empty(speed_m_s.shape[0])
    for i in range(out.shape[0]):
        out[i] = flywheel_bearing_force(p, speed_m_s[i], vertical_load_n[i])
        if with_drag:
            out[i] += drag_force(p, speed_m_s[i])
    return out


@njit(cache=True)
def wheel_extra_torque(p, wheel_speed_rad_s):
    """The wheel equation's generic slot: T₀ sgn ω + T₁ ω, a torque opposing the rotation
    beside the brake's (0 on the reference rig; floats or arrays). A locked wheel (ω = 0)
    feels none: the lock holds it."""
    return p[WHEEL_EXTRA_0] * np.sign(wheel_speed_rad_s) + p[WHEEL_EXTRA_1] * wheel_speed_rad_s


@njit(cache=True)
def wheel_slot_torque(p, signals):
    """The wheel equation's generic slot (``model.basis``): Σ c_k φ_k [N m] opposing the
    rotation beside the brake's, at ``signals`` (ω, v, P, F_z, λ, E_b, θ, 0; 0 on the
    reference rig)."""
    return basis.slot_value(p, WHEEL_SLOT, signals)


@njit(cache=True)
def wheel_acceleration(p, wheel_speed_rad_s, radius_m, tyre_force_n, brake_torque_n_m,
                       extra_torque_n_m):
    """ω̇ from eq. (7) with the torque of the wheel's slots (``extra_torque_n_m``:
    :func:`wheel_extra_torque` and :func:`wheel_slot_torque`), and lock: a stopped wheel
    stays stopped while the brake holds it."""
    net = radius_m * tyre_force_n - brake_torque_n_m - extra_torque_n_m
    if wheel_speed_rad_s <= 0.0 and net <= 0.0:
        return 0.0
    return net / p[WHEEL_INERTIA]


@njit(cache=True)
def gear_walk_torque(p, angle_rad, rate_rad_s):
    """Spring-damper torque c_θ θ̇ + k_θ θ of the gear-walk element, eq. (6)."""
    return p[GW_DAMPING] * rate_rad_s + p[GW_STIFFNESS] * angle_rad


@njit(cache=True)
def aircraft_coupling(p):
    """J_θ = L_gw (m_gw/2 + m_w), the gear-walk/aircraft coupling of eqs. (5)-(6)."""
    return p[GW_LENGTH] * (0.5 * p[AC_GEAR_MASS] + p[AC_WHEEL_MASS])


@njit(cache=True)
def translational_mass(p):
    """Mass whose speed is v_f (rig: J_f/R_f²) or v_a (aircraft: m_a + m_w + m_gw)."""
    if p[CONFIGURATION] == 0.0:
        return p[FLY_INERTIA] / (p[FLY_RADIUS] * p[FLY_RADIUS])
    return p[AC_MASS] + p[AC_WHEEL_MASS] + p[AC_GEAR_MASS]


@njit(cache=True, inline="always")
def valve_excess(current_a, max_current_a, deadband_a):
    """The static map's variable e = I − I0 ≥ 0 [A], I within [0, I_max]."""
    current = np.minimum(np.maximum(current_a, 0.0), max_current_a)
    return np.maximum(current - deadband_a, 0.0)


@njit(cache=True, inline="always")
def valve_map(current_a, max_current_a, deadband_a, k1_pa_per_a, k2_pa_per_a2, k3_pa_per_a3,
              max_pressure_pa, extra_pa=0.0):
    """Static current→pressure map P = k1 e + k2 e² + k3 e³ + the map's slot ``extra_pa``
    (:func:`valve_excess`), dead-band I0, saturation P_max [Pa]; k3 is the map's named
    term (0 on the reference rig)."""
    excess = valve_excess(current_a, max_current_a, deadband_a)
    pressure = (k1_pa_per_a * excess + k2_pa_per_a2 * excess * excess
                + k3_pa_per_a3 * excess * excess * excess) + extra_pa
    return np.minimum(np.maximum(pressure, 0.0), max_pressure_pa)


@njit(cache=True)
def map_slot(p, current_a):
    """The static map's generic slot [Pa] at ``current_a`` [A]: Σ c_k φ_k(e), e = I − I0
    (a call, not inlined, because the step only pays for it when a term is set)."""
    excess = valve_excess(current_a, p[MAX_CURRENT], p[DEADBAND])
    return basis.slot_value(p, MAP_SLOT, (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
                                          0.0, 0.0, excess))


@njit(cache=True)
def valve_static_pressure(p, current_a):
    """The valve's static-map pressure [Pa] of the parameter set at ``current_a`` [A] (a
    float)."""
    extra = map_slot(p, current_a) if basis.slot_acts(p, MAP_SLOT) else 0.0
    return valve_map(current_a, p[MAX_CURRENT], p[DEADBAND], p[MAP_K1], p[MAP_K2],
                     p[MAP_EXTRA_3], p[MAX_PRESSURE], extra)


@njit(cache=True)
def load_lift(p, speed_m_s):
    """What the speed takes off the loading device's set point: k_L v² and the loading
    equation's generic slot c v [N] (floats or arrays)."""
    return p[LIFT] * speed_m_s * speed_m_s + p[LOAD_EXTRA_1] * speed_m_s


@njit(cache=True)
def vertical_load_reference(p, time_s, speed_m_s):
    """Loading-device reference F_z0 − :func:`load_lift`, ramped in over the touch-down
    ramp."""
    elapsed = time_s - p[TOUCHDOWN_T]
    if elapsed < 0.0:
        return 0.0
    ramp = p[TOUCHDOWN_RAMP]
    scale = 1.0 if ramp <= 0.0 or elapsed >= ramp else elapsed / ramp
    return scale * max(p[LOAD_STATIC] - load_taken(p, speed_m_s, elapsed), 0.0)


@njit(cache=True)
def load_taken(p, speed_m_s, contact_time_s):
    """What the loading device's set point F_z0 loses at speed ``speed_m_s`` and
    ``contact_time_s`` after touch-down [N]: :func:`load_lift` and the generic slot. The one
    definition the plant, the calibration and the diagnosis read the loading law through."""
    return load_lift(p, speed_m_s) + loading_slot(p, speed_m_s, contact_time_s)


@njit(cache=True)
def loads_taken(p, speed_m_s, contact_time_s):
    """:func:`load_taken` of each sample of two arrays (n,) [N]."""
    out = np.empty(speed_m_s.shape[0])
    for i in range(out.shape[0]):
        out[i] = load_taken(p, speed_m_s[i], contact_time_s[i])
    return out


@njit(cache=True)
def loading_slot(p, speed_m_s, contact_time_s):
    """The loading equation's generic slot (``model.basis``): Σ c_k φ_k(v, t_c) [N] taken
    off the set point, t_c the time since touch-down (0 on the reference rig)."""
    if not basis.slot_acts(p, LOADING_SLOT):
        return 0.0
    return basis.slot_value(p, LOADING_SLOT, (0.0, speed_m_s, 0.0, 0.0, 0.0, 0.0, 0.0,
                                              contact_time_s, 0.0, 0.0, 0.0, 0.0, 0.0))
