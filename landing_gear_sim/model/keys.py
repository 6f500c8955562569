"""Every parameter key of the schema as a constant (``K.BRAKE_GAIN_N_M_PER_PA`` for
``"brake.gain_n_m_per_pa"``), in the schema's order: a key mistyped in code is an import
error and a mypy error, not a ``ParameterError`` on the one path that reads it.

Plain ``str`` constants, so they serialise (YAML, JSON) as the keys themselves. The module
follows :data:`landing_gear_sim.model.parameters.SPECS`, and a test checks it does: same keys,
same order, and the order only appended to (the compiled physics caches its indices).
"""

from __future__ import annotations

from typing import Final

CONFIGURATION: Final = "configuration"
ELEMENTS_GEAR_WALK: Final = "elements.gear_walk"
ELEMENTS_LOAD_DEPENDENT_RADIUS: Final = "elements.load_dependent_radius"
ELEMENTS_ACTUATOR_DYNAMICS: Final = "elements.actuator_dynamics"
ELEMENTS_DRAG: Final = "elements.drag"
ELEMENTS_ACTUATOR_DELAY: Final = "elements.actuator_delay"
ELEMENTS_PRESSURE_SENSOR_OFFSET: Final = "elements.pressure_sensor_offset"
ELEMENTS_TIRE_RELAXATION: Final = "elements.tire_relaxation"
ELEMENTS_BRAKE_FADE: Final = "elements.brake_fade"
FLYWHEEL_RADIUS_M: Final = "flywheel.radius_m"
FLYWHEEL_INERTIA_KG_M2: Final = "flywheel.inertia_kg_m2"
DRAG_COEFF_N_S2_PER_M2: Final = "drag.coeff_n_s2_per_m2"
WHEEL_UNLOADED_RADIUS_M: Final = "wheel.unloaded_radius_m"
WHEEL_INERTIA_KG_M2: Final = "wheel.inertia_kg_m2"
RADIUS_A_M_PER_N2: Final = "radius.a_m_per_n2"
RADIUS_B_M_PER_N: Final = "radius.b_m_per_n"
RADIUS_C_M: Final = "radius.c_m"
FRICTION_THETA1: Final = "friction.theta1"
FRICTION_THETA2: Final = "friction.theta2"
FRICTION_THETA3: Final = "friction.theta3"
GEAR_WALK_LENGTH_M: Final = "gear_walk.length_m"
GEAR_WALK_INERTIA_KG_M2: Final = "gear_walk.inertia_kg_m2"
GEAR_WALK_STIFFNESS_N_M_PER_RAD: Final = "gear_walk.stiffness_n_m_per_rad"
GEAR_WALK_DAMPING_N_M_S_PER_RAD: Final = "gear_walk.damping_n_m_s_per_rad"
AIRCRAFT_MASS_KG: Final = "aircraft.mass_kg"
AIRCRAFT_WHEEL_MASS_KG: Final = "aircraft.wheel_mass_kg"
AIRCRAFT_GEAR_MASS_KG: Final = "aircraft.gear_mass_kg"
BRAKE_GAIN_N_M_PER_PA: Final = "brake.gain_n_m_per_pa"
BRAKE_FADE_FRACTION: Final = "brake.fade_fraction"
BRAKE_FADE_ENERGY_J: Final = "brake.fade_energy_j"
TYRE_RELAXATION_LENGTH_M: Final = "tyre.relaxation_length_m"
ACTUATOR_MAX_CURRENT_A: Final = "actuator.max_current_a"
ACTUATOR_DEADBAND_CURRENT_A: Final = "actuator.deadband_current_a"
ACTUATOR_MAP_K1_PA_PER_A: Final = "actuator.map_k1_pa_per_a"
ACTUATOR_MAP_K2_PA_PER_A2: Final = "actuator.map_k2_pa_per_a2"
ACTUATOR_MAX_PRESSURE_PA: Final = "actuator.max_pressure_pa"
ACTUATOR_GAIN: Final = "actuator.gain"
ACTUATOR_NATURAL_FREQUENCY_HZ: Final = "actuator.natural_frequency_hz"
ACTUATOR_DAMPING_RATIO: Final = "actuator.damping_ratio"
ACTUATOR_DELAY_S: Final = "actuator.delay_s"
LOADING_STATIC_LOAD_N: Final = "loading.static_load_n"
LOADING_LIFT_COEFF_N_S2_PER_M2: Final = "loading.lift_coeff_n_s2_per_m2"
LOADING_SERVO_TIME_CONSTANT_S: Final = "loading.servo_time_constant_s"
LOADING_TOUCHDOWN_RAMP_S: Final = "loading.touchdown_ramp_s"
RIG_TEST_INITIAL_SPEED_M_S: Final = "rig_test.initial_speed_m_s"
RIG_TEST_TOUCHDOWN_S: Final = "rig_test.touchdown_s"
RIG_TEST_BRAKE_START_S: Final = "rig_test.brake_start_s"
RIG_TEST_BRAKE_RAMP_S: Final = "rig_test.brake_ramp_s"
RIG_TEST_STOP_SPEED_M_S: Final = "rig_test.stop_speed_m_s"
RIG_TEST_MAX_DURATION_S: Final = "rig_test.max_duration_s"
SENSORS_PRESSURE_NOISE_PA: Final = "sensors.pressure_noise_pa"
SENSORS_SPEED_NOISE_RAD_S: Final = "sensors.speed_noise_rad_s"
SENSORS_FORCE_NOISE_N: Final = "sensors.force_noise_n"
SENSORS_PRESSURE_OFFSET_PA: Final = "sensors.pressure_offset_pa"
SIMULATION_OUTPUT_RATE_HZ: Final = "simulation.output_rate_hz"
BRAKE_GAIN_SLOPE_WHEEL_SPEED_S_PER_RAD: Final = "brake.gain_slope_wheel_speed_s_per_rad"
BRAKE_GAIN_SLOPE_PRESSURE_PER_PA: Final = "brake.gain_slope_pressure_per_pa"
SENSORS_CROSSTALK_FX_PER_FZ: Final = "sensors.crosstalk_fx_per_fz"
SENSORS_WHEEL_SPEED_DELAY_S: Final = "sensors.wheel_speed_delay_s"
FRICTION_CHANGE_SPEED_M_S: Final = "friction.change_speed_m_s"
FRICTION_AFTER_THETA1: Final = "friction.after_theta1"
FRICTION_AFTER_THETA2: Final = "friction.after_theta2"
FRICTION_AFTER_THETA3: Final = "friction.after_theta3"
ACTUATOR_BACKLASH_A: Final = "actuator.backlash_a"
BRAKE_GAIN_DRIFT_PER_RUN: Final = "brake.gain_drift_per_run"
FRICTION_LOAD_SENSITIVITY_PER_N: Final = "friction.load_sensitivity_per_n"
FRICTION_REFERENCE_LOAD_N: Final = "friction.reference_load_n"
SENSORS_WHEEL_RUNOUT_1: Final = "sensors.wheel_runout_1"
SENSORS_WHEEL_RUNOUT_1_PHASE_RAD: Final = "sensors.wheel_runout_1_phase_rad"
SENSORS_WHEEL_RUNOUT_2: Final = "sensors.wheel_runout_2"
SENSORS_WHEEL_RUNOUT_2_PHASE_RAD: Final = "sensors.wheel_runout_2_phase_rad"
BRAKE_FADE_SHAPE: Final = "brake.fade_shape"
SENSORS_PRESSURE_DELAY_S: Final = "sensors.pressure_delay_s"
BRAKE_RUNOUT_1: Final = "brake.runout_1"
BRAKE_RUNOUT_1_PHASE_RAD: Final = "brake.runout_1_phase_rad"
BRAKE_RUNOUT_2: Final = "brake.runout_2"
BRAKE_RUNOUT_2_PHASE_RAD: Final = "brake.runout_2_phase_rad"
WHEEL_EXTRA_TORQUE_N_M: Final = "wheel.extra_torque_n_m"
WHEEL_EXTRA_TORQUE_N_M_S_PER_RAD: Final = "wheel.extra_torque_n_m_s_per_rad"
FLYWHEEL_EXTRA_FORCE_N: Final = "flywheel.extra_force_n"
FLYWHEEL_EXTRA_FORCE_N_S_PER_M: Final = "flywheel.extra_force_n_s_per_m"
LOADING_EXTRA_LOAD_N_S_PER_M: Final = "loading.extra_load_n_s_per_m"
ACTUATOR_EXTRA_MAP_PA_PER_A3: Final = "actuator.extra_map_pa_per_a3"


def _slot_terms(section: str, term: str = "term") -> tuple[tuple[str, str], ...]:
    """An equation's generic slot (``model.basis``): its (code, coefficient) keys."""
    return tuple((f"{section}.{term}_{k}_code", f"{section}.{term}_{k}_coeff")
                 for k in (1, 2, 3))


WHEEL_TERMS: Final = _slot_terms("wheel")
TYRE_TERMS: Final = _slot_terms("friction")
LOADING_TERMS: Final = _slot_terms("loading")
FX_TERMS: Final = _slot_terms("sensors", "fx_term")
VALVE_TERMS: Final = _slot_terms("actuator")
FLYWHEEL_TERMS: Final = _slot_terms("flywheel")
MAP_TERMS: Final = _slot_terms("actuator", "map_term")
PRESSURE_TERMS: Final = _slot_terms("sensors", "p_term")
