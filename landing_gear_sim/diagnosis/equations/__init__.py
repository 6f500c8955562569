"""The rig's equations, one module each: everything the diagnosis knows about an equation —
its law, its error from measured signals, the relations that check it, its library of terms
and its slot — is in that equation's module.

- :mod:`.valve`: the static map and A(s);
- :mod:`.wheel`: the wheel's torque balance and the brake's gain law;
- :mod:`.tyre`: the tyre's force law, on the curve and at lock;
- :mod:`.flywheel`: the flywheel's momentum balance;
- :mod:`.loading`: the loading device's set point;
- :mod:`.fx_channel`, :mod:`.pressure_channel`, :mod:`.wheel_channel`, :mod:`.load_cell`:
  what each channel reads of its quantity;
- :mod:`.equation`: what an equation is and declares; :mod:`.registry`: the equations
  gathered; :mod:`.placing`: which equation a residual structure lives in.

The physics itself is the model's (:mod:`landing_gear_sim.model`): an equation's module reads
its balance through the model's compiled law and the calibration's reading of it from
measured signals, and never writes it again.
"""

from landing_gear_sim.diagnosis.equations.equation import Declared, Equation

__all__ = ["Declared", "Equation"]
