"""Fixtures for the device tests: real Kinect v1 depth frames from tests/data."""
from __future__ import annotations

import pytest

from kinect_retarget.sim.depth_sequences import load_fakenect_dir

FAKENECT = "depth_real/fakenect_openiss/fakenect-record"


@pytest.fixture(scope="session")
def real_depth(data_dir):
    """Ten consecutive real raw 11-bit depth frames (480, 640) uint16 recorded by libfreenect."""
    return load_fakenect_dir(data_dir / FAKENECT, limit=10)
