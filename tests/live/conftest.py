"""Live test helpers: small real takes from the Kinect v2 recordings in tests/data, and a stand-in pipeline for
tests of the pump plumbing (the retarget itself is tested against the real engine elsewhere)."""
from __future__ import annotations

import threading
from types import SimpleNamespace

import numpy as np
import pytest

from kinect_retarget.core.skeletons import NOT_TRACKED
from kinect_retarget.core.take import Take
from kinect_retarget.takes import kinect_v2_csv, krtake


def read_kinectreader_csv(path, frames: int | None = None) -> Take:
    """Microsoft KinectReader CSV through the package's own reader, cut to `frames`."""
    take = kinect_v2_csv.read(path)
    n = frames or take.frame_count
    return Take(take.skeleton, take.positions[:n], take.states[:n], take.times[:n], take.rate, take.source_format)


@pytest.fixture
def wave_take(data_dir) -> Take:
    return read_kinectreader_csv(data_dir / "kinect_v2" / "Ges01_wavehand.csv")


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
