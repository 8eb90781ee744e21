"""The torso axis follows a leaning trunk (depth/skeleton_fit: the line from the torso patch to the head top),
on real motion: CMU 131_03 (hop) while the performer crouches and leans up to 14 degrees."""
from __future__ import annotations

import numpy as np

from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.depth import skeleton_fit
from kinect_retarget.depth.skeleton_tracker import SkeletonTracker, TrackerSettings

J = KINECT_V1.index


def _trunk(p):
    v = p[J("ShoulderCenter")] - p[J("HipCenter")]
    return v / np.linalg.norm(v)


def _trunk_errors(seq):
    # the fit's own torso axis (the shoulder centre's body-part proposal would follow the lean either way)
    tracker = SkeletonTracker(gravity=seq.gravity, settings=TrackerSettings(part_forest=None))
    out = []
    for i in range(len(seq.mm)):
        pos, _ = tracker.update(seq.mm[i], seq.times[i])
        out.append(np.degrees(np.arccos(np.clip(_trunk(pos) @ _trunk(seq.joints[i]), -1.0, 1.0))))
    return np.array(out)


def test_trunk_lean_is_followed(data_dir, monkeypatch):
    from kinect_retarget.sim.synthetic_depth import Scenario, render_sequence
    seq = render_sequence(str(data_dir / "mocap_bvh" / "131_03.bvh"), str(data_dir / "meshes" / "makehuman"),
                          Scenario(seed=6), start=240, frames=30)
    leaning = _trunk_errors(seq)
    assert leaning.mean() < 8.0, leaning
    monkeypatch.setattr(skeleton_fit, "HEAD_AXIS_WEIGHT", 0.0)   # gravity and the patch alone keep it upright
    # (6.8 against 8.3 degrees: the calibration measuring the patch where it grew narrowed the gap, was 7.2 / 12.3)
    assert _trunk_errors(seq).mean() > leaning.mean() + 1.0
