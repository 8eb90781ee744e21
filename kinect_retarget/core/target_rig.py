"""A target armature as numpy arrays: what the solver needs from a Blender rig, without bpy."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .control_rig_mapping import RigLinks


@dataclass
class TargetRig:
    """bone_names (B,); parents (B,) index or -1; rest (B, 4, 4) armature-space rest matrices
    (Blender's Bone.matrix_local: column 1 of the 3x3 part is the bone's Y axis, head -> tail);
    lengths (B,); object_matrix (4, 4) the armature object's world matrix; inherit_rotation (B,) bool.
    `generated` marks the project's own Kinect rig (root scale n = 1); `links` what else the armature says about
    its bones (deform, custom shapes, constraints), which the structure mapping of control rigs reads."""

    name: str
    bone_names: tuple[str, ...]
    parents: np.ndarray
    rest: np.ndarray
    lengths: np.ndarray
    object_matrix: np.ndarray = field(default_factory=lambda: np.eye(4))
    inherit_rotation: np.ndarray | None = None
    generated: bool = False
    links: RigLinks | None = None

    def __post_init__(self) -> None:
        self.bone_names = tuple(self.bone_names)
        self.parents = np.asarray(self.parents, dtype=np.int64)
        self.rest = np.asarray(self.rest, dtype=np.float64)
        self.lengths = np.asarray(self.lengths, dtype=np.float64)
        self.object_matrix = np.asarray(self.object_matrix, dtype=np.float64)
        if self.inherit_rotation is None:
            self.inherit_rotation = np.ones(len(self.bone_names), dtype=bool)
        self._index = {n: i for i, n in enumerate(self.bone_names)}

    def index(self, bone: str) -> int:
        return self._index[bone]

    def has(self, bone: str) -> bool:
        return bone in self._index

    @property
    def heads(self) -> np.ndarray:
        return self.rest[:, :3, 3]

    @property
    def tails(self) -> np.ndarray:
        return self.heads + self.rest[:, :3, 1] * self.lengths[:, None]

    @property
    def object_rotation(self) -> np.ndarray:
        """Rotation part of the object's world matrix, scale removed."""
        m = self.object_matrix[:3, :3]
        return m / np.linalg.norm(m, axis=0, keepdims=True)

    def ancestors(self, b: int) -> list[int]:
        out = []
        p = int(self.parents[b])
        while p >= 0:
            out.append(p)
            p = int(self.parents[p])
        return out


def evaluate_pose(rig: TargetRig, bone_indices: np.ndarray, quats: np.ndarray,
                  root_bone: int | None = None, root_location: np.ndarray | None = None,
                  locations: dict[int, np.ndarray] | None = None) -> np.ndarray:
    """Forward kinematics like Blender's: posed armature-space matrices (F, B, 4, 4).

    quats (F, M, 4) for the bones `bone_indices`; other bones keep their rest pose; locations {bone: (F, 3)}:
    other keyed locations. Used by benchmarks and tests to check the solver without Blender; the bpy tests
    check Blender itself.
    """
    from .quat import to_matrix

    f = quats.shape[0]
    nb = len(rig.bone_names)
    basis = np.broadcast_to(np.eye(4), (f, nb, 4, 4)).copy()
    basis[:, bone_indices, :3, :3] = to_matrix(quats)
    if root_bone is not None and root_location is not None:
        basis[:, root_bone, :3, 3] = root_location
    for b, loc in (locations or {}).items():  # other keyed locations (root motion's root bone)
        basis[:, b, :3, 3] = loc
    posed = np.empty((f, nb, 4, 4))
    for b in parents_first_order(rig):
        p = rig.parents[b]
        if p < 0:
            posed[:, b] = rig.rest[b] @ basis[:, b]
        else:
            rel = np.linalg.inv(rig.rest[p]) @ rig.rest[b]
            if rig.inherit_rotation[b]:
                posed[:, b] = posed[:, p] @ rel @ basis[:, b]
            else:  # parent moves the head only
                head = (posed[:, p] @ rel)[:, :3, 3]
                posed[:, b] = rig.rest[b] @ basis[:, b]
                posed[:, b, :3, 3] = head + (rig.rest[b][:3, :3] @ basis[:, b, :3, 3, None])[..., 0]
    return posed


def parents_first_order(rig: TargetRig) -> list[int]:
    """Bone indices with every parent before its children."""
    order, seen = [], set()

    def visit(b: int) -> None:
        if b in seen:
            return
        p = int(rig.parents[b])
        if p >= 0:
            visit(p)
        seen.add(b)
        order.append(b)
    for b in range(len(rig.bone_names)):
        visit(b)
    return order
