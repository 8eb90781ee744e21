"""Shared helpers for the benchmarks (run with the venv's python from the repository root)."""
from __future__ import annotations

import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
SAMPLE_TAKES = REPO / "sample_takes"
SHARED_DATA = REPO.parent / "shared" / "data"   # the workshop's full data, beside the repository: not shipped


def shared_data_or_skip(script: str) -> Path:
    """SHARED_DATA, or (absent, as in a plain clone) say so and end the benchmark successfully."""
    if not SHARED_DATA.is_dir():
        print(f"{Path(script).name}: skipped: it reads the full recordings in {SHARED_DATA}, which is not there "
              f"(the repository ships only the trimmed copies the tests need)")
        sys.exit(0)
    return SHARED_DATA


def best_of(fn, repeat: int = 3, both: bool = False):
    """Minimum wall time of `repeat` calls, seconds; with both, also the minimum CPU time of this process
    (steadier on a shared machine)."""
    wall, cpu = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return (min(wall), min(cpu)) if both else min(wall)
