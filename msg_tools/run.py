"""The typed run object every tool works on."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .errors import RunFormatError

SIGNALS: tuple[str, ...] = (
    "current_a", "pressure_pa", "wheel_speed_rad_s", "flywheel_speed_rad_s",
    "vertical_load_n", "longitudinal_force_n",
)
"""Signal fields of a :class:`Run`, besides ``time_s``."""


@dataclass(frozen=True)
class Run:
    """One rig test on a common time base, SI units.

    All arrays have shape (n,). ``pressure_pa`` is gauge pressure;
    ``longitudinal_force_n`` is positive when braking.
    """

    name: str
    time_s: np.ndarray
    current_a: np.ndarray
    pressure_pa: np.ndarray
    wheel_speed_rad_s: np.ndarray
    flywheel_speed_rad_s: np.ndarray
    vertical_load_n: np.ndarray
    longitudinal_force_n: np.ndarray
    source: str = field(default="")
    notes: tuple[str, ...] = field(default=(), compare=False)
    """What reading had to do to the file (e.g. a last line cut short, dropped): for the
    user, beside the run, never silent."""
    absent: tuple[str, ...] = field(default=())
    """Signal fields the logger did not record (a braking log without load cells, or without
    a flywheel encoder): NaN here, and what needs them skips the run and says so."""

    def __post_init__(self) -> None:
        n = np.shape(self.time_s)
        for name in ("time_s", *SIGNALS):
            value = np.asarray(getattr(self, name), dtype=float)
            if value.shape != n or value.ndim != 1:
                raise RunFormatError(f"{self.source or self.name}: {name} has shape "
                                     f"{value.shape}, expected {n}")
            object.__setattr__(self, name, value)
        if value.size < 2 or np.any(np.diff(self.time_s) <= 0):
            raise RunFormatError(f"{self.source or self.name}: time must be strictly "
                                 "increasing with at least 2 samples")

    def part(self, samples: slice, name: str) -> Run:
        """The samples ``samples`` of this run, as the run ``name``."""
        return Run(name=name, time_s=self.time_s[samples], source=self.source,
                   notes=self.notes, absent=self.absent,
                   **{s: getattr(self, s)[samples] for s in SIGNALS})

    def lacks(self, *fields: str) -> tuple[str, ...]:
        """Those of ``fields`` the logger did not record."""
        return tuple(f for f in fields if f in self.absent)

    @property
    def rate_hz(self) -> float:
        """Mean sample rate."""
        return (self.time_s.size - 1) / float(self.time_s[-1] - self.time_s[0])

    def __len__(self) -> int:
        return int(self.time_s.size)
