"""The unit every source produces and the pump consumes: one whole skeleton frame."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class SkeletonFrame:
    """positions (J, 3) Kinect camera space metres; states (J,) uint8; time_s on the source's own clock
    (only differences matter); arrival = time.perf_counter() when the frame reached the queue; body: which
    performer (from 0) for sources that see several (sources/body_fanout.py routes them to their rigs)."""

    positions: np.ndarray
    states: np.ndarray
    time_s: float
    arrival: float
    body: int = 0
