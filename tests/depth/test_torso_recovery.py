"""The torso climbs back to a head the forest confirms (depth/skeleton_fit._pin_along_axis): after a deep bend
the torso's geodesic disc, seeded where the torso last was, sits on the hips, and a head top more than 15 cm
up the axis was refused as a raised hand, so the skeleton stayed sunk for frames after the performer stood up
(real depth, pick up and throw). Rendered here: a standing performer whose remembered torso is put 40 cm low."""
from __future__ import annotations

import numpy as np

from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.depth import skeleton_fit
from kinect_retarget.depth.skeleton_tracker import SkeletonTracker, TrackerSettings

SC = KINECT_V1.index("ShoulderCenter")


def _shoulder_centre_error_after_sinking(seq, drop=0.4):
    tracker = SkeletonTracker(gravity=seq.gravity, settings=TrackerSettings(steady_output=False))
    for i in range(8):
        tracker.update(seq.mm[i], seq.times[i])
    tracker.last_good.torso_centre = tracker.last_good.torso_centre - np.array([0.0, drop, 0.0])
    pos, _ = tracker.update(seq.mm[8], seq.times[8])
    return abs(pos[SC, 1] - seq.joints[8][SC, 1])   # heights: the output is the SDK's joint, a few cm off


def test_sunk_torso_climbs_back_to_a_confirmed_head(rendered, monkeypatch):
    seq, _ = rendered
    recovered = _shoulder_centre_error_after_sinking(seq)
    assert recovered < 0.08, recovered
    monkeypatch.setattr(skeleton_fit, "FAR_HEAD_SHIFT", 1.0)   # the head refused: the torso stays low
    assert _shoulder_centre_error_after_sinking(seq) > 0.2
