"""Shared fixtures. Real data: the repository's tests/data (see tests/data/CREDITS.md), served by `shared_data`
at the same sub-paths as in the workshop's shared/data folder."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[1]
SAMPLE_TAKES = REPO / "sample_takes"


@pytest.fixture(scope="session")
def shared_data(tmp_path_factory) -> Path:
    """tests/data, gzipped files decompressed, laid out like shared/data (tests/repo_data.py)."""
    from tests.repo_data import materialize
    return materialize(tmp_path_factory.mktemp("data"))


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261122)


def assert_quat_equal(a, b, atol: float = 1e-6) -> None:
    """q and -q are the same rotation."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    d = np.minimum(np.abs(a - b).max(axis=-1), np.abs(a + b).max(axis=-1))
    assert np.all(d <= atol), f"quaternions differ by up to {d.max():.3g}"
