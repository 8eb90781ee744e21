"""Live test helpers: small real takes from the shared Kinect v2 recordings, and a stand-in pipeline for
tests of the pump plumbing (the retarget itself is tested against the real engine elsewhere)."""
from __future__ import annotations

import threading
from types import SimpleNamespace

import numpy as np
import pytest

from kinect_retarget.core.skeletons import KINECT_V2, NOT_TRACKED
from kinect_retarget.core.take import Take
from kinect_retarget.takes import krtake


def read_kinectreader_csv(path, frames: int | None = None) -> Take:
    """Microsoft KinectReader CSV (100 ns ticks, then 25 x (x, y, z, state)); trailing commas allowed."""
    rows = []
    with open(path, encoding="utf-8") as fh:
        for line in fh:
            vals = [v for v in line.strip().split(",") if v != ""]
            if vals:
                rows.append([float(v) for v in vals])
            if frames and len(rows) >= frames:
                break
    a = np.asarray(rows)
    block = a[:, 1:].reshape(len(a), 25, 4)
    return Take(KINECT_V2, block[..., :3], block[..., 3].astype(np.uint8), (a[:, 0] - a[0, 0]) / 1e7, 30.0,
                "kinectreader_csv")


@pytest.fixture
def wave_take(shared_data) -> Take:
    return read_kinectreader_csv(shared_data / "kinect_v2" / "Ges01_wavehand.csv")


@pytest.fixture
def wave_take_file(wave_take, tmp_path):
    path = tmp_path / "wave.krtake"
    krtake.write(path, wave_take)
    return path


class StandInPipeline:
    """Stateful like the engine's: an exponential filter on positions, so frame order and completeness
    matter. Returns None for frames without a tracked joint."""

    def __init__(self):
        self.reset()
        self.calls = 0

    def reset(self, rate=30.0):
        self.state = None

    def process_frame(self, positions, states, time_s):
        self.calls += 1
        if not np.any(states != NOT_TRACKED):
            return None
        p = np.asarray(positions, dtype=np.float64)
        self.state = p if self.state is None else 0.5 * self.state + 0.5 * p
        return SimpleNamespace(root_location=self.state[0].copy(), quats=np.tile([1.0, 0, 0, 0], (3, 1)),
                               time_s=time_s, index=self.calls - 1)

    def process_frames(self, positions, states, times):
        """Frame by frame (the engine's batch step filters all and solves only the last; same pose)."""
        pose = None
        for p, s, t in zip(positions, states, times):
            pose = self.process_frame(p, s, float(t)) or pose
        return pose


@pytest.fixture
def stand_in():
    return StandInPipeline()


@pytest.fixture(autouse=True)
def no_leftover_threads():
    before = set(threading.enumerate())
    yield
    left = [t for t in threading.enumerate() if t not in before and t.name.startswith("kinect_retarget")]
    for t in left:
        t.join(3.0)
    assert not [t for t in left if t.is_alive()], f"threads left running: {left}"
