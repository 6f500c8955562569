"""The rig plant composed from its elements, and the step functions of the plant and
the loading device (the actuator's are in :mod:`landing_gear_sim.model.actuator`).

Three blocks exchange values once per output step ``h`` (the same cut as the
ROS graph: actuator node, loading-device node, plant node):

* actuator: valve current I_k (held over the step) → brake pressure at t_{k+1};
* loading device: flywheel speed at t_k → vertical load at t_{k+1};
* plant: wheel, tyre, gear walk, flywheel/aircraft, advanced from t_k to t_{k+1}
  with pressure and load interpolated linearly between the exchanged values.

The actuator and the load servo are linear between exchanges and are stepped
exactly (matrix exponential). The plant is sub-stepped with classical RK4; the
substep is chosen from the wheel/tyre stiffness r² F_z μ'/(J_w v_h), which grows
as speed falls, so the loop stays stable down to the stop speed. The wheel
never spins backwards: a wheel that reaches ω = 0 is clamped there and stays
locked while the brake torque exceeds the tyre torque.

Plant state vector (``N_STATES``): speed v (flywheel rim or aircraft) [m/s],
gear-walk angle θ [rad] and rate [rad/s], wheel speed ω [rad/s], and four energy
accumulators [J] (brake, drag with the bearings, tyre slip, gear-walk damping) for bookkeeping, the
relaxed tyre force [N] (used by the ``tire_relaxation`` element only) and the wheel's angle
since the run's start [rad] (a disc's run-out acts at it; a simulation of a measured run
sets it to the measured angle at each exchange step).
"""

from __future__ import annotations

import math

from numba import njit

from landing_gear_sim.model import basis
from landing_gear_sim.model import elements as el

(SPEED, ANGLE, ANGLE_RATE, OMEGA, E_BRAKE, E_DRAG, E_SLIP, E_DAMP, TYRE_FORCE,
 WHEEL_ANGLE) = range(10)
N_STATES = 10

MAX_SUBSTEP_S = 1e-3  # physics runs at 1 kHz or finer whatever the exchange rate
# h·|λ_max| per substep; RK4's real-axis limit is 2.78 (1.0 cost a third more substeps in a
# stop for a force 1e-6 of its range closer: λ_max is the curve's stiffest slope, not today's)
STABILITY_MARGIN = 2.0

CHANNELS: tuple[str, ...] = (
    "time_s", "current_a", "pressure_pa", "wheel_speed_rad_s", "speed_m_s",
    "hub_speed_m_s", "vertical_load_n", "longitudinal_force_n", "slip",
    "wheel_decel_g", "rolling_radius_m", "gear_angle_rad", "gear_rate_rad_s",
    "brake_torque_n_m", "brake_energy_j", "drag_energy_j", "slip_energy_j",
    "damping_energy_j",
)
"""Columns of a simulation record, in order (SI; slip and η dimensionless)."""
N_CHANNELS = len(CHANNELS)


@njit(cache=True)
def tyre_state(p, x, vertical_load_n):
    """Radius [m], hub speed [m/s], slip [-] and tyre force F_x [N] at state ``x``.

    F_x is F_z μ(λ, F_z), or the relaxed force state when ``tire_relaxation`` is on.
    """
    radius = el.rolling_radius(p, vertical_load_n)
    hub = x[SPEED] - p[el.GW_LENGTH] * x[ANGLE_RATE] if p[el.HAS_GEAR_WALK] else x[SPEED]
    slip = el.slip_ratio(hub, x[OMEGA], radius)
    if p[el.HAS_RELAXATION]:
        force = x[TYRE_FORCE]
    else:
        force = vertical_load_n * el.tyre_friction(p, slip, x[SPEED], vertical_load_n)
    return radius, hub, slip, force


@njit(cache=True, inline="always")
def wheel_extra(p, x, pressure_pa, vertical_load_n, slip):
    """The torque of the wheel equation's slots at state ``x`` [N m]."""
    if not basis.slot_acts(p, el.WHEEL_SLOT):
        return el.wheel_extra_torque(p, x[OMEGA])
    signals = (x[OMEGA], x[SPEED], pressure_pa, vertical_load_n, abs(slip), x[E_BRAKE],
               x[WHEEL_ANGLE], 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    return el.wheel_extra_torque(p, x[OMEGA]) + el.wheel_slot_torque(p, signals)


@njit(cache=True)
def derivatives(p, x, pressure_pa, vertical_load_n, dx):
    """Write dx/dt of the plant state into ``dx`` (eqs. 1-8; rig or aircraft form)."""
    radius, hub, slip, fx = tyre_state(p, x, vertical_load_n)
    tb = el.brake_torque(p, pressure_pa, x[E_BRAKE], x[OMEGA], x[WHEEL_ANGLE])
    drag = el.flywheel_resistance(p, x[SPEED], vertical_load_n)
    mass = el.translational_mass(p)
    if p[el.HAS_GEAR_WALK] == 0.0:
        accel, angle_accel = (-fx - drag) / mass, 0.0
    else:
        moment = p[el.GW_LENGTH] * fx - el.gear_walk_torque(p, x[ANGLE], x[ANGLE_RATE])
        inertia = p[el.GW_INERTIA]
        if p[el.CONFIGURATION] == 0.0:  # rig: gear base fixed to the sledge
            accel, angle_accel = (-fx - drag) / mass, moment / inertia
        else:  # aircraft: eqs. (5)-(6) coupled through J_θ
            coupling = el.aircraft_coupling(p)
            det = mass * inertia - coupling * coupling
            accel = ((-fx - drag) * inertia + coupling * moment) / det
            angle_accel = (mass * moment + coupling * (-fx - drag)) / det
    dx[SPEED] = accel
    dx[ANGLE] = x[ANGLE_RATE]
    dx[ANGLE_RATE] = angle_accel
    extra = wheel_extra(p, x, pressure_pa, vertical_load_n, slip)
    dx[OMEGA] = el.wheel_acceleration(p, x[OMEGA], radius, fx, tb, extra)
    dx[E_BRAKE] = tb * max(x[OMEGA], 0.0)
    # the bearings' losses are drag's: they leave the flywheel and the wheel as heat
    dx[E_DRAG] = drag * x[SPEED] + extra * x[OMEGA]
    dx[E_SLIP] = fx * (hub - x[OMEGA] * radius)
    dx[E_DAMP] = p[el.GW_DAMPING] * x[ANGLE_RATE] ** 2 if p[el.HAS_GEAR_WALK] else 0.0
    if p[el.HAS_RELAXATION]:
        steady = vertical_load_n * el.tyre_friction(p, slip, x[SPEED], vertical_load_n)
        dx[TYRE_FORCE] = el.relaxation_rate(p, hub) * (steady - x[TYRE_FORCE])
    else:  # the force is the steady one (tyre_state's): evaluating μ again cost ~20 %
        dx[TYRE_FORCE] = 0.0
    dx[WHEEL_ANGLE] = x[OMEGA]


@njit(cache=True)
def substep_count(p, x, step_s, max_load_n):
    """Substeps for one exchange step: ≤ MAX_SUBSTEP_S and stable for the stiffest mode."""
    hub = max(x[SPEED] - p[el.GW_LENGTH] * x[ANGLE_RATE], el.MIN_HUB_SPEED_M_S)
    radius = el.rolling_radius(p, max_load_n)
    compliance = radius * radius / p[el.WHEEL_INERTIA] + 1.0 / el.translational_mass(p)
    if p[el.HAS_GEAR_WALK]:
        compliance += p[el.GW_LENGTH] ** 2 / p[el.GW_INERTIA]
    rate = max(max_load_n * el.burckhardt_slope_max(p, max_load_n) * compliance / hub,
               el.relaxation_rate(p, hub))
    n_stiff = math.ceil(step_s * rate / STABILITY_MARGIN)
    n_max = math.ceil(step_s / MAX_SUBSTEP_S - 1e-9)
    return max(n_stiff, n_max, 1)


@njit(cache=True)
def plant_step(p, x, pressure0, pressure1, load0, load1, step_s, work):
    """Advance ``x`` in place over one exchange step ``step_s``.

    Pressure [Pa] and vertical load [N] go linearly from their values at the
    start (``*0``) to those at the end (``*1``). ``work`` is scratch, shape (5, N_STATES).
    """
    n = substep_count(p, x, step_s, max(load0, load1))
    h = step_s / n
    k1, k2, k3, k4, xs = work[0], work[1], work[2], work[3], work[4]
    dp, dl = (pressure1 - pressure0) / n, (load1 - load0) / n
    for i in range(n):
        pa, la = pressure0 + i * dp, load0 + i * dl
        pm, lm = pa + 0.5 * dp, la + 0.5 * dl
        derivatives(p, x, pa, la, k1)
        for j in range(N_STATES):
            xs[j] = x[j] + 0.5 * h * k1[j]
        derivatives(p, xs, pm, lm, k2)
        for j in range(N_STATES):
            xs[j] = x[j] + 0.5 * h * k2[j]
        derivatives(p, xs, pm, lm, k3)
        for j in range(N_STATES):
            xs[j] = x[j] + h * k3[j]
        derivatives(p, xs, pa + dp, la + dl, k4)
        for j in range(N_STATES):
            x[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])
        if x[OMEGA] < 0.0:  # the wheel locks; it never turns backwards
            x[OMEGA] = 0.0


@njit(cache=True)
def loading_step(p, xl, time_s, speed_m_s, step_s):
    """Advance the loading-device servo ``xl`` (1,) over one step; return F_z [N].

    The reference ramps linearly over the step (touch-down ramp) at the speed of
    the step start; the first-order servo is stepped exactly for that input.
    """
    start = el.vertical_load_reference(p, time_s, speed_m_s)
    end = el.vertical_load_reference(p, time_s + step_s, speed_m_s)
    tau = p[el.LOAD_TAU]
    decay = math.exp(-step_s / tau)
    xl[0] = end + decay * (xl[0] - start) - (end - start) * tau / step_s * (1.0 - decay)
    return xl[0]


@njit(cache=True)
def record(p, x, time_s, current_a, pressure_pa, load_n, row):
    """Fill one output row (see CHANNELS) from the state at ``time_s``."""
    radius, hub, slip, fx = tyre_state(p, x, load_n)
    tb = el.brake_torque(p, pressure_pa, x[E_BRAKE], x[OMEGA], x[WHEEL_ANGLE])
    omega_dot = el.wheel_acceleration(p, x[OMEGA], radius, fx, tb,
                                      wheel_extra(p, x, pressure_pa, load_n, slip))
    row[0], row[1], row[2] = time_s, current_a, pressure_pa
    row[3], row[4], row[5] = x[OMEGA], x[SPEED], hub
    row[6], row[7], row[8] = load_n, fx, slip
    row[9], row[10] = -omega_dot * radius / el.GRAVITY_M_S2, radius
    row[11], row[12], row[13] = x[ANGLE], x[ANGLE_RATE], tb
    row[14], row[15], row[16], row[17] = x[E_BRAKE], x[E_DRAG], x[E_SLIP], x[E_DAMP]
