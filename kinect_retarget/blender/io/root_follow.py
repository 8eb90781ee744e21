"""Root motion on a rig whose hips follow the root bone through constraints (issue 16): Rigify's `torso`
hangs from MCH-torso.parent, which follows `root` through an Armature constraint at full weight.

Root motion there is exact only if the hips move rigidly with the root: posing the root by the
armature-space motion A (its evaluated matrix times its rest inverse) must move the hips to A·H·basis (H: the
hips' rest matrix), a constant offset at full influence, and with the root at rest the hips sit at H·basis.
This module checks exactly that on Blender's evaluation of an armature-only copy (issue 15's
ArmatureEvaluator), at random root and hips poses; core/root_motion.py then does the rest.
"""
from __future__ import annotations

import numpy as np

from ...core.parent_model import IDENTITY
from ...core.quat import angle_between, from_matrix
from ...core.target_rig import TargetRig
from .armature_probe import MAX_ANGLE, ArmatureEvaluator, random_rotations
from .pose_apply import set_rotations

SAMPLES = 8             # the first with the root at rest
TOLERANCE_M = 1e-5      # Blender evaluates in float32: about 1e-7 m at a metre
TOLERANCE_DEG = 1e-3


def _rotation(m: np.ndarray) -> np.ndarray:
    r = m[:3, :3] / np.linalg.norm(m[:3, :3], axis=0)
    return from_matrix(r)


def root_follow_problem(obj, rig: TargetRig, root: int, hips: int, seed: int = 0) -> str | None:
    """None when Blender moves the hips rigidly with the root bone (constant offset, full influence; at
    the hips' rest when the root is at rest), else a sentence saying what was found. The user's rig is not
    evaluated or changed: only a temporary armature-only copy."""
    root_name, hips_name = rig.bone_names[root], rig.bone_names[hips]
    rng = np.random.default_rng(seed)
    worst_m = worst_deg = 0.0
    with ArmatureEvaluator(obj, rig.bone_names) as ev:
        pose_bones = ev.copy.pose.bones
        for s in range(SAMPLES):
            root_q = IDENTITY if s == 0 else random_rotations(rng, 1, np.pi)[0]
            hips_q = random_rotations(rng, 1, MAX_ANGLE)[0]
            set_rotations(pose_bones, (root_name, hips_name), np.stack([root_q, hips_q]))
            pose_bones[root_name].location = (0.0, 0.0, 0.0) if s == 0 else rng.normal(0, 0.5, 3).tolist()
            pose_bones[hips_name].location = rng.normal(0, 0.2, 3).tolist()
            ev.copy.update_tag()
            ev.depsgraph.update()
            done = ev.copy.evaluated_get(ev.depsgraph).pose.bones
            root_m = np.array(done[root_name].matrix)
            keyed = rig.rest[root] @ np.array(pose_bones[root_name].matrix_basis)
            moved = root_m @ np.linalg.inv(rig.rest[root])   # the root's armature-space motion A
            want = moved @ rig.rest[hips] @ np.array(pose_bones[hips_name].matrix_basis)
            for got, goal in ((root_m, keyed), (np.array(done[hips_name].matrix), want)):
                worst_m = max(worst_m, float(np.linalg.norm(got[:3, 3] - goal[:3, 3])))
                worst_deg = max(worst_deg, float(np.degrees(angle_between(_rotation(got), _rotation(goal)))))
    if worst_m <= TOLERANCE_M and worst_deg <= TOLERANCE_DEG:
        return None
    return (f"its hips {hips_name!r} do not move rigidly with it in Blender's evaluation (up to "
            f"{worst_m * 1000:.3f} mm and {worst_deg:.4f}° from a constant offset at full influence; a parent "
            "switch not set to the root, or constraints on the root or the hips, do this)")
