"""Keypoint layouts of 2D pose estimators and how each maps onto the Kinect v1 joint set.

Kinect v1 has joints no estimator reports (Spine, Hand; Foot for COCO): they are synthesised from
neighbouring keypoints and marked inferred, or left missing for the lifter to infer in 3D.
"""
from __future__ import annotations

# OpenPose BODY_25 (pose_keypoints_2d order).
BODY_25 = ("Nose", "Neck", "RShoulder", "RElbow", "RWrist", "LShoulder", "LElbow", "LWrist", "MidHip",
           "RHip", "RKnee", "RAnkle", "LHip", "LKnee", "LAnkle", "REye", "LEye", "REar", "LEar",
           "LBigToe", "LSmallToe", "LHeel", "RBigToe", "RSmallToe", "RHeel")

# COCO person keypoints (17), as in person_keypoints_*.json categories[0].keypoints.
COCO_17 = ("nose", "left_eye", "right_eye", "left_ear", "right_ear", "left_shoulder", "right_shoulder",
           "left_elbow", "right_elbow", "left_wrist", "right_wrist", "left_hip", "right_hip", "left_knee",
           "right_knee", "left_ankle", "right_ankle")

# Kinect v1's Spine sits about a third of the way from the hip centre to the shoulder centre.
SPINE_FRACTION = 0.35
# Kinect v1's Hand is about a third of a forearm beyond the wrist.
HAND_EXTENSION = 0.30


def _ix(names: tuple[str, ...]):
    return {n: i for i, n in enumerate(names)}


def _recipe(ix, hip_l, hip_r, mid_hip, neck, sh_l, sh_r, head_alts, sides, feet):
    """Build a Kinect v1 recipe from source keypoint names (see tracks2d.combine)."""
    one = lambda n: [(ix[n], 1.0)]  # noqa: E731
    mean = lambda *ns: [(ix[n], 1.0 / len(ns)) for n in ns]  # noqa: E731
    hip_c = [one(mid_hip)] if mid_hip else []
    hip_c.append(mean(hip_l, hip_r))
    sh_c = [one(neck)] if neck else []
    sh_c.append(mean(sh_l, sh_r))
    r: dict[str, list] = {"HipCenter": hip_c, "ShoulderCenter": sh_c, "Head": [mean(*a) for a in head_alts]}
    spine = []
    for h in hip_c:
        for c in sh_c:
            spine.append([(k, w * (1 - SPINE_FRACTION)) for k, w in h] + [(k, w * SPINE_FRACTION) for k, w in c])
    r["Spine"] = spine
    for side, (sh, el, wr, hip, kn, an) in sides.items():
        r[f"Shoulder{side}"] = [one(sh)]
        r[f"Elbow{side}"] = [one(el)]
        r[f"Wrist{side}"] = [one(wr)]
        r[f"Hand{side}"] = [[(ix[wr], 1 + HAND_EXTENSION), (ix[el], -HAND_EXTENSION)]]
        r[f"Hip{side}"] = [one(hip)]
        r[f"Knee{side}"] = [one(kn)]
        r[f"Ankle{side}"] = [one(an)]
        if feet:
            r[f"Foot{side}"] = [mean(*feet[side]), one(feet[side][0])]
    return r


_B = _ix(BODY_25)
BODY_25_TO_V1 = _recipe(
    _B, "LHip", "RHip", "MidHip", "Neck", "LShoulder", "RShoulder",
    head_alts=[("LEar", "REar"), ("LEye", "REye"), ("Nose",)],
    sides={"Left": ("LShoulder", "LElbow", "LWrist", "LHip", "LKnee", "LAnkle"),
           "Right": ("RShoulder", "RElbow", "RWrist", "RHip", "RKnee", "RAnkle")},
    feet={"Left": ("LBigToe", "LSmallToe"), "Right": ("RBigToe", "RSmallToe")})

_C = _ix(COCO_17)
COCO_17_TO_V1 = _recipe(
    _C, "left_hip", "right_hip", None, None, "left_shoulder", "right_shoulder",
    head_alts=[("left_ear", "right_ear"), ("left_eye", "right_eye"), ("nose",)],
    sides={"Left": ("left_shoulder", "left_elbow", "left_wrist", "left_hip", "left_knee", "left_ankle"),
           "Right": ("right_shoulder", "right_elbow", "right_wrist", "right_hip", "right_knee", "right_ankle")},
    feet=None)

# Joints that no estimator measures directly: always marked inferred.
SYNTHETIC_V1 = frozenset({"Spine", "HandLeft", "HandRight"})
