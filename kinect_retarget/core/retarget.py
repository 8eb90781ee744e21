"""Parent-relative bone rotations and root motion for a target rig (paper 000, §2.4–2.5, eq. 10–13).

For every mapped bone b, with source joint frame O_s(t) (joint_frames.py) and the frame O_t the same rules
give on the target's rest pose:

    desired armature-space rotation   D_b(t) = O_s(t) · O_tᵀ · R_rest(b)                      (eq. 11)
    pose-bone rotation                Q_b(t) = (P_parent(t) · R_rel(b))ᵀ · D_b(t)           (eq. 12)

O_s(t)·O_tᵀ is the paper's bone rotation matrix between two configurations (the target rest pose standing in
for the paper's fixed initial pose, §2.2), so the bone's Y axis points exactly along the performer's segment
and its twist follows the joint frame. Everything is computed from the rig's rest matrices; the rig itself
is never changed. The root bone's head follows the root joint's displacement times n (eq. 13).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, overload

import numpy as np

from .conventions import KINECT_TO_BLENDER
from .joint_frames import ALIASES, frame_axes, frame_from_y_hint, resolver, role_and_side, segment_hint
from .quat import conjugate, from_axes, from_matrix, mul, rotate
from .skeletons import Skeleton
from .target_rig import TargetRig

ROOT_MODES = ("xyz", "xy", "none")
AXIAL_ROLES = ("pelvis", "spine", "chest", "neck", "head")  # segments that point up on any rest humanoid
COS_ALONG_SEGMENT = 0.5  # an axial bone more than 60° off vertical at rest is a control, not a segment


@dataclass(frozen=True)
class MappedBone:
    bone: str
    index: int      # in the target rig
    head: int       # source joint indices of the segment
    tail: int
    tail_name: str  # canonical role lookup name (source skeleton's joint name)
    is_root: bool


def resolve_joint(skeleton: Skeleton, name: str) -> int:
    for alias in ALIASES.get(name, (name,)):
        if alias in skeleton.joints:
            return skeleton.index(alias)
    for canonical, aliases in ALIASES.items():  # a v2 name asked of a v1 skeleton
        if name in aliases and canonical in skeleton.joints:
            return skeleton.index(canonical)
    raise KeyError(name)


def resolve_mapping(skeleton: Skeleton, rig: TargetRig, mapping: dict[str, str]) -> list[MappedBone]:
    """mapping: target bone -> source joint spec: 'ElbowLeft' (segment from the joint's parent to it),
    'ShoulderLeft>ElbowLeft' (explicit head>tail), or the root joint's name for the pelvis/root bone.
    Bones absent from the rig and joints absent from the skeleton are skipped (left alone)."""
    out = []
    for bone, spec in mapping.items():
        if not spec or not rig.has(bone):
            continue
        try:
            if ">" in spec:
                head, tail = (resolve_joint(skeleton, s.strip()) for s in spec.split(">"))
            else:
                tail = resolve_joint(skeleton, spec)
                head = skeleton.parents[tail]
        except KeyError:
            continue
        is_root = head == -1
        if is_root:  # pelvis frame: up toward the first spine joint, twist from the hips
            head, tail = tail, resolve_joint(skeleton, "Spine")
        tail_name = skeleton.joints[head] if is_root else skeleton.joints[tail]
        out.append(MappedBone(bone, rig.index(bone), head, tail, tail_name, is_root))
    return out


def is_axial_control(m: MappedBone, rig: TargetRig, up: np.ndarray) -> bool:
    """A spine/neck/head bone that does not lie along its segment at rest (Rigify's torso and chest
    controls rest horizontal): its head and tail are not joint positions."""
    axial = m.is_root or role_and_side(m.tail_name)[0] in AXIAL_ROLES
    return axial and float(rig.rest[m.index, :3, 1] @ up) < COS_ALONG_SEGMENT


def target_joint_positions(skeleton: Skeleton, rig: TargetRig, mapped: list[MappedBone],
                           up: np.ndarray) -> np.ndarray:
    """Estimated rest positions of the source joints on the target (armature space), NaN where unknown.
    Tails of mapped bones first, heads fill the rest (a thigh's head is the hip joint); control bones that
    do not lie along their segment say nothing about joints."""
    pos = np.full((len(skeleton), 3), np.nan)
    usable = [m for m in mapped if not is_axial_control(m, rig, up)]
    for m in usable:
        if not m.is_root:
            pos[m.tail] = rig.tails[m.index]
    for m in usable:
        if np.isnan(pos[m.head, 0]):
            pos[m.head] = rig.heads[m.index]
    return pos


def rest_leg_length(rig: TargetRig, mapped: list[MappedBone]) -> float | None:
    """The rig's hip->knee + knee->ankle (mean of both sides) from the heads of the thigh, shin and foot bones:
    a limb bone's head sits at its joint even where twist bones split the limb (MakeHuman's upperleg01 ends a
    fifth of the way to the knee, so its tail is no knee)."""
    by_joint = {m.tail_name: m.index for m in mapped}
    lengths = []
    for side in ("Left", "Right"):
        thigh, shin, foot = (by_joint.get(j + side) for j in ("Knee", "Ankle", "Foot"))
        if thigh is None or shin is None:
            continue
        ankle = rig.heads[foot] if foot is not None else rig.tails[shin]
        lengths.append(float(np.linalg.norm(rig.heads[shin] - rig.heads[thigh])
                             + np.linalg.norm(ankle - rig.heads[shin])))
    return float(np.mean(lengths)) if lengths else None


def leg_length(get) -> float | None:
    """Mean of left and right hip->knee + knee->ankle lengths (median over frames), or None."""
    lengths = []
    for side in ("Left", "Right"):
        hip, knee, ankle = get("Hip" + side), get("Knee" + side), get("Ankle" + side)
        if hip is None or knee is None or ankle is None:
            continue
        seg = np.linalg.norm(knee - hip, axis=-1) + np.linalg.norm(ankle - knee, axis=-1)
        seg = seg[np.isfinite(seg)]
        if seg.size:
            lengths.append(float(np.median(seg)))
    return float(np.mean(lengths)) if lengths else None


class Retargeter:
    """Solves pose-bone quaternions for mapped bones of one rig, batched over frames."""

    def __init__(self, skeleton: Skeleton, rig: TargetRig, mapping: dict[str, str], *, root_mode: str = "xyz",
                 root_scale: float | None = None):
        if root_mode not in ROOT_MODES:
            raise ValueError(f"root mode must be one of {ROOT_MODES}, got {root_mode!r}")
        self.skeleton, self.rig, self.root_mode = skeleton, rig, root_mode
        self.mapped = resolve_mapping(skeleton, rig, mapping)
        if not self.mapped:
            raise ValueError(f"no bone of armature {rig.name!r} is mapped to a {skeleton.name} joint: "
                             "wrong armature or preset?")
        self.bone_indices = np.array([m.index for m in self.mapped])
        self.bone_names = tuple(m.bone for m in self.mapped)
        roots = [m for m in self.mapped if m.is_root]
        self.root = roots[0] if roots else None
        self.arm_from_kinect = rig.object_rotation.T @ KINECT_TO_BLENDER
        # the character's own left and up in armature space, for hints when a joint is missing
        self.world_lateral = rig.object_rotation.T @ np.array([1.0, 0.0, 0.0])
        self.world_up = rig.object_rotation.T @ np.array([0.0, 0.0, 1.0])
        tpos = target_joint_positions(skeleton, rig, self.mapped, self.world_up)
        get_t = _drop_unknown(resolver(skeleton.joints, tpos))
        self.target_leg = rest_leg_length(rig, self.mapped) or leg_length(get_t)
        # the target's rest frame O_t per bone (eq. 11 uses O_tᵀ · R_rest(b))
        self.rest_frames = np.empty((len(self.mapped), 3, 3))
        for k, m in enumerate(self.mapped):
            y = rig.rest[m.index, :3, 1]
            if is_axial_control(m, rig, self.world_up):
                # the segment such a control drives points up in the rest pose (paper §2.2), whatever the
                # bone's own axis; the control turns with it rigidly
                y = self.world_up
            hint = segment_hint(get_t, m.tail_name, y, self.world_lateral, self.world_up)
            o_t = frame_from_y_hint(y, np.nan_to_num(hint))
            self.rest_frames[k] = o_t
        self._chain_plan()
        self.rest_q = from_matrix(rig.rest[self.bone_indices, :3, :3])
        self.root_scale = root_scale

    def _chain_plan(self) -> None:
        """For each mapped bone: the nearest mapped ancestor (or -1) and the fixed rotation S between that
        ancestor's posed frame and this bone's parent frame (rest-relative rotations of unmapped bones in
        between; the bone's own rest-relative rotation included). Then frame_rot(b) = D[ancestor] · S."""
        rig = self.rig
        slot = {m.index: k for k, m in enumerate(self.mapped)}
        self.anchor = np.full(len(self.mapped), -1)
        self.static = np.empty((len(self.mapped), 3, 3))
        for k, m in enumerate(self.mapped):
            b = m.index
            if not rig.inherit_rotation[b]:  # rotation ignores the parent: rest orientation only
                self.static[k] = rig.rest[b, :3, :3]
                continue
            chain = np.eye(3)
            child, p = b, int(rig.parents[b])
            while p >= 0 and p not in slot:
                chain = rig.rest[p, :3, :3].T @ rig.rest[child, :3, :3] @ chain
                child = p
                if not rig.inherit_rotation[p]:  # p keeps its rest orientation: the chain starts there
                    break
                p = int(rig.parents[p])
            if p >= 0 and p in slot:
                self.anchor[k] = slot[p]
                self.static[k] = rig.rest[p, :3, :3].T @ rig.rest[child, :3, :3] @ chain
            else:  # reached the top: armature space
                self.static[k] = rig.rest[child, :3, :3] @ chain
        self.has_anchor = self.anchor >= 0
        self.static_q = from_matrix(self.static)

    def scale_for(self, source_leg: float | None) -> float:
        """Root scale n (eq. 13): target leg / source leg, unless fixed."""
        if self.root_scale is not None:
            return float(self.root_scale)
        if self.rig.generated or not source_leg or not self.target_leg:
            return 1.0
        return self.target_leg / source_leg

    @overload
    def solve(self, positions: np.ndarray, root_reference: np.ndarray | None = ...,
              source_leg: float | None = ..., want_desired: Literal[False] = ...) -> tuple[np.ndarray, np.ndarray]: ...

    @overload
    def solve(self, positions: np.ndarray, root_reference: np.ndarray | None = ...,
              source_leg: float | None = ..., *,
              want_desired: Literal[True]) -> tuple[np.ndarray, np.ndarray, np.ndarray]: ...

    def solve(self, positions: np.ndarray, root_reference: np.ndarray | None = None,
              source_leg: float | None = None, want_desired: bool = False):
        """positions (F, J, 3) Kinect camera space -> quats (F, M, 4) for self.bone_names, and the root bone's
        pose location (F, 3) (zeros without a mapped root). root_reference: Kinect position of the root joint
        that maps to the rest position (the take's first keyed frame). With want_desired, also the desired
        armature-space bone rotations (F, M, 4), for rigs whose constraints need Blender's evaluation."""
        # joint-major layout (J, F, 3): every per-joint slice below is contiguous, which numpy handles fastest
        p = np.ascontiguousarray(np.swapaxes(np.asarray(positions, dtype=np.float64) @ self.arm_from_kinect.T, 0, 1))
        nframes = p.shape[1]
        get = resolver(self.skeleton.joints, p, joint_axis=0)
        cache: dict = {}
        y = np.stack([p[m.tail] - p[m.head] for m in self.mapped])                    # (M, F, 3)
        hints = np.stack([segment_hint(get, m.tail_name, y[k], self.world_lateral, self.world_up, cache)
                          for k, m in enumerate(self.mapped)])
        # eq. 11 as (O_s · O_tᵀ) · R_rest: the first factor is the segment's turn away from the rest pose, a
        # moderate rotation whose quaternion comes from the cheap trace formula; its columns are sums of O_s's
        # axes with constant weights. Quaternion products then beat stacks of 3x3 matrix products.
        x, y_axis, z = frame_axes(y, hints)
        o_t = self.rest_frames[:, None, :, None, :]  # (M, 1, row, 1, col) broadcasts against (M, F, 3)
        turn = [x * o_t[:, :, j, :, 0] + y_axis * o_t[:, :, j, :, 1] + z * o_t[:, :, j, :, 2] for j in range(3)]
        desired = mul(from_axes(*turn), self.rest_q[:, None])                       # (M, F, 4), eq. 11
        frame_rot = np.broadcast_to(self.static_q[:, None], desired.shape).copy()
        if self.has_anchor.any():
            frame_rot[self.has_anchor] = mul(desired[self.anchor[self.has_anchor]],
                                             self.static_q[self.has_anchor, None])
        quats = np.swapaxes(mul(conjugate(frame_rot), desired), 0, 1)                   # (F, M, 4), eq. 12
        location = np.zeros((nframes, 3))
        if self.root is not None and self.root_mode != "none" and nframes:
            ref = p[self.root.head, 0] if root_reference is None else root_reference @ self.arm_from_kinect.T
            delta = (p[self.root.head] - ref) * self.scale_for(source_leg)
            if self.root_mode == "xy":
                delta -= np.outer(delta @ self.world_up, self.world_up)
            k = self.mapped.index(self.root)
            location = rotate(conjugate(frame_rot[k]), delta)
        if want_desired:
            desired = np.swapaxes(desired, 0, 1)
        return (quats, location, desired) if want_desired else (quats, location)


def _drop_unknown(get):
    """Wrap a joint lookup so joints with NaN positions count as absent."""
    def inner(name):
        v = get(name)
        return None if v is None or np.isnan(v).any() else v
    return inner
