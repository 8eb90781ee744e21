"""Emulated Kinect end to end: rendered depth -> emulated USB -> driver -> tracker -> skeleton frames -> rig."""
from __future__ import annotations

import time

import numpy as np

from kinect_retarget.core.skeletons import NOT_TRACKED


def test_emulated_usb_depth_to_skeleton_frames_to_rig(rendered):
    from kinect_retarget.sim.emulated_kinect import EmulatedKinect
    from kinect_retarget.sources.depth_skeletons import open_skeleton_producer
    seq, _ = rendered
    producer = open_skeleton_producer(EmulatedKinect(list(seq.raw)), gravity=seq.gravity)
    frames = []
    deadline = time.monotonic() + 20
    try:
        while len(frames) < 8 and time.monotonic() < deadline:
            f = producer.read(0.1)
            if f is not None:
                frames.append(f)
    finally:
        producer.close()
    assert len(frames) == 8
    times = [t for _, _, t in frames]
    # device time: whole frame periods (the live queue keeps the newest frame, so a slow machine skips some)
    periods = np.diff(times) * 30.0
    assert times[0] == 0.0 and np.all(periods >= 0.99) and np.allclose(periods, np.round(periods), atol=0.01)
    for positions, states, _ in frames:
        assert positions.shape == (20, 3) and np.all(np.isfinite(positions))
        assert np.all(states != NOT_TRACKED)
    # the stream loops over the rendered frames: the skeletons sit on the performer (hip centre within 15 cm)
    hips = np.array([p[0] for p, _, _ in frames])
    assert np.min(np.linalg.norm(hips[:, None] - seq.joints[None, :, 0], axis=-1), axis=1).max() < 0.15
    mm, mask, pos, st = producer.preview()
    assert mm.shape == (480, 640) and mask is not None and mask.any()
    # and the skeleton frames pose a rig through the engine's live pipeline (what live applies each frame):
    # the posed rig's bones point where the tracked skeleton's bones point
    from kinect_retarget.core.conventions import kinect_to_blender
    from kinect_retarget.core.kinect_rig_layout import generated_mapping, generated_rig
    from kinect_retarget.core.pipeline import RetargetPipeline, RetargetSettings
    from kinect_retarget.core.skeletons import KINECT_V1
    from kinect_retarget.core.target_rig import evaluate_pose
    from kinect_retarget.core.quat import normalize
    lengths = np.median(np.linalg.norm(np.array([p for p, _, _ in frames])[:, 1:]
                                       - np.array([p for p, _, _ in frames])[:, KINECT_V1.parent_array[1:]], axis=-1), 0)
    lengths = np.concatenate([[0.1], lengths])
    rig = generated_rig(KINECT_V1, lengths)
    pipe = RetargetPipeline(KINECT_V1, rig, generated_mapping(KINECT_V1), RetargetSettings(filter="none"))
    poses = [pipe.process_frame(p, s, t) for p, s, t in frames]
    assert all(pose is not None for pose in poses)
    quats = np.array([pose.quats for pose in poses])
    posed = evaluate_pose(rig, pipe.retargeter.bone_indices, quats, pipe.retargeter.root.index,
                          np.array([pose.root_location for pose in poses]))
    p = kinect_to_blender(np.array([f[0] for f in frames]))
    knee, ankle = KINECT_V1.index("KneeLeft"), KINECT_V1.index("AnkleLeft")
    shin = next(m for m in pipe.retargeter.mapped if (m.head, m.tail) == (knee, ankle))
    got = normalize(posed[:, shin.index, :3, 1] @ rig.object_rotation.T)
    want = normalize(p[:, ankle] - p[:, knee])
    assert np.all(np.sum(got * want, -1) > np.cos(np.radians(2)))


def test_preview_image_shows_person_and_skeleton(rendered):
    from kinect_retarget.depth.tracking_preview import preview_rgba
    from kinect_retarget.depth.skeleton_tracker import SkeletonTracker
    seq, _ = rendered
    tr = SkeletonTracker(gravity=seq.gravity)
    pos, st = tr.update(seq.mm[0], 0.0)
    img = preview_rgba(seq.mm[0], tr.last_mask, pos, st)
    assert img.shape == (240, 320, 4) and img.dtype == np.float32
    assert np.all((img >= 0) & (img <= 1))
    yellow = np.all(np.isclose(img[..., :3], [1.0, 0.85, 0.1]), axis=-1)
    assert yellow.sum() > 50                                     # bones and joints drawn
    # the head joint is drawn where it projects (rows bottom-up in Blender images)
    u = (319.5 - 575 * pos[3, 0] / pos[3, 2]) / 2
    v = (239.5 - 575 * pos[3, 1] / pos[3, 2]) / 2
    assert yellow[239 - int(round(v)), int(round(u))]
    empty = preview_rgba(np.zeros((480, 640), np.uint16), None, np.zeros((20, 3)), np.zeros(20, np.uint8))
    assert np.all(empty[..., :3] == 0)
