"""The Movie Clip track naming scheme and named tracks -> 2D tracks (no Blender needed)."""
from __future__ import annotations

import numpy as np
import pytest

from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.lift import LiftError
from kinect_retarget.lift.clip_naming import joint_for_track, match_tracks
from kinect_retarget.lift.clip_tracks import NamedTrack, tracks_from_named

J = KINECT_V1.index


@pytest.mark.parametrize("name, joint", [
    ("ElbowLeft", "ElbowLeft"), ("LElbow", "ElbowLeft"), ("left_elbow", "ElbowLeft"), ("l_elbow", "ElbowLeft"),
    ("L.Elbow", "ElbowLeft"), ("elbow.R", "ElbowRight"), ("Right Knee", "KneeRight"), ("r_hip", "HipRight"),
    ("humanoid_root", "HipCenter"), ("sacroiliac", "HipCenter"), ("vl5", "Spine"), ("skullbase", "Head"),
    ("MidHip", "HipCenter"), ("Neck", "ShoulderCenter"), ("RBigToe", "FootRight"), ("l_toe", "FootLeft"),
    ("KneeLeft.001", "KneeLeft"), ("Track", None), ("Track.003", None), ("elbow", None), ("left", None),
])
def test_track_names(name, joint):
    assert joint_for_track(name) == joint


def test_unknown_and_duplicate_names_are_reported():
    mapping, problems = match_tracks(["l_knee", "KneeLeft", "Track.001", "marker"])
    assert mapping == {"l_knee": "KneeLeft"}
    assert any("'l_knee' and 'KneeLeft' both name joint KneeLeft" in p for p in problems)
    assert any("2 track name(s) follow no joint naming" in p and "'Track.001'" in p for p in problems)


def _track(name, frames, uv, enabled=None):
    frames = np.asarray(frames)
    return NamedTrack(name, frames, np.asarray(uv, float), np.ones(len(frames), bool) if enabled is None
                      else np.asarray(enabled))


def test_named_tracks_to_kinect_joints():
    f = np.arange(10, 20)
    tracks = [_track("l_hip", f, np.c_[f + 100, np.full(10, 300)]),
              _track("r_hip", f, np.c_[f + 60, np.full(10, 300)]),
              _track("l_shoulder", f, np.c_[f + 110, np.full(10, 150)]),
              _track("r_shoulder", f, np.c_[f + 50, np.full(10, 150)], enabled=[True] * 5 + [False] * 5),
              _track("l_elbow", f, np.c_[f + 115, np.full(10, 200)]),
              _track("l_wrist", f, np.c_[f + 118, np.full(10, 250)]),
              _track("Track.004", f, np.zeros((10, 2)))]
    t = tracks_from_named(tracks, 24.0, (640, 480), "clip 'walk'")
    assert t.frame_count == 10 and np.allclose(np.diff(t.times), 1 / 24)
    assert np.allclose(t.uv[0, J("HipCenter")], (90, 300)) and t.inferred[0, J("HipCenter")]
    assert t.inferred[:5, J("ShoulderCenter")].all() and (t.confidence[5:, J("ShoulderCenter")] == 0).all()
    assert t.inferred[:5, J("Spine")].all()
    assert t.inferred[:, J("HandLeft")].all()
    assert (t.confidence[5:, J("ShoulderRight")] == 0).all()  # disabled markers are gaps
    assert any("Track.004" in p for p in t.problems)


def test_no_joint_tracks_is_a_clear_error():
    with pytest.raises(LiftError, match="no track is named after a joint"):
        tracks_from_named([_track("Track", [1], [[1, 1]])], 24, (640, 480), "clip 'x'")
    with pytest.raises(LiftError, match="the clip has no tracks"):
        tracks_from_named([], 24, (640, 480), "clip 'x'")
