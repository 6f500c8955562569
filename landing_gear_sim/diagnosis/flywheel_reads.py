"""Whether the flywheel feels what the F_x channel reads: a channel's error shows wherever
the channel is read, the flywheel's balance included; a torque on the wheel does not reach
it (the tyre pushes it, the flywheel feels the true F_x). The F_x channel's families ask it
before they name the channel."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.diagnosis.equation_library import FLYWHEEL
from landing_gear_sim.diagnosis.selection import Term, ordinary_fit
from landing_gear_sim.model.parameters import RigParameters


def flywheel_carries(braking: Sequence[br.Braking], params: RigParameters,
                     values: Callable[[br.Braking], np.ndarray]) -> tuple[float, float]:
    """How much of ``values`` (a signal of a braking run) the measured F_x carries that the
    flywheel does not feel: its coefficient in the flywheel's balance error, and its t
    (0, 0: no run to tell). A channel's error shows wherever the channel is read; a torque
    on the wheel (a bearing's) does not reach the flywheel's balance."""
    # the reading's excess adds to the balance as a force that pushes the flywheel: the
    # library's terms oppose its motion
    carried = (Term[br.Braking]("", "", "", 0.0, lambda b, _: -values(b)),)
    rows = [r for b in braking if (r := FLYWHEEL.rows(b, params, carried)) is not None]
    if not rows:
        return 0.0, 0.0
    coef, t = ordinary_fit(np.vstack([np.hstack([r.terms, r.owned]) for r in rows]),
                           np.concatenate([r.error for r in rows]))
    return float(coef[0]), float(t[0])


def flywheel_reads(braking: Sequence[br.Braking], params: RigParameters,
                   values: Callable[[br.Braking], np.ndarray], coefficient: float) -> bool:
    """Whether the flywheel's balance carries ``coefficient`` of ``values`` as the F_x
    channel does (at least half of it, the same way): a channel's error, not a torque on the
    wheel."""
    carried, _ = flywheel_carries(braking, params, values)
    return carried * coefficient > 0 and abs(carried) >= abs(coefficient) / 2
