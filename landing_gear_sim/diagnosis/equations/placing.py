"""Where a residual structure lives (issue 28, "say where").

A simulation's wheel-speed residual carries every equation's error: the valve's, the wheel's
torque balance, the flywheel's momentum balance, the loading device's. Each equation's own
error is computed here from the measured signals under the model (the other equations' terms
measured, not simulated), each through its owner, so a structure found in a simulation's
residual can be traced to the equation that carries it most strongly against its own noise —
an `unexplained` finding names that equation, not a generic wheel-speed lead. No plotting
here.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.runs import ClassifiedRun, braking_window
from landing_gear_sim.diagnosis import residuals as rs
from landing_gear_sim.diagnosis.equations import valve
from landing_gear_sim.diagnosis.equations.equation import Equation
from landing_gear_sim.diagnosis.equations.registry import DECLARED, ERRORS
from landing_gear_sim.diagnosis.findings import Signature, SignatureKind
from landing_gear_sim.model.parameters import RigParameters
from msg_tools.run import Run


@dataclass(frozen=True)
class EquationError:
    """One equation's error over one run's samples that carry it, (m,) in its unit."""

    equation: Equation
    run: str
    error: np.ndarray
    rate_hz: float


def equation_errors(run: ClassifiedRun, params: RigParameters, simulated: Run
                    ) -> list[EquationError]:
    """Each equation's error in ``run`` under ``params`` (``simulated``: the run simulated
    with them), over the samples a residual signature looks at: the whole of an actuator
    run, the braking window of a stop."""
    if not run.braking:
        return [EquationError(Equation.VALVE, run.name, valve.output_error(run, simulated),
                              run.rate_hz)]
    window = braking_window(run, params)
    b = br.prepare(run, params)
    return [EquationError(equation, run.name, error(run, b, params, simulated)[window],
                          run.rate_hz) for equation, error in ERRORS.items()]


@dataclass(frozen=True)
class Place:
    """Where a signature lives: the equation whose error carries it most strongly, and how
    strongly each equation carries it (the signature's own measure: power over the floor,
    |r| over its band)."""

    equation: Equation
    strength: dict[Equation, float]

    def describe(self) -> str:
        others = ", ".join(f"{e}: {s:.1f}" for e, s in self.strength.items()
                           if e is not self.equation)
        return (f"it lives in the {DECLARED[self.equation].law} equation "
                f"({self.strength[self.equation]:.1f}; {others})")


Measure = Callable[[EquationError], float | None]


def locate(signature: Signature, errors: Sequence[EquationError],
           regressors: Callable[[str], dict[str, np.ndarray]] | None = None) -> Place | None:
    """The equation that carries ``signature`` most strongly over the runs it recurs in
    (None when no equation's error shows it, or it is a lag: a channel's timing is the
    channel's own)."""
    measure = _measure(signature, regressors)
    if measure is None:
        return None
    strength: dict[Equation, list[float]] = {}
    for error in errors:
        if error.run in signature.runs:
            value = measure(error)
            if value is not None:
                strength.setdefault(error.equation, []).append(value)
    if not strength:
        return None
    median = {e: float(np.median(v)) for e, v in strength.items()}
    return Place(max(median, key=lambda e: median[e]), median)


def _measure(signature: Signature,
             regressors: Callable[[str], dict[str, np.ndarray]] | None) -> Measure | None:
    if signature.kind is SignatureKind.FREQUENCY:
        return lambda error: _line_strength(error, signature.value)
    if signature.kind is SignatureKind.REGRESSOR and regressors is not None:
        return lambda error: _regressor_strength(error, regressors(error.run),
                                                 signature.regressor)
    return None


def _line_strength(error: EquationError, frequency_hz: float) -> float | None:
    """Power over the noise floor at ``frequency_hz`` (the nearest bin within 0.5 Hz)."""
    if error.error.size < 256:
        return None
    spectrum = rs.spectrum(error.error, error.rate_hz, segment=min(2048, error.error.size))
    near = np.abs(spectrum.frequency_hz - frequency_hz) <= max(0.5, 0.05 * frequency_hz)
    ratio = spectrum.psd[near] / spectrum.floor[near]
    finite = ratio[np.isfinite(ratio)]
    return float(finite.max()) if finite.size else None


def _regressor_strength(error: EquationError, regressors: dict[str, np.ndarray], name: str
                        ) -> float | None:
    """|r| of the equation's error with the regressor, over its noise band."""
    signal = regressors.get(name)
    if signal is None or signal.size != error.error.size or np.ptp(signal) == 0:
        return None
    (found,) = rs.regressor_correlations(error.error, {name: signal})
    return abs(found.value) / found.band


def locate_all(signatures: Sequence[Signature], runs: Sequence[ClassifiedRun],
               params: RigParameters, simulated: Sequence[Run],
               regressors: Callable[[ClassifiedRun, Run], dict[str, np.ndarray]]
               ) -> list[Place | None]:
    """:func:`locate` for each of ``signatures`` (``regressors``: a run's, over the samples
    the signatures look at, from the run and its simulation)."""
    if not signatures:
        return []
    wanted = {name for s in signatures for name in s.runs}
    pairs = [(r, sim) for r, sim in zip(runs, simulated, strict=True) if r.name in wanted]
    errors = [e for r, sim in pairs for e in equation_errors(r, params, sim)]
    by_run = {r.name: regressors(r, sim) for r, sim in pairs if r.braking}
    return [locate(s, errors, lambda name: by_run.get(name, {})) for s in signatures]
