"""Live statistics: counters and arrival-to-applied latency over a fixed window (memory stays flat)."""
from __future__ import annotations

import numpy as np


class LatencyWindow:
    """The last `size` latencies in a ring buffer; percentiles over that window."""

    def __init__(self, size: int = 4096):
        self._buf = np.zeros(size)
        self._n = 0

    def add(self, seconds: float) -> None:
        self._buf[self._n % self._buf.size] = seconds
        self._n += 1

    @property
    def count(self) -> int:
        return min(self._n, self._buf.size)

    def percentile_ms(self, q: float) -> float | None:
        if self._n == 0:
            return None
        return float(np.percentile(self._buf[:self.count], q) * 1000.0)


class RateMeter:
    """Frames per second over the last second or so, from arrival times."""

    def __init__(self, size: int = 64):
        self._times = np.full(size, np.nan)
        self._n = 0

    def add(self, t: float) -> None:
        self._times[self._n % self._times.size] = t
        self._n += 1

    def fps(self) -> float:
        n = min(self._n, self._times.size)
        if n < 2:
            return 0.0
        t = np.sort(self._times[:n])
        span = t[-1] - t[0]
        return float((n - 1) / span) if span > 0 else 0.0


class LiveStats:
    def __init__(self) -> None:
        self.received = 0      # frames taken from the queue
        self.applied = 0       # frames whose pose reached the rig
        self.superseded = 0    # drained together with a newer frame: filtered and recorded, not shown
        self.stale = 0         # newest frame already too old when drained: not shown
        self.untracked = 0     # frames with no tracked joint: recorded, pose held
        self.recorded = 0
        self.latency = LatencyWindow()
        self.rate = RateMeter()

    def as_dict(self, overflowed: int = 0) -> dict:
        p50, p99 = self.latency.percentile_ms(50), self.latency.percentile_ms(99)
        return {"received": self.received, "applied": self.applied,
                "dropped": self.superseded + self.stale + overflowed,
                "superseded": self.superseded, "stale": self.stale, "overflowed": overflowed,
                "untracked": self.untracked, "recorded": self.recorded,
                "latency_p50_ms": None if p50 is None else round(p50, 3),
                "latency_p99_ms": None if p99 is None else round(p99, 3),
                "fps": round(self.rate.fps(), 2)}
