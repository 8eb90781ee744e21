"""Shared fixtures. Real data: the repository's tests/data (see tests/data/CREDITS.md), served by `data_dir`
at the same sub-paths as in the workshop's shared/data folder."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[1]
SAMPLE_TAKES = REPO / "sample_takes"
TESTS = Path(__file__).resolve().parent
# Tiers (markers registered in pytest.ini; `make test-core` deselects bpy, slow and network): folders whose
# tests need the bpy wheel, and folders whose tests render depth, build meshes, stream the emulated Kinect or
# track images (seconds each). Tests that open sockets carry @pytest.mark.network themselves.
BPY_FOLDERS = ("blender",)
SLOW_FOLDERS = ("depth", "autorig", "device", "lift")


def pytest_collection_modifyitems(config, items):
    for item in items:
        folder = Path(str(item.fspath)).resolve().relative_to(TESTS).parts[0]
        if folder in BPY_FOLDERS:
            item.add_marker(pytest.mark.bpy)
        if folder in SLOW_FOLDERS:
            item.add_marker(pytest.mark.slow)


@pytest.fixture(scope="session")
def data_dir(tmp_path_factory) -> Path:
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
