"""The SDK's joint conventions: what moves, by how much, and that the tracker reports it."""
from __future__ import annotations

import numpy as np

from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.depth import sdk_joints
from kinect_retarget.depth.sdk_joints import to_sdk_joints

J = KINECT_V1.index


def _random_rotation(rng):
    q = rng.normal(size=4)
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def test_every_joint_moves_by_the_stated_amounts(rendered):
    seq, _ = rendered
    mh = seq.joints[:5]
    sdk = to_sdk_joints(mh)
    hips = (mh[:, J("HipLeft")] + mh[:, J("HipRight")]) / 2
    axis = mh[:, J("ShoulderCenter")] - hips
    np.testing.assert_allclose(sdk[:, J("HipCenter")], hips + sdk_joints.HIP_CENTER_UP * axis, atol=1e-12)
    torso = np.linalg.norm(axis, axis=-1)
    up = axis / torso[:, None]
    front = np.cross(mh[:, J("HipLeft")] - mh[:, J("HipRight")], up)
    front /= np.linalg.norm(front, axis=-1, keepdims=True)
    assert np.all(front[:, 2] < 0)   # the rendered performer faces the sensor: the front is toward it
    np.testing.assert_allclose(sdk[:, J("Spine")] - sdk[:, J("HipCenter")],
                               sdk_joints.SPINE_UP * axis - sdk_joints.SPINE_BACK * torso[:, None] * front, atol=1e-12)
    np.testing.assert_allclose(sdk[:, J("ShoulderCenter")] - mh[:, J("ShoulderCenter")],
                               -(sdk_joints.SHOULDER_CENTER_DOWN * axis
                                 + sdk_joints.SHOULDER_CENTER_BACK * torso[:, None] * front), atol=1e-12)
    np.testing.assert_allclose(sdk[:, J("Head")] - mh[:, J("Head")], -sdk_joints.HEAD_DOWN * axis, atol=1e-12)
    width = lambda p, a, b: np.linalg.norm(p[:, J(a)] - p[:, J(b)], axis=-1)
    np.testing.assert_allclose(width(sdk, "HipLeft", "HipRight"),
                               (1 - sdk_joints.HIPS_INWARD) * width(mh, "HipLeft", "HipRight"), rtol=0.02)
    assert np.all(width(sdk, "ShoulderLeft", "ShoulderRight") < width(mh, "ShoulderLeft", "ShoulderRight"))
    left = mh[:, J("HipLeft")] - mh[:, J("HipRight")]
    across = left - np.sum(left * up, axis=-1, keepdims=True) * up
    across /= np.linalg.norm(across, axis=-1, keepdims=True)
    for s, outward in (("Left", 1.0), ("Right", -1.0)):
        # the arm moved out along the upper arm and forward, then shoulder to hand in and down, unchanged in shape
        whole = -(sdk_joints.ARM_INWARD * outward * across + sdk_joints.ARM_DOWN * up) * torso[:, None]
        assert np.all(np.sum(whole * across, axis=-1) * outward < 0) and np.all(np.sum(whole * up, axis=-1) < 0)
        upper = mh[:, J(f"Elbow{s}")] - mh[:, J(f"Shoulder{s}")]
        out = upper / np.linalg.norm(upper, axis=-1, keepdims=True) * (sdk_joints.ARM_OUT * torso)[:, None]
        out += front * (sdk_joints.ARMS_FORWARD * torso)[:, None]
        for n in ("Elbow", "Wrist", "Hand"):
            np.testing.assert_allclose(sdk[:, J(f"{n}{s}")] - mh[:, J(f"{n}{s}")], out + whole, atol=1e-12)
        rise = np.sum((sdk[:, J(f"Knee{s}")] - mh[:, J(f"Knee{s}")]) * up, axis=-1)
        np.testing.assert_allclose(rise, sdk_joints.KNEES_UP * torso, atol=1e-12)
        facing = np.cross(mh[:, J("HipLeft")] - mh[:, J("HipRight")], up)   # the knee goes back, not forward
        assert np.all(np.sum((sdk[:, J(f"Knee{s}")] - mh[:, J(f"Knee{s}")]) * facing, axis=-1) < 0)
        np.testing.assert_allclose(sdk[:, J(f"Foot{s}")] - mh[:, J(f"Foot{s}")],
                                   sdk_joints.FEET_FORWARD * torso[:, None] * front, atol=1e-12)
        hip_forward = np.sum((sdk[:, J(f"Hip{s}")] - mh[:, J(f"Hip{s}")]) * front, axis=-1)
        np.testing.assert_allclose(hip_forward, sdk_joints.HIPS_FORWARD * torso, atol=1e-12)
        shin = mh[:, J(f"Knee{s}")] - mh[:, J(f"Ankle{s}")]   # the ankle goes up its shin and back
        unit = lambda v: v / np.linalg.norm(v, axis=-1, keepdims=True)
        np.testing.assert_allclose(sdk[:, J(f"Ankle{s}")] - mh[:, J(f"Ankle{s}")], torso[:, None] * (
            sdk_joints.ANKLES_UP_SHIN * unit(shin) - sdk_joints.ANKLES_BACK * unit(facing)), atol=1e-12)


def test_the_same_on_a_moved_turned_body_and_the_input_is_left_alone(rendered):
    seq, _ = rendered
    mh = seq.joints[3]
    before = mh.copy()
    rot, shift = _random_rotation(np.random.default_rng(7)), np.array([0.4, -0.2, 1.1])
    np.testing.assert_allclose(to_sdk_joints(mh @ rot.T + shift), to_sdk_joints(mh) @ rot.T + shift, atol=1e-12)
    np.testing.assert_array_equal(mh, before)


def test_the_tracker_reports_the_sdk_hip_centre_not_makehumans(rendered):
    from kinect_retarget.depth.skeleton_tracker import track_depth_frames
    seq, _ = rendered
    take = track_depth_frames(seq.mm, seq.times, gravity=seq.gravity)
    frames = np.arange(take.frame_count)
    hc = take.positions[frames, J("HipCenter")]
    to_sdk = np.linalg.norm(hc - to_sdk_joints(seq.joints[frames])[:, J("HipCenter")], axis=-1).mean()
    to_mh = np.linalg.norm(hc - seq.joints[frames, J("HipCenter")], axis=-1).mean()
    assert to_sdk < 0.05 and to_mh > to_sdk + 0.04, (to_sdk, to_mh)


def _across_line(p, s, direction):
    """The knee's place across its hip-ankle line along `direction` (made perpendicular to the line)."""
    hip, knee, ankle = p[J(f"Hip{s}")], p[J(f"Knee{s}")], p[J(f"Ankle{s}")]
    line = (ankle - hip) / np.linalg.norm(ankle - hip)
    d = direction - (direction @ line) * line
    return (knee - hip) @ (d / np.linalg.norm(d))


def _torso_frame(mh):
    """(torso length, up, front, across toward the performer's left) of one MakeHuman pose (20, 3)."""
    hips = (mh[J("HipLeft")] + mh[J("HipRight")]) / 2
    torso = np.linalg.norm(mh[J("ShoulderCenter")] - hips)
    up = (mh[J("ShoulderCenter")] - hips) / torso
    left = mh[J("HipLeft")] - mh[J("HipRight")]
    front = np.cross(left, up)
    across = left - (left @ up) * up
    return torso, up, front / np.linalg.norm(front), across / np.linalg.norm(across)


def test_a_knee_bent_backward_or_sideways_is_brought_within_the_sdks_range(rendered, monkeypatch):
    seq, _ = rendered
    mh = seq.joints[5].copy()
    torso, up, front, across = _torso_frame(mh)   # the right knee's outward is -across
    bent = mh.copy()
    bent[J("KneeLeft")] -= 0.25 * front      # 25 cm backward
    bent[J("KneeRight")] += 0.03 * across     # 3 cm inward
    far = mh.copy()
    far[J("KneeRight")] -= 0.30 * across      # 30 cm outward
    clamped = {name: to_sdk_joints(p) for name, p in (("plain", mh), ("bent", bent), ("far", far))}
    behind, inward, most = sdk_joints.KNEE_BEHIND_MAX, sdk_joints.KNEE_OUTWARD[0], sdk_joints.KNEE_SIDEWAYS_MOVE
    monkeypatch.setattr(sdk_joints, "KNEE_BEHIND_MAX", np.inf)
    monkeypatch.setattr(sdk_joints, "KNEE_OUTWARD", (-np.inf, np.inf))
    free = {name: to_sdk_joints(p) for name, p in (("plain", mh), ("bent", bent), ("far", far))}
    np.testing.assert_array_equal(clamped["plain"], free["plain"])   # a knee within the range stays
    assert _across_line(free["bent"], "Left", -front) > behind * torso + 0.05
    assert abs(_across_line(clamped["bent"], "Left", -front) - behind * torso) < 1e-9
    assert _across_line(free["bent"], "Right", -across) < inward * torso
    assert abs(_across_line(clamped["bent"], "Right", -across) - inward * torso) < 1e-9
    sideways = np.linalg.norm(clamped["far"][J("KneeRight")] - free["far"][J("KneeRight")])
    assert abs(sideways - most * torso) < 1e-9   # far out: moved that much only
    np.testing.assert_array_equal(np.delete(clamped["far"], [J("KneeRight")], 0),
                                  np.delete(free["far"], [J("KneeRight")], 0))


def test_an_ankle_in_front_of_its_foot_is_moved_back_to_the_sdks_limit(rendered, monkeypatch):
    seq, _ = rendered
    mh = seq.joints[5].copy()
    torso, up, front, _ = _torso_frame(mh)
    ahead = mh.copy()
    ahead[J("AnkleLeft")] = ahead[J("FootLeft")] + 0.10 * front + 0.06 * up   # 10 cm in front of its foot
    limit = sdk_joints.ANKLE_BEFORE_FOOT
    sdk = to_sdk_joints(ahead)
    before = (sdk[J("AnkleLeft")] - sdk[J("FootLeft")]) @ front
    assert abs(before - limit * torso) < 1e-9
    monkeypatch.setattr(sdk_joints, "ANKLE_BEFORE_FOOT", np.inf)
    free = to_sdk_joints(ahead)
    assert (free[J("AnkleLeft")] - free[J("FootLeft")]) @ front > limit * torso + 0.05
    np.testing.assert_array_equal(sdk[J("AnkleRight")], free[J("AnkleRight")])   # one behind its foot stays
    np.testing.assert_allclose(sdk[J("AnkleLeft")] - free[J("AnkleLeft")],
                               -(((free[J("AnkleLeft")] - free[J("FootLeft")]) @ front) - limit * torso) * front,
                               atol=1e-12)   # straight back, nothing else


def test_hips_sunk_to_the_knees_are_lifted_along_the_torso_to_the_sdks_limit(rendered, monkeypatch):
    seq, _ = rendered
    mh = seq.joints[5].copy()
    _, up, _, _ = _torso_frame(mh)
    sunk = mh.copy()   # the pelvis down to the knees' height, as the tracker's upright torso leaves it in a deep bend
    drop = (((mh[J("HipLeft")] + mh[J("HipRight")]) / 2 - mh[J("KneeLeft")]) @ up) * up
    for n in ("HipCenter", "HipLeft", "HipRight", "Spine"):
        sunk[J(n)] -= drop
    torso, up, _, _ = _torso_frame(sunk)
    knees = (sunk[J("KneeLeft")] + sunk[J("KneeRight")]) / 2
    sdk, standing = to_sdk_joints(sunk), to_sdk_joints(mh)
    hips = sdk[J("HipCenter")] - sdk_joints.HIP_CENTER_UP * torso * up   # the hips' midpoint as lifted
    assert abs((hips - knees) @ up - sdk_joints.HIPS_ABOVE_KNEES * torso) < 1e-9
    before = (sunk[J("HipLeft")] + sunk[J("HipRight")]) / 2
    assert np.linalg.norm(np.cross(hips - before, up)) < 1e-9   # straight up the torso
    monkeypatch.setattr(sdk_joints, "HIPS_ABOVE_KNEES", -np.inf)
    free = to_sdk_joints(sunk)
    assert (sdk[J("HipCenter")] - free[J("HipCenter")]) @ up > 0.1
    for n in ("ShoulderCenter", "Head", "AnkleRight", "HandLeft"):   # the pelvis moves, not the rest
        np.testing.assert_allclose(sdk[J(n)], free[J(n)], atol=1e-12)
    np.testing.assert_array_equal(standing, to_sdk_joints(mh))   # standing hips: untouched
