"""Live on rigs whose bone parents are driven by constraints or drivers (Rigify's MCH parents of its FK
controls). numpy cannot evaluate those parents; the bake corrects them with several Blender evaluations per
frame, which live cannot afford. Live reads the constrained parents' matrices from the last evaluation
(which the viewport does anyway) and solves every other link analytically, so a still pose is exact after
one evaluation and a moving one lags only by what the constrained parents moved in one frame.
"""
from __future__ import annotations

import numpy as np

from .quat import from_matrix, to_matrix
from .target_rig import TargetRig, parents_first_order


class ConstrainedParentCorrection:
    def __init__(self, rig: TargetRig, bone_names, constrained_bones):
        self.rig = rig
        self.mapped = [rig.index(n) for n in bone_names]
        self.slot = {b: k for k, b in enumerate(self.mapped)}
        needed = set(self.mapped)
        for b in self.mapped:
            needed.update(rig.ancestors(b))
        self.order = [b for b in parents_first_order(rig) if b in needed]
        self.constrained = {rig.index(n) for n in constrained_bones if rig.has(n)} & needed
        rot = rig.rest[:, :3, :3]
        self.rel = {b: (rot[b] if rig.parents[b] < 0 else rot[rig.parents[b]].T @ rot[b]) for b in self.order}
        # bones whose evaluated matrix is read: constrained ones that are not mapped, and their parents
        self.constrained_unmapped = {b for b in self.constrained if b not in self.slot}
        self.read = sorted(self.constrained_unmapped |
                           {int(rig.parents[b]) for b in self.constrained_unmapped if rig.parents[b] >= 0})

    @property
    def active(self) -> bool:
        return bool(self.constrained_unmapped)

    def correct(self, quats: np.ndarray, evaluated: dict, desired: np.ndarray) -> np.ndarray:
        """quats (M, 4) solved for plain parenting -> quats that give the desired rotations under the actual
        parents. evaluated: bone index -> (3, 3) armature-space rotation from the last evaluation; desired:
        (M, 3, 3) matrices or (M, 4) quaternions, from the solver (FramePose.desired)."""
        if np.shape(desired)[-1] == 4:  # the engine hands desired rotations as quaternions
            desired = to_matrix(desired)
        out = np.array(quats, dtype=np.float64)
        actual = {}
        rot = self.rig.rest[:, :3, :3]
        for b in self.order:
            p = int(self.rig.parents[b])
            if b in self.constrained_unmapped:
                # the constraint's result relative to the parent, as last evaluated, carried onto the parent's
                # pose of this frame: exact when the constraint follows the parent chain, one frame late
                # for what it takes from elsewhere
                if p >= 0:
                    actual[b] = actual[p] @ (evaluated[p].T @ evaluated[b])
                else:
                    actual[b] = evaluated[b]
                continue
            frame = rot[b] if p < 0 or not self.rig.inherit_rotation[b] else actual[p] @ self.rel[b]
            if b in self.slot:
                k = self.slot[b]
                out[k] = from_matrix(frame.T @ desired[k])
                actual[b] = desired[k]
            else:
                actual[b] = frame
        return out
