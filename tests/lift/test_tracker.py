"""The paper's particle-filter / colour-histogram tracker on a short rendered sequence of real motion."""
from __future__ import annotations

import json

import numpy as np
import pytest

from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.lift import LiftError, read_2d
from kinect_retarget.lift.video_camera import Camera, view_points
from kinect_retarget.lift.image_sequence import load_frame, write_ppm
from kinect_retarget.sim.body_imagery import background, render
from kinect_retarget.lift.joint_tracker import JointTracker, TrackerSettings, write_keypoints

from .mocap import walking_take

SIZE = (320, 240)
NAMES = ("HipCenter", "ShoulderCenter", "Head", "ElbowLeft", "WristLeft", "ElbowRight", "WristRight",
         "KneeLeft", "AnkleLeft", "KneeRight", "AnkleRight")


@pytest.fixture(scope="module")
def sequence(data_dir):
    take = walking_take(data_dir, 7.0).slice(slice(150, 180))  # one second in mid-walk
    pos = view_points(take.positions, 80.0, 5.0, 3.5, take.positions[:, 0].mean(axis=0))  # walks across
    cam = Camera.for_image(*SIZE, 300.0)
    rng = np.random.default_rng(11)
    bg = background(*SIZE, rng)
    return [render(p, cam, *SIZE, bg, rng) for p in pos], cam.project(pos)


def test_tracker_follows_rendered_joints(sequence):
    images, uv = sequence
    idx = [KINECT_V1.index(n) for n in NAMES]
    tr = JointTracker(images[0], {n: tuple(uv[0, j]) for n, j in zip(NAMES, idx)}, TrackerSettings(seed=3))
    res = [tr.initial()] + [tr.step(im) for im in images[1:]]
    est = np.stack([r.uv for r in res])
    found = np.stack([r.found for r in res])
    err = np.linalg.norm(est - uv[:, idx], axis=-1)
    assert found.mean() > 0.9
    assert np.mean(err[found]) < 6.0  # pixels; the body is ~150 px tall
    # a tracker that never moves would be far worse: the walk carries the joints tens of pixels
    assert np.mean(np.linalg.norm(uv[:, idx] - uv[:1, idx], axis=-1)) > 2.5 * np.mean(err[found])


def test_tracker_output_is_openpose_keypoints(sequence, tmp_path):
    images, uv = sequence
    frames = tmp_path / "frames"
    frames.mkdir()
    paths = []
    for i, im in enumerate(images[:6]):
        paths.append(str(frames / f"f{i:03d}.ppm"))
        write_ppm(paths[-1], im)
    assert np.abs(load_frame(paths[0]) - images[0]).max() <= 0.5 / 255 + 1e-6
    idx = [KINECT_V1.index(n) for n in NAMES]
    init = {n: tuple(uv[0, j]) for n, j in zip(NAMES, idx)}
    tr = JointTracker(load_frame(paths[0]), init)
    res = [tr.initial()] + [tr.step(load_frame(p)) for p in paths[1:]]
    write_keypoints(str(tmp_path / "kp"), paths, res, tr.names)
    tracks = read_2d(tmp_path / "kp", "openpose", image_size=SIZE)
    assert tracks.frame_count == 6
    assert np.allclose(tracks.uv[0, KINECT_V1.index("ElbowLeft")], uv[0, KINECT_V1.index("ElbowLeft")], atol=0.01)


def test_tracker_init_outside_frame_is_rejected(sequence):
    images, _ = sequence
    with pytest.raises(LiftError, match="ElbowLeft outside the 320x240 first frame"):
        JointTracker(images[0], {"ElbowLeft": (400.0, 10.0)})


def test_cli_track_then_lift(sequence, tmp_path):
    from kinect_retarget.cli import main
    images, uv = sequence
    frames = tmp_path / "frames"
    frames.mkdir()
    for i, im in enumerate(images[:12]):
        write_ppm(str(frames / f"f{i:03d}.ppm"), im)
    idx = [KINECT_V1.index(n) for n in NAMES]
    (tmp_path / "init.json").write_text(json.dumps({n: uv[0, j].tolist() for n, j in zip(NAMES, idx)}))
    assert main(["track-2d", str(frames), "--init", str(tmp_path / "init.json"), "--out", str(tmp_path / "kp")]) == 0
    out = tmp_path / "walk.krtake"
    assert main(["lift", str(tmp_path / "kp"), "--format", "openpose", "--out", str(out), "--focal", "300",
                 "--image-size", "320", "240"]) == 0
    from kinect_retarget.takes import load_take
    take = load_take(out)
    assert take.frame_count == 12 and take.skeleton is KINECT_V1
    assert main(["lift", str(tmp_path / "nothing"), "--format", "openpose", "--out", str(out)]) == 2


def test_hidden_joint_is_reported_lost_then_found_again(sequence):
    images, uv = sequence
    j = KINECT_V1.index("WristRight")
    hidden = [im.copy() for im in images]
    for f in range(10, 16):  # cover the right wrist with a grey card for six frames
        u, v = np.round(uv[f, j]).astype(int)
        hidden[f][max(v - 14, 0):v + 15, max(u - 14, 0):u + 15] = 0.5
    init = {"WristRight": tuple(uv[0, j]), "KneeLeft": tuple(uv[0, KINECT_V1.index("KneeLeft")])}
    tr = JointTracker(hidden[0], init, TrackerSettings(seed=2))
    res = [tr.initial()] + [tr.step(im) for im in hidden[1:]]
    found = np.array([r.found[0] for r in res])
    assert (~found[10:16]).sum() >= 4  # the card hides it (the edge of the forearm may still match)
    assert found[:10].all() and found[20:].mean() > 0.8
