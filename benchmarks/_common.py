"""Shared helpers for the benchmarks (run with the venv's python from the repository root)."""
from __future__ import annotations

import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
SAMPLE_TAKES = REPO / "sample_takes"
SHARED_DATA = REPO.parent / "shared" / "data"


def best_of(fn, repeat: int = 3) -> float:
    """Minimum wall time of `repeat` calls, seconds."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)
