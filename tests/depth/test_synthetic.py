"""The synthetic Kinect: mocap retarget onto MakeHuman, rendering, sensor artefacts, ground truth."""
from __future__ import annotations

import numpy as np

from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.sim.makehuman_body import load_body
from kinect_retarget.sim.bvh_motion import read_bvh_positions
from kinect_retarget.depth.depth_camera import raw_to_mm
from kinect_retarget.device.depth_unpack import NO_READING_RAW
from kinect_retarget.sim.mocap_pose import cmu_points, pose_from_points

J = KINECT_V1.index


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def test_direction_matching_retarget_follows_the_mocap(data_dir):
    body = load_body(str(data_dir / "meshes" / "makehuman"))
    for clip, naming in (("131_03", "max"), ("01_01", "motionbuilder")):
        names, _, pos, _ = read_bvh_positions(data_dir / "mocap_bvh" / f"{clip}.bvh")
        cmu = cmu_points(names, pos[:400:40])
        posed = pose_from_points(body, cmu)
        for a, b, ca, cb in (("ElbowLeft", "WristLeft", "elbow.L", "wrist.L"),
                             ("KneeRight", "AnkleRight", "knee.R", "ankle.R"),
                             ("HipLeft", "KneeLeft", "hip.L", "knee.L")):
            got = _unit(posed.joints[:, J(b)] - posed.joints[:, J(a)])
            want = _unit(cmu[cb] - cmu[ca])
            assert np.degrees(np.arccos(np.clip(np.sum(got * want, -1), -1, 1))).max() < 1.0, (clip, a, b)
        # the MakeHuman proportions are kept: bone lengths do not change over the motion
        shin = np.linalg.norm(posed.joints[:, J("AnkleLeft")] - posed.joints[:, J("KneeLeft")], axis=-1)
        assert np.ptp(shin) < 1e-9
        # skinning moves the skin with the bones: the left hand's skin follows the left wrist
        verts = posed.vertices(body, slice(0, 3))
        assert verts.shape == (3, len(body.rest_vertices), 3) and np.all(np.isfinite(verts))


def test_rendered_frames_are_kinect_like(rendered, camera):
    seq, _ = rendered
    assert seq.raw.shape == (12, 480, 640) and seq.raw.dtype == np.uint16
    assert np.array_equal(seq.mm, raw_to_mm(seq.raw))                      # the driver's own conversion
    assert np.all((seq.raw < 1100) | (seq.raw == NO_READING_RAW))
    # ground truth sits inside the body: each torso joint is behind the depth seen at its pixel
    for j in ("HipCenter", "Spine", "ShoulderCenter", "Head"):
        p = seq.joints[:, J(j)]
        u = np.round(camera.cx - camera.f * p[:, 0] / p[:, 2]).astype(int)
        v = np.round(camera.cy - camera.f * p[:, 1] / p[:, 2]).astype(int)
        surface = seq.mm[np.arange(len(p)), v, u] / 1000.0
        assert np.all(surface > 0) and np.all((p[:, 2] - surface > -0.01) & (p[:, 2] - surface < 0.2)), j
    # the projector's shadow: a band without readings beside the body, on the image side away from it
    frame = seq.raw[0]
    hip = seq.joints[0, J("HipCenter")]
    row = int(round(camera.cy - camera.f * hip[1] / hip[2]))
    line = frame[row]
    mm = raw_to_mm(line) / 1000.0
    body = np.flatnonzero((mm > 0) & (mm < hip[2] + 0.3))
    left_edge = body.min()
    assert np.all(line[left_edge - 4:left_edge] == NO_READING_RAW)         # shadow cast to the image left
    # distance: the performer stays in the Kinect's working range
    assert np.all((seq.joints[..., 2] > 1.4) & (seq.joints[..., 2] < 3.6))
