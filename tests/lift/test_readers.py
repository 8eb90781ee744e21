"""Keypoint readers on small files in the estimators' real formats, made from real mocap, plus bad input."""
from __future__ import annotations

import json

import numpy as np
import pytest

from kinect_retarget.core.skeletons import INFERRED, KINECT_V1, NOT_TRACKED, TRACKED
from kinect_retarget.lift import LiftError, LiftSettings, lift, read_2d
from kinect_retarget.lift.openpose import write_frame
from kinect_retarget.lift.schemes import BODY_25, COCO_17

from .mocap import IMAGE, camera, seen_from, walking_take

J = KINECT_V1.index
# Estimator keypoint -> the Kinect joint that stands at the same place in our mocap
BODY25_FROM_V1 = {"MidHip": "HipCenter", "Neck": "ShoulderCenter", "Nose": "Head",
                  **{f"{s[0]}{p}": f"{p}{s}" for s in ("Left", "Right")
                     for p in ("Shoulder", "Elbow", "Wrist", "Hip", "Knee", "Ankle")},
                  "LBigToe": "FootLeft", "RBigToe": "FootRight"}
COCO_FROM_V1 = {"nose": "Head", **{f"{s.lower()}_{p.lower()}": f"{p}{s}" for s in ("Left", "Right")
                                   for p in ("Shoulder", "Elbow", "Wrist", "Hip", "Knee", "Ankle")}}


@pytest.fixture(scope="module")
def projected(data_dir):
    truth = seen_from(walking_take(data_dir, 2.0), 20.0)
    return truth, camera().project(truth.positions)


def openpose_folder(tmp_path, uv, frames=None):
    frames = range(len(uv)) if frames is None else frames
    for f in frames:
        kp, conf = np.zeros((25, 2)), np.zeros(25)
        for name, joint in BODY25_FROM_V1.items():
            kp[BODY_25.index(name)], conf[BODY_25.index(name)] = uv[f, J(joint)], 0.9
        write_frame(str(tmp_path / f"walk_{f:012d}_keypoints.json"), kp, conf)
    return tmp_path


def test_openpose_folder_round_trip(tmp_path, projected):
    truth, uv = projected
    tracks = read_2d(openpose_folder(tmp_path, uv), "openpose", fps=30.0, image_size=IMAGE)
    assert tracks.frame_count == len(uv) and not tracks.problems
    for joint in ("HipCenter", "ElbowLeft", "KneeRight", "FootLeft"):
        assert np.allclose(tracks.uv[:, J(joint)], uv[:, J(joint)], atol=1e-3)
    assert tracks.inferred[:, J("Spine")].all() and tracks.inferred[:, J("HandLeft")].all()
    assert not tracks.inferred[:, J("ElbowLeft")].any()
    assert np.allclose(np.diff(tracks.times), 1 / 30)


def test_openpose_bad_files_are_named_and_skipped(tmp_path, projected):
    truth, uv = projected
    folder = openpose_folder(tmp_path, uv)
    (folder / "walk_000000000005_keypoints.json").write_text("")
    (folder / "walk_000000000006_keypoints.json").write_text('{"version": 1.3, "people": [{"pose_keyp')
    (folder / "walk_000000000007_keypoints.json").write_text('{"version": 1.3, "people": []}')
    (folder / "walk_000000000008_keypoints.json").write_text(
        json.dumps({"people": [{"pose_keypoints_2d": [1.0] * 54}]}))  # COCO-18 output
    tracks = read_2d(folder, "openpose", image_size=IMAGE)
    text = "\n".join(tracks.problems)
    assert "walk_000000000005_keypoints.json: file is empty" in text
    assert "walk_000000000006_keypoints.json: malformed JSON at line 1" in text
    assert "walk_000000000007_keypoints.json: no person detected" in text
    assert "54 values; BODY_25 has 75" in text
    assert np.all(tracks.confidence[5:9] == 0)
    res = lift(tracks, LiftSettings(focal_px=1000.0))
    # the four lost frames are bridged (shorter than the gap limit) and marked inferred; the rest tracked
    assert np.all(res.take.states[5:9, J("ElbowLeft")] == INFERRED)
    assert np.all(res.take.states[:5, J("ElbowLeft")] == TRACKED)


def test_openpose_joints_outside_image_are_ignored_with_a_message(tmp_path, projected):
    truth, uv = projected
    uv = uv.copy()
    uv[3, J("WristLeft")] = (5000.0, 200.0)
    tracks = read_2d(openpose_folder(tmp_path, uv), "openpose", image_size=IMAGE)
    assert any("LWrist at (5000, 200) px is outside the 1280x720 image" in p for p in tracks.problems)
    assert tracks.confidence[3, J("WristLeft")] == 0 and tracks.confidence[4, J("WristLeft")] > 0


def test_openpose_empty_folder_and_all_bad(tmp_path):
    with pytest.raises(LiftError, match="no \\*_keypoints.json files"):
        read_2d(tmp_path, "openpose")
    (tmp_path / "a_000000000000_keypoints.json").write_text("{}")
    with pytest.raises(LiftError, match="no usable person in any of its 1 keypoint files"):
        read_2d(tmp_path, "openpose")


def test_openpose_picks_the_same_person_when_several(tmp_path, projected):
    truth, uv = projected
    folder = openpose_folder(tmp_path, uv[:4])
    path = folder / "walk_000000000002_keypoints.json"
    data = json.loads(path.read_text())
    other = np.array(data["people"][0]["pose_keypoints_2d"]).reshape(25, 3)
    other[:, 0] += 300
    other[:, 2] = 1.0  # more confident, but far from where our performer was
    data["people"].insert(0, {"pose_keypoints_2d": other.ravel().tolist()})
    path.write_text(json.dumps(data))
    tracks = read_2d(folder, "openpose")
    assert np.allclose(tracks.uv[2, J("HipCenter")], uv[2, J("HipCenter")], atol=1e-3)


def coco_file(path, uv, drop_image=None):
    images, anns = [], []
    for f in range(len(uv)):
        images.append({"id": 100 + f, "file_name": f"frame_{f}.jpg", "width": IMAGE[0], "height": IMAGE[1]})
        if f == drop_image:
            continue
        kp = np.zeros((17, 3))
        for name, joint in COCO_FROM_V1.items():
            kp[COCO_17.index(name)] = (*uv[f, J(joint)], 2)
        kp[COCO_17.index("left_knee"), 2] = 1 if f == 1 else 2  # occluded but labelled
        anns.append({"id": f, "image_id": 100 + f, "category_id": 1, "keypoints": kp.ravel().tolist(),
                     "num_keypoints": 13})
    path.write_text(json.dumps({"images": images[::-1], "annotations": anns,
                                "categories": [{"id": 1, "name": "person", "keypoints": list(COCO_17)}]}))
    return path


def test_coco_annotations_round_trip(tmp_path, projected):
    truth, uv = projected
    tracks = read_2d(coco_file(tmp_path / "kp.json", uv, drop_image=4), "coco")
    assert tracks.image_size == IMAGE
    assert np.allclose(tracks.uv[0, J("KneeLeft")], uv[0, J("KneeLeft")], atol=1e-3)  # frame order by name
    assert tracks.inferred[1, J("KneeLeft")] and not tracks.inferred[2, J("KneeLeft")]
    assert tracks.confidence[:, J("FootLeft")].max() == 0  # COCO has no feet
    assert any("image 104 (frame_4.jpg): no person" in p for p in tracks.problems)
    res = lift(tracks, LiftSettings(focal_px=1000.0))
    assert np.all(res.take.states[:, J("FootLeft")] == INFERRED)
    assert np.all(np.isfinite(res.take.positions[res.take.states != NOT_TRACKED]))


def test_coco_results_list_and_malformed(tmp_path, projected):
    truth, uv = projected
    def keypoints(f):
        kp = np.zeros((17, 3))
        for name, joint in COCO_FROM_V1.items():
            kp[COCO_17.index(name)] = (*uv[f, J(joint)], 0.8)  # detector confidence in the third slot
        return kp.ravel().tolist()
    res = [{"image_id": f, "category_id": 1, "score": 0.9, "keypoints": keypoints(f)} for f in range(len(uv))]
    (tmp_path / "res.json").write_text(json.dumps(res))
    tracks = read_2d(tmp_path / "res.json", "coco")
    assert tracks.frame_count == len(uv)
    (tmp_path / "bad.json").write_text('{"annotations": [')
    with pytest.raises(LiftError, match="bad.json: malformed JSON at line 1"):
        read_2d(tmp_path / "bad.json", "coco")
    (tmp_path / "empty.json").write_text("  ")
    with pytest.raises(LiftError, match="empty.json: file is empty"):
        read_2d(tmp_path / "empty.json", "coco")
    (tmp_path / "other.json").write_text('{"foo": 1}')
    with pytest.raises(LiftError, match="not COCO keypoints"):
        read_2d(tmp_path / "other.json", "coco")


def test_cli_lift_with_calibration_take(tmp_path, projected, data_dir):
    from kinect_retarget.cli import main
    from kinect_retarget.lift.bones import lengths_from_take
    from kinect_retarget.takes import load_take
    truth, uv = projected
    (tmp_path / "kp").mkdir()
    folder = openpose_folder(tmp_path / "kp", uv)
    calib = data_dir / "mocap_bvh" / "131_02.bvh"
    out = tmp_path / "lifted.krtake"
    assert main(["lift", str(folder), "--out", str(out), "--calibrate", str(calib), "--focal", "1000",
                 "--image-size", "1280", "720"]) == 0
    take = load_take(out)
    want = lengths_from_take(load_take(calib))
    knee = J("KneeLeft")
    assert lengths_from_take(take)[knee] == pytest.approx(want[knee], rel=0.02)
    assert take.metadata["focal_known"] is True
