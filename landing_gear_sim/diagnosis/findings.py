"""What a diagnosis finds: causes with their evidence, and residual structure."""

from __future__ import annotations

import dataclasses
import enum
from dataclasses import dataclass, field


class SignatureKind(str, enum.Enum):
    """What a residual signature measures (compares equal to its value)."""

    FREQUENCY = "frequency"
    LAG = "lag"
    REGRESSOR = "regressor"

    def __str__(self) -> str:
        return self.value

    @property
    def parameter(self) -> str:
        """Its key parameter's name in an ``unexplained`` finding."""
        return {"frequency": "frequency_hz", "lag": "lag_s", "regressor": "correlation"}[
            self.value]


@dataclass(frozen=True, kw_only=True)
class Finding:
    """One cause (or unexplained structure) with its evidence.

    ``parameters`` are the key parameters (contract names, SI) and ``std`` their
    1-σ; ``fit_before``/``fit_after`` are fit % per channel on the held-out runs;
    ``delta_bic`` is BIC(with) − BIC(without) on the fitting runs (negative favours
    the extension) and ``held_out`` the same log-likelihood change on held-out runs.
    """

    cause: str
    parameters: dict[str, float]
    std: dict[str, float]
    evidence: str
    fit_before: dict[str, float]
    fit_after: dict[str, float]
    delta_bic: float | None
    held_out: float | None
    accepted: bool
    fitted_on: tuple[str, ...] = ()
    checked_on: tuple[str, ...] = ()
    family: str = ""
    """A ``discovered`` finding: the library family of its terms (``sliding_speed``, ...)."""
    term: str = ""
    """A ``discovered`` finding: the extended law with its fitted values."""
    equation: str = ""
    """An ``unexplained`` finding: the equation (or the channel's measurement) whose error
    carries it: ``valve``, ``wheel``, ``flywheel``, ``loading device``, ``pressure channel``,
    ``wheel channel``, ..."""
    channel: str = ""
    """An ``unexplained`` finding: the measured channel its evidence was found in."""
    reason: str = ""
    """A scored candidate: why it was accepted or not, by the first rule it met or failed."""
    round: int = 0
    """A scored candidate: the round of the search it was scored in (0: the discovery's)."""
    rmse_before: dict[str, float] = field(default_factory=dict)
    rmse_after: dict[str, float] = field(default_factory=dict)
    """RMSE per channel on the held-out runs [the channel's SI unit], beside the fit %."""
    units: dict[str, str] = field(default_factory=dict)
    """The SI unit of a parameter whose key does not carry one (an ``unexplained``
    finding's deviation, in its relation's unit; '-': a ratio)."""
    approximate: bool = False
    """A ``discovered`` law whose own equation still shows what the final model misses (an
    ``unexplained`` finding there): it approximates the rig's law, and that finding says
    where it misses."""

    def to_json(self) -> dict[str, object]:
        document: dict[str, object] = {"cause": self.cause, "parameters": self.parameters,
                    "uncertainty": self.std, "evidence": self.evidence,
                    "fit_before": self.fit_before, "fit_after": self.fit_after,
                    "delta_bic": self.delta_bic, "held_out_delta": self.held_out,
                    "fitted_on": list(self.fitted_on), "checked_on": list(self.checked_on)}
        if self.reason:
            document |= {"reason": self.reason, "round": self.round}
        if self.rmse_after:
            document |= {"rmse_before": self.rmse_before, "rmse_after": self.rmse_after}
        if self.family:
            document |= {"family": self.family, "term": self.term}
        if self.equation:
            document |= {"equation": self.equation, "channel": self.channel}
        if self.units:
            document |= {"units": self.units}
        if self.approximate:
            document |= {"approximate": True}
        return document


def approximations(findings: list[Finding], equations: dict[str, str]) -> list[Finding]:
    """``findings`` with each discovered law marked approximate where an ``unexplained``
    finding lives in the equation it extends (``equations``: a family -> its equation)."""
    missed = {f.equation for f in findings if f.cause == "unexplained"}
    return [dataclasses.replace(f, approximate=True)
            if f.cause == "discovered" and equations.get(f.family) in missed else f
            for f in findings]


@dataclass(frozen=True)
class Signature:
    """Structure in the residual that recurs across runs.

    ``kind`` says what ``value`` is: a frequency [Hz], a lag [s, positive: measurement
    later] or a correlation with the named ``regressor``; ``size`` compares it with the
    noise (peak power over floor; lag in samples; |correlation| over its band).
    """

    kind: SignatureKind
    channel: str
    value: float
    size: float
    runs: tuple[str, ...]
    regressor: str = ""
    tentative: bool = False
    """Too scattered over the runs to report, enough to try a candidate for."""

    def describe(self) -> str:
        where = f"{self.channel} residual in {len(self.runs)} runs"
        if self.kind is SignatureKind.FREQUENCY:
            return f"spectral line at {self.value:.2f} Hz ({self.size:.0f}x the floor) in {where}"
        if self.kind is SignatureKind.LAG:
            return (f"measured {self.channel} lags the simulation by {self.value * 1e3:.1f} ms"
                    f" in {len(self.runs)} runs")
        return (f"{where} correlates with {self.regressor} (r = {self.value:+.2f}, "
                f"{self.size:.1f}x its noise band)")
