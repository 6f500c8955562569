"""What a braking run achieved, from any run (simulated or measured).

The peak available friction comes from the rig's friction curve (the model's, calibrated
for a measured run); everything else from the run's signals.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import asdict, dataclass

import numpy as np

from landing_gear_sim.errors import LandingGearSimError
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.elements import slip_ratio
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import (
    friction_at,
    gear_walk_modes,
    load_factor_at,
    logged_or_set_load_n,
    peak_friction,
    rim_speed_m_s,
    rolling_radius_at,
)
from landing_gear_sim.model.scenario import BRAKE_ON_CURRENT_A, brake_start_index
from msg_tools.checks import MIN_BRAKING_SAMPLES, too_short
from msg_tools.run import Run
from msg_tools.units import PA_PER_BAR

LOCK_SLIP = 0.95  # a wheel at 95 % slip or more is locked
LOCK_MIN_SPEED_M_S = 5.0  # locks below this speed are the stop itself, not a skid
LOCK_FRICTION_SHARE = 0.25  # a lock's μ this far from the curve's μ(1) is no sliding tyre
MIN_LOAD_N = 1000.0  # below this the wheel is not on the flywheel: no friction to speak of
CYCLE_PROMINENCE_PA = 2 * PA_PER_BAR  # a pressure cycle is a peak standing 2 bar above its valleys
GEAR_WALK_BAND = 0.3  # cycling within ±30 % of the gear-walk frequency is flagged
# the brake off this long ends a stop: an anti-skid release lasts tens of milliseconds, the
# rig takes seconds to spin the flywheel up again (2 s of free rolling before each stop)
STOP_GAP_S = 1.0


@dataclass(frozen=True)
class BrakingMetrics:
    """Stopping performance of one run, SI."""

    stopping_distance_m: float
    stopping_time_s: float
    mean_deceleration_m_s2: float
    braking_efficiency: float
    mean_friction: float
    peak_friction: float
    slip_rms: float
    slip_max: float
    lock_events: int
    lock_duration_s: float
    cycling_frequency_hz: float
    gear_walk_frequency_hz: float
    cycling_near_gear_walk: bool

    def to_dict(self) -> dict[str, float | int | bool | None]:
        """The metrics, what the log could not give (no load cells: friction) as None."""
        return {k: None if isinstance(v, float) and math.isnan(v) else v
                for k, v in asdict(self).items()}


def braking_window(run: Run) -> slice:
    """From the first brake command (scenario.brake_start_index) to the end of the run."""
    if (short := too_short(run, "a stop's metrics")) is not None:
        raise LandingGearSimError(short)
    start = brake_start_index(run.current_a, run.rate_hz)
    lacking = run.lacks("flywheel_speed_rad_s")
    if lacking:
        raise LandingGearSimError(f"{run.name}: {lacking[0]} not logged: the stop's speed, "
                                  "slip and distance need the flywheel's (the vehicle's) speed")
    # without a load cell the wheel's contact shows as the flywheel turning
    touching = (float(np.max(run.vertical_load_n)) >= MIN_LOAD_N if not run.lacks(
        "vertical_load_n") else float(np.max(np.abs(run.flywheel_speed_rad_s))) > 0.0)
    if start is None or not touching:
        raise LandingGearSimError(f"{run.name}: not a braking run (no current, or the wheel "
                                  "never touches the flywheel)")
    return slice(start, len(run))


def stops(run: Run) -> list[Run]:
    """The stops of a log, each from the end of the one before (its free rolling included)
    to its brake's last command; the last to the end of the log. A rig test is one stop,
    itself; a day's log of many is its stops (one hour of 227 stops was measured as one of
    3598 s)."""
    on = np.flatnonzero(run.current_a > BRAKE_ON_CURRENT_A)
    # a brake released between them: samples logged off (a log's gap while braking is
    # none: it had split a stop in two)
    apart = (np.diff(run.time_s[on]) > STOP_GAP_S) & (np.diff(on) > 1)
    ends = on[np.flatnonzero(apart)] if on.size else on
    if ends.size == 0:
        return [run]
    bounds = [0, *(int(e) + 1 for e in ends), len(run)]
    return [run.part(slice(a, b), f"{run.name} stop {k}")
            for k, (a, b) in enumerate(itertools.pairwise(bounds), 1)]


def speeds_m_s(run: Run, rig: RigParameters) -> tuple[np.ndarray, np.ndarray]:
    """Flywheel rim (vehicle) speed and wheel peripheral speed at the rolling radius [m/s]."""
    vehicle = rim_speed_m_s(rig, run.flywheel_speed_rad_s)
    load = np.maximum(logged_or_set_load_n(run, rig), 0.0)
    return vehicle, run.wheel_speed_rad_s * rolling_radius_at(rig, load)


def slip_from(vehicle_m_s: np.ndarray, wheel_m_s: np.ndarray) -> np.ndarray:
    """λ of eq. (1) from the vehicle speed and the wheel's peripheral speed [m/s]."""
    return slip_ratio(vehicle_m_s, wheel_m_s, 1.0)


def braking_metrics(run: Run, rig: RigParameters) -> BrakingMetrics:
    """Metrics of the braking phase of ``run`` on the rig ``rig``."""
    window = braking_window(run)
    t = run.time_s[window]
    vehicle, wheel = speeds_m_s(run, rig)
    speed = vehicle[window]
    load = logged_or_set_load_n(run, rig)[window]
    slip = slip_from(vehicle, wheel)[window]
    loaded = load > MIN_LOAD_N
    # without load cells no friction is measured: NaN, 'not logged' in tables and JSON
    friction = run.longitudinal_force_n[window][loaded] / load[loaded] if not run.lacks(
        "vertical_load_n", "longitudinal_force_n") else np.full(1, np.nan)
    peak, _ = peak_friction(rig)
    moving = speed > LOCK_MIN_SPEED_M_S
    locked = (slip >= LOCK_SLIP) & moving
    duration = float(t[-1] - t[0])
    cycles = _cycling_frequency(run.pressure_pa[window], duration)
    gear_walk, _ = gear_walk_modes(rig)
    return BrakingMetrics(
        stopping_distance_m=_trapezoid(speed, t),
        stopping_time_s=duration,
        mean_deceleration_m_s2=float(speed[0] - speed[-1]) / max(duration, 1e-9),
        braking_efficiency=_efficiency(rig, friction, speed[loaded], load[loaded], peak)
        if np.isfinite(friction).all() else math.nan,
        mean_friction=float(np.mean(friction)),
        peak_friction=peak,
        slip_rms=float(np.sqrt(np.mean(slip[moving] ** 2))) if moving.any() else 0.0,
        slip_max=float(np.max(slip[moving])) if moving.any() else 0.0,
        lock_events=int(np.count_nonzero(np.diff(locked.astype(int)) == 1) + int(locked[0])),
        lock_duration_s=float(np.count_nonzero(locked)) / run.rate_hz,
        cycling_frequency_hz=cycles,
        gear_walk_frequency_hz=gear_walk,
        cycling_near_gear_walk=cycles > 0 and abs(cycles - gear_walk) <= GEAR_WALK_BAND * gear_walk,
    )


UNFINISHED_SHARE = 0.25  # a log ending above this share of the braking speed cut its stop


def unfinished(run: Run, rig: RigParameters) -> str | None:
    """What a stop whose log ends before the stop does is (None: it ended): above a quarter
    of the speed it braked from and twice the rig's stop speed (a stop cut at half its
    speed had been reported as a stop of 236 m in 4.9 s)."""
    vehicle, _ = speeds_m_s(run, rig)
    start, end = float(vehicle[braking_window(run)][0]), float(vehicle[-1])
    if end <= max(UNFINISHED_SHARE * start, 2.0 * rig.number(K.RIG_TEST_STOP_SPEED_M_S)):
        return None
    return (f"{run.name}: the log ends at {end:.3g} m/s, braking from {start:.3g} m/s: the "
            "stop never ended; its distance, time and deceleration are of the part logged")


def unconfirmed_locks(run: Run, rig: RigParameters) -> str | None:
    """What says that the run's locks are not confirmed by the force (None: no lock, or the
    force confirms it): a locked tyre slides, pulling μ = F_x/F_z at the curve's μ(λ = 1);
    one that still grips at low slip pulls far less, and a wheel channel that stopped
    reads 0 all the same (a stuck encoder had read as 9.5 s locked)."""
    if run.lacks("vertical_load_n", "longitudinal_force_n"):
        return None
    window = braking_window(run)
    vehicle, wheel = speeds_m_s(run, rig)
    slip = slip_from(vehicle[window], wheel[window])
    load = run.vertical_load_n[window]
    locked = (slip >= LOCK_SLIP) & (vehicle[window] > LOCK_MIN_SPEED_M_S) & (load > MIN_LOAD_N)
    if np.count_nonzero(locked) < MIN_BRAKING_SAMPLES:
        return None
    pulled = float(np.median(run.longitudinal_force_n[window][locked] / load[locked]))
    sliding = float(friction_at(rig, np.ones(1))[0])
    if abs(pulled / sliding - 1.0) <= LOCK_FRICTION_SHARE:
        return None
    duration = np.count_nonzero(locked) / run.rate_hz
    return (f"{run.name}: {duration:.3g} s read as locked is unconfirmed: the tyre pulls "
            f"μ {pulled:.3g} there, not the {sliding:.3g} of a sliding tyre (the curve's "
            "μ(λ = 1)); wheel_speed_rad_s may have stopped reading (an encoder stuck at 0)")


def _efficiency(rig: RigParameters, friction: np.ndarray, speed_m_s: np.ndarray,
                load_n: np.ndarray, peak: float) -> float:
    """Mean friction used over the friction available, sample by sample: the peak at the
    sample's load (a tyre's load sensitivity) and, on a runway whose surface changes below
    ``friction.change_speed_m_s`` (a μ-jump), of the surface under the tyre."""
    available = peak * load_factor_at(rig, load_n)
    change = rig.number(K.FRICTION_CHANGE_SPEED_M_S)
    if change > 0.0:
        after, _ = peak_friction(rig.replace({f"friction.theta{i}": rig.number(
            f"friction.after_theta{i}") for i in (1, 2, 3)}, "the surface after the change"))
        available = np.where(speed_m_s < change, available * after / peak, available)
    return float(np.mean(friction / available))


def _trapezoid(y: np.ndarray, t: np.ndarray) -> float:
    """The trapezoid integral of ``y`` over ``t`` (numpy's own is numpy ≥ 2 only, and
    scipy.integrate's import cost ``metrics`` 0.7 s of its start)."""
    return float(np.sum(np.diff(t) * (y[1:] + y[:-1])) / 2.0)


def _cycling_frequency(pressure_pa: np.ndarray, duration_s: float) -> float:
    """Release cycles per second: pressure peaks standing out by CYCLE_PROMINENCE_PA."""
    cycles = release_cycles(pressure_pa, CYCLE_PROMINENCE_PA)
    return cycles / duration_s if duration_s > 0 and cycles >= 2 else 0.0


def release_cycles(pressure_pa: np.ndarray, prominence_pa: float) -> int:
    """The peaks of ``pressure_pa`` that stand out by ``prominence_pa`` on both sides: the
    peaks of that prominence scipy.signal.find_peaks gives (its import was 0.9 s of the
    ``metrics`` command's start), in one pass. A peak counts once the pressure has risen to
    it by ``prominence_pa`` from its lowest since the last peak, and fallen from it by as
    much; between two such falls only the highest samples are peaks of that prominence,
    each of their separate visits one (scipy's rule for a tie: two equal counts of a
    quantised log, a shallower dip between them, are two peaks)."""
    cycles, risen = 0, False
    low = high = math.inf
    visits, dipped = 0, False
    for value in pressure_pa.tolist():
        if not risen:
            low = min(low, value)
            risen, high, visits, dipped = value - low >= prominence_pa, value, 1, False
        elif value > high:
            high, visits, dipped = value, 1, False
        elif high - value >= prominence_pa:
            cycles, risen, low = cycles + visits, False, value
        elif value < high:
            dipped = True
        elif dipped:  # the highest level reached again after a dip: another peak
            visits, dipped = visits + 1, False
    return cycles


def metrics_table(rows: dict[str, BrakingMetrics]) -> str:
    """One line per run: efficiency, friction, stop, slip, locks, cycling."""
    header = (f"{'run':24s} {'eff':>5s} {'μ':>5s} {'stop [m]':>8s} {'stop [s]':>8s} "
              f"{'decel [m/s²]':>12s} {'slip rms':>8s} {'slip max':>8s} {'locks':>5s} "
              f"{'cycling [Hz]':>12s}")
    lines = [header]
    for name, m in rows.items():
        lines.append(f"{name:24s} {shown(m.braking_efficiency, '5.3f')} "
                     f"{shown(m.mean_friction, '5.3f')} "
                     f"{m.stopping_distance_m:8.1f} {m.stopping_time_s:8.2f} "
                     f"{m.mean_deceleration_m_s2:12.2f} {m.slip_rms:8.3f} {m.slip_max:8.3f} "
                     f"{m.lock_events:5d} {m.cycling_frequency_hz:12.2f}")
    return "\n".join(lines)


def efficiency_against_distance(rows: dict[str, BrakingMetrics]) -> str | None:
    """Why one stop uses more of the friction available yet stops longer than another (None
    when the two agree): the efficiency averages over the stop's time, the distance is
    decided where the speed is high (a threshold controller once read 0.865 against 0.814,
    and 323 m against 322, with nothing said)."""
    (first, a), (second, b) = list(rows.items())[:2]
    if (a.braking_efficiency - b.braking_efficiency) * (
            a.stopping_distance_m - b.stopping_distance_m) <= 0:
        return None
    better, worse = (first, second) if a.braking_efficiency > b.braking_efficiency \
        else (second, first)
    return (f"note: {better} uses more of the friction available than {worse} yet stops "
            "longer: the efficiency is averaged over the stop's time, while the distance is "
            "decided at high speed, where a slower first apply costs metres that better grip "
            "later does not win back")


def shown(value: float, spec: str) -> str:
    """``value`` as ``spec``; '-' where the log could not give it (no load cells: friction)."""
    if math.isfinite(value):
        return format(value, spec)
    return "-".rjust(len(format(0.0, spec)))
