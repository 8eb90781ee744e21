"""Correct solved rotations on rigs whose bone parents are driven by constraints or drivers (e.g. Rigify's
MCH parents of its FK controls): numpy cannot evaluate those, so Blender evaluates the pose and each bone's
rotation is corrected toward its desired armature-space rotation (a few evaluations per frame)."""
from __future__ import annotations

import bpy
import numpy as np

from ...core.quat import from_matrix, make_continuous, to_matrix
from .pose_apply import set_rotations

MAX_PASSES = 8
TOLERANCE = np.radians(0.05)  # residual (sin of the angle) accepted per bone


def _mapped_ancestors(pose_bones, bone_names) -> tuple[list[int], list[int]]:
    """Nearest mapped ancestor of each mapped bone (-1 for none), and an order with ancestors first."""
    slot = {n: k for k, n in enumerate(bone_names)}
    anchor, depth = [], []
    for name in bone_names:
        pb, d, a = pose_bones[name].parent, 0, -1
        while pb is not None:
            if pb.name in slot:
                a = slot[pb.name] if a < 0 else a
                d += 1
            pb = pb.parent
        anchor.append(a)
        depth.append(d)
    return anchor, sorted(range(len(bone_names)), key=lambda k: depth[k])


def read_rotations(pose_bones, index, flat: np.ndarray) -> np.ndarray:
    """Armature-space 3x3 rotations of the pose bones at `index`, as Blender last evaluated them (one bulk
    read into `flat`, a float32 buffer of 16 per pose bone; pose scale dropped)."""
    pose_bones.foreach_get("matrix", flat)
    # foreach_get flattens each 4x4 column by column
    m = flat.reshape(-1, 4, 4)[index, :3, :3].transpose(0, 2, 1).astype(np.float64)
    m /= np.linalg.norm(m, axis=-2, keepdims=True)  # drop any pose scale
    return m


def correct_for_evaluation(obj: bpy.types.Object, bone_names, quats: np.ndarray, root_bone: str | None,
                           root_location: np.ndarray, desired: np.ndarray, progress=None) -> np.ndarray:
    """quats (F, M, 4) solved assuming plain parenting, desired (F, M, 4) armature-space rotations ->
    corrected quats, frame by frame through Blender.

    Each evaluation corrects every bone top-down, predicting how a correction of an ancestor turns its
    descendants, so a pass usually lands within tolerance and a second evaluation confirms it."""
    pose_bones = obj.pose.bones
    view_layer = bpy.context.view_layer
    keys = list(pose_bones.keys())
    index = [keys.index(n) for n in bone_names]
    anchor, order = _mapped_ancestors(pose_bones, bone_names)
    nb = len(pose_bones)
    flat = np.empty(nb * 16, dtype=np.float32)
    out = np.array(quats, dtype=np.float64)
    plain = to_matrix(out)
    carry = np.broadcast_to(np.eye(3), plain.shape[1:]).copy()  # last frame's correction, a warm start
    for f in range(out.shape[0]):
        if root_bone is not None:
            pose_bones[root_bone].location = root_location[f].tolist()
        basis = plain[f] @ carry
        wanted = to_matrix(desired[f])
        for _ in range(MAX_PASSES):
            set_rotations(pose_bones, bone_names, from_matrix(basis))
            obj.update_tag()
            view_layer.update()
            actual = read_rotations(pose_bones, index, flat)
            turned = np.empty_like(actual)  # world change each bone receives this pass
            worst = 0.0
            for k in order:
                a = anchor[k]
                predicted = turned[a] @ actual[k] if a >= 0 else actual[k]
                err = predicted.T @ wanted[k]  # predicted -> desired, in bone space
                # sin of the residual angle from the skew part: exact near zero, unlike arccos of the trace
                worst = max(worst, np.linalg.norm([err[2, 1] - err[1, 2], err[0, 2] - err[2, 0],
                                                   err[1, 0] - err[0, 1]]) / 2)
                basis[k] = basis[k] @ err
                turned[k] = wanted[k] @ actual[k].T
            if worst < TOLERANCE:
                break
        out[f] = from_matrix(basis)
        carry = np.swapaxes(plain[f], -1, -2) @ basis
        if progress is not None:
            progress(f)
    return make_continuous(out, axis=0)
