"""A take: joint positions over time, as every reader returns and every writer and source produces."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .skeletons import NOT_TRACKED, Skeleton


class TakeError(ValueError):
    """Bad input: names the file (and line or record) and what is wrong with it."""


@dataclass
class Take:
    """positions (F, J, 3) float64 Kinect camera space metres; states (F, J) uint8 (0 not tracked,
    1 inferred, 2 tracked); times (F,) float64 seconds, strictly increasing; rate: nominal frames per second.
    """

    skeleton: Skeleton
    positions: np.ndarray
    states: np.ndarray
    times: np.ndarray
    rate: float
    source_format: str = "krtake"
    metadata: dict = field(default_factory=dict)
    hand_states: np.ndarray | None = None  # (F, 2) Kinect v2 HandState of the left and right hand, when read

    def __post_init__(self) -> None:
        self.positions = np.asarray(self.positions, dtype=np.float64)
        self.states = np.asarray(self.states, dtype=np.uint8)
        self.times = np.asarray(self.times, dtype=np.float64)
        f, j = self.states.shape if self.states.ndim == 2 else (-1, -1)
        if self.positions.shape != (f, j, 3) or j != len(self.skeleton):
            raise TakeError(f"take arrays disagree: positions {self.positions.shape}, states "
                            f"{self.states.shape}, skeleton {self.skeleton.name} has {len(self.skeleton)} joints")
        if self.times.shape != (f,):
            raise TakeError(f"take has {f} frames but {self.times.shape} timestamps")
        if f > 1 and np.any(np.diff(self.times) <= 0):
            bad = int(np.argmax(np.diff(self.times) <= 0)) + 1
            raise TakeError(f"timestamps must increase: frame {bad} is not after frame {bad - 1}")
        if not np.all(np.isfinite(self.positions[self.states != NOT_TRACKED])):
            raise TakeError("take has NaN or infinite positions for tracked joints")
        if not (np.isfinite(self.rate) and self.rate > 0):
            raise TakeError(f"take rate must be positive, got {self.rate}")

    @property
    def frame_count(self) -> int:
        return int(self.times.shape[0])

    @property
    def duration(self) -> float:
        return float(self.times[-1] - self.times[0]) if self.frame_count else 0.0

    @property
    def tracked_fraction(self) -> float:
        """Fraction of joint samples reported tracked (state 2)."""
        return float(np.mean(self.states == 2)) if self.states.size else 0.0

    @property
    def any_tracked(self) -> np.ndarray:
        """(F,) True for frames where at least one joint is tracked or inferred."""
        return np.any(self.states != NOT_TRACKED, axis=1)

    def slice(self, frames: slice | np.ndarray) -> Take:
        return Take(self.skeleton, self.positions[frames], self.states[frames], self.times[frames], self.rate,
                    self.source_format, dict(self.metadata),
                    None if self.hand_states is None else self.hand_states[frames])


def nominal_rate(times: np.ndarray, default: float = 30.0) -> float:
    """The take's nominal rate from the median frame interval, rounded to a common rate when close."""
    if len(times) < 2:
        return default
    rate = 1.0 / float(np.median(np.diff(times)))
    for common in (24.0, 25.0, 30.0, 50.0, 60.0, 100.0, 120.0):
        if abs(rate - common) / common < 0.03:
            return common
    return round(rate, 3)
