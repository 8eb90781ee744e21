"""Correct solved rotations on rigs whose bone parents are driven by constraints or drivers (e.g. Rigify's
MCH parents of its FK controls): numpy cannot evaluate those, so Blender evaluates the pose and each bone's
rotation is corrected toward its desired armature-space rotation, one hierarchy level per pass."""
from __future__ import annotations

import bpy
import numpy as np

from ..core.quat import from_matrix, make_continuous, to_matrix
from ..core.rotation_modes import channel_values

MAX_PASSES = 8
TOLERANCE = np.radians(0.01)


def _set_rotations(pose_bones, bone_names, quats) -> None:
    for name, q in zip(bone_names, quats):
        pb = pose_bones[name]
        suffix, values = channel_values(q, pb.rotation_mode)
        setattr(pb, suffix, values.tolist())


def correct_for_evaluation(obj: bpy.types.Object, bone_names, quats: np.ndarray, root_bone: str | None,
                           root_location: np.ndarray, desired: np.ndarray, progress=None) -> np.ndarray:
    """quats (F, M, 4) solved assuming plain parenting -> corrected quats, frame by frame through Blender."""
    pose_bones = obj.pose.bones
    view_layer = bpy.context.view_layer
    index = [list(pose_bones.keys()).index(n) for n in bone_names]
    nb = len(pose_bones)
    flat = np.empty(nb * 16, dtype=np.float32)
    out = np.array(quats, dtype=np.float64)
    for f in range(out.shape[0]):
        if root_bone is not None:
            pose_bones[root_bone].location = root_location[f].tolist()
        for _ in range(MAX_PASSES):
            _set_rotations(pose_bones, bone_names, out[f])
            obj.update_tag()
            view_layer.update()
            pose_bones.foreach_get("matrix", flat)
            actual = flat.reshape(nb, 4, 4).transpose(0, 2, 1)[index, :3, :3].astype(np.float64)
            actual /= np.linalg.norm(actual, axis=-2, keepdims=True)  # drop any pose scale
            err = np.swapaxes(actual, -1, -2) @ desired[f]             # actual -> desired, in bone space
            basis = to_matrix(out[f]) @ err
            out[f] = from_matrix(basis)
            angle = np.arccos(np.clip((np.trace(err, axis1=-2, axis2=-1) - 1) / 2, -1, 1))
            if angle.max() < TOLERANCE:
                break
        if progress is not None:
            progress(f)
    return make_continuous(out, axis=0)
