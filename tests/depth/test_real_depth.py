"""The tracker on real Kinect v1 depth frames (no ground truth: person found, skeleton plausible)."""
from __future__ import annotations

import numpy as np

from kinect_retarget.core.skeletons import KINECT_V1, NOT_TRACKED
from kinect_retarget.depth.skeleton_tracker import SkeletonTracker

J = KINECT_V1.index


def _plausible(pos, st):
    assert np.all(np.isfinite(pos))
    assert np.all(st != NOT_TRACKED)
    assert pos[J("ShoulderCenter"), 1] > pos[J("HipCenter"), 1] + 0.2          # upright
    assert 0.2 < np.linalg.norm(pos[J("ShoulderLeft")] - pos[J("ShoulderRight")]) < 0.5
    # the performer's left is on the sensor's right (-X) when facing it
    assert pos[J("ShoulderLeft"), 0] < pos[J("ShoulderRight"), 0]


def test_skeltrack_frames(data_dir):
    files = sorted((data_dir / "depth_real" / "skeltrack" / "tests" / "resources").glob("depth-data-*"))
    assert len(files) >= 10
    tr = SkeletonTracker()
    for i, f in enumerate(files):
        mm = np.fromfile(f, "<u2").reshape(480, 640)
        pos, st = tr.update(mm, i / 30)
        _plausible(pos, st)
        assert 0.7 < pos[J("Spine"), 2] < 1.6                                  # the person is 0.7-1.5 m away


def test_fakenect_recording(data_dir):
    from kinect_retarget.device.disparity_calibration import Calibration
    from kinect_retarget.sim.depth_sequences import load_fakenect_dir
    raws = load_fakenect_dir(data_dir / "depth_real" / "fakenect_openiss" / "fakenect-record")
    cal = Calibration()
    tr = SkeletonTracker()
    found = 0
    for i, raw in enumerate(raws):
        pos, st = tr.update(cal.to_mm(raw), i / 30)
        if np.any(st != NOT_TRACKED):
            found += 1
            _plausible(pos, st)
            assert 0.8 < pos[J("Spine"), 2] < 1.8                              # walks in to about 1-1.3 m
    assert found >= 0.9 * len(raws)
