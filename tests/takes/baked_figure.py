"""Bake a take onto the generated Kinect rig without Blender (the solver and Blender-like forward kinematics)
and measure the figure that comes out: bone directions, heights, upright-ness."""
from __future__ import annotations

import numpy as np

from kinect_retarget.core.conventions import kinect_to_blender
from kinect_retarget.core.kinect_rig_layout import generated_mapping, generated_rig, median_segment_lengths
from kinect_retarget.core.pipeline import RetargetPipeline, RetargetSettings
from kinect_retarget.core.quat import normalize
from kinect_retarget.core.target_rig import evaluate_pose

LIMBS = [(f"{a}{s}", f"{b}{s}") for s in ("Left", "Right") for a, b in
         (("Shoulder", "Elbow"), ("Elbow", "Wrist"), ("Hip", "Knee"), ("Knee", "Ankle"))] + \
        [("HipCenter", "ShoulderCenter"), ("ShoulderCenter", "Head")]


def bake(take):
    """(posed joint positions (F, 20, 3) in Blender space, take sample of each baked frame)."""
    rig = generated_rig(take.skeleton, median_segment_lengths(take))
    pipe = RetargetPipeline(take.skeleton, rig, generated_mapping(take.skeleton), RetargetSettings(filter="none"))
    motion = pipe.process_take(take)
    posed = evaluate_pose(rig, pipe.retargeter.bone_indices, motion.quats, pipe.retargeter.root.index,
                          motion.root_location)
    # the generated rig's bone j ends at joint j: its tail is the joint's baked position
    tails = posed[..., :3, 3] + posed[..., :3, 1] * rig.lengths[None, :, None]
    root = take.skeleton.root
    tails[:, root] = posed[:, root, :3, 3]
    return tails @ rig.object_rotation.T, motion.samples


def limb_direction_errors(joints, samples, reference_take) -> np.ndarray:
    """Degrees between each baked limb and the same limb of the reference take (its source's joints)."""
    sk = reference_take.skeleton
    ref = kinect_to_blender(reference_take.positions[samples])
    errs = []
    for a, b in LIMBS:
        ia, ib = sk.index(a), sk.index(b)
        got = normalize(joints[:, ib] - joints[:, ia])
        want = normalize(ref[:, ib] - ref[:, ia])
        errs.append(np.degrees(np.arccos(np.clip(np.sum(got * want, -1), -1, 1))))
    return np.array(errs)


def heights(joints, skeleton) -> dict:
    """Baked figure: head above pelvis above ankles in every frame, and its head-to-foot height (90th pct)."""
    k = skeleton.index
    z = joints[..., 2]
    feet = np.minimum.reduce([z[:, k(j)] for j in ("AnkleLeft", "AnkleRight", "FootLeft", "FootRight")])
    upright = bool(np.all(z[:, k("Head")] > z[:, k("HipCenter")]) and
                   np.all(z[:, k("HipCenter")] > np.maximum(z[:, k("AnkleLeft")], z[:, k("AnkleRight")])))
    return {"upright": upright, "head_to_foot_m": float(np.percentile(z[:, k("Head")] - feet, 90))}
