# colcon hook (see colcon.pkg): `landing-gear-sim` on PATH in a sourced workspace; only the
# command, not the node executables of lib/landing_gear_sim (plant, profile...)
_colcon_prepend_unique_value PATH "$COLCON_CURRENT_PREFIX/share/landing_gear_sim/bin"
