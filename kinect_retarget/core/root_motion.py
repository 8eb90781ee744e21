"""Root motion for game engines (issue 16): the performer's horizontal travel (and optionally facing) moves
from the hips onto the rig's root bone (Unreal's and Rigify's `root`, at the floor, an ancestor of the hips),
the hips keyed relative to it, so an engine can read the travel from the root while the pose in the world
stays exactly what the bake gave.

With the root bone R (rest matrix C) moved by an armature-space rigid motion A(t) (a turn about the up axis
through R's head and a horizontal shift), R's pose basis is C⁻¹·A·C, and the hips' basis becomes
H⁻¹·A⁻¹·H·B(t) (H: the hips' rest matrix, B: their baked basis), valid because the bones between R and the
hips are not posed (checked). Every other mapped bone is keyed relative to its parent and is untouched.
Pure numpy.
"""
from __future__ import annotations

import numpy as np

from .quat import from_matrix, make_continuous, to_matrix
from .target_rig import TargetRig

FACING_FORWARD = np.array([0.0, -1.0, 0.0])  # a character faces -Y in Blender (docs/conventions.md)


class RootMotionError(ValueError):
    """The rig has no bone that can carry root motion (message says why)."""


def find_root_bone(rig: TargetRig, hips: int, named: str | None = None, constrained: bool = False) -> int:
    """The bone to carry root motion: `named`, else the top ancestor of the hips bone. constrained: `named`
    may be a bone the hips follow through constraints (the caller verifies that they do)."""
    if named:
        if not rig.has(named):
            raise RootMotionError(f"root motion: the armature has no bone named {named!r}")
        root = rig.index(named)
        if root not in rig.ancestors(hips) and not constrained:
            raise RootMotionError(f"root motion: {named!r} is not an ancestor of the hips bone "
                                  f"{rig.bone_names[hips]!r} (a rig whose hips follow the root by constraints, "
                                  "as Rigify's, needs Blender's check: bake it in Blender)")
        return root
    above = rig.ancestors(hips)
    if not above:
        raise RootMotionError(f"root motion needs a root bone above the hips, and {rig.bone_names[hips]!r} "
                              "has no parent (rigs like Unreal's Mannequin or Rigify have one named 'root')")
    return above[-1]


def followed_root(rig: TargetRig, hips: str | None) -> str | None:
    """The root a control rig's hips follow by constraints, found without names (rig.links): from the hips'
    top ancestor through Armature, Child Of or full Copy Transforms constraints reading one bone (Rigify: torso
    -> MCH-torso.parent -> its Armature constraint -> root). None when there is no such bone."""
    if rig.links is None or hips is None or not rig.has(hips):
        return None
    b, seen = rig.index(hips), set()
    while b not in seen:
        seen.add(b)
        b = ([b] + rig.ancestors(b))[-1]
        follows = [c.targets[0] for c in rig.links.constraints[b] if len(c.targets) == 1 and c.influence >= 0.999
                   and c.kind in ("ARMATURE", "CHILD_OF", "COPY_TRANSFORMS")]
        if not follows:
            return rig.bone_names[b] if len(seen) > 1 else None
        b = follows[0]
    return None


def _basis(quats: np.ndarray, location: np.ndarray) -> np.ndarray:
    m = np.broadcast_to(np.eye(4), quats.shape[:-1] + (4, 4)).copy()
    m[..., :3, :3] = to_matrix(quats)
    m[..., :3, 3] = location
    return m


def _yaw(rot: np.ndarray, up: np.ndarray, forward: np.ndarray) -> np.ndarray:
    """Heading (radians, about `up`, unwrapped) of `forward` turned by the rotations rot (F, 3, 3)."""
    f = rot @ forward
    side = np.cross(up, forward)
    return np.unwrap(np.arctan2(f @ side, f @ forward))


def _about_up(angle: np.ndarray, up: np.ndarray) -> np.ndarray:
    """(F, 3, 3) rotations by `angle` about the unit axis `up` (Rodrigues)."""
    k = np.array([[0, -up[2], up[1]], [up[2], 0, -up[0]], [-up[1], up[0], 0]])
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3) + s * k + (1 - c) * (k @ k)


def transfer_root_motion(rig: TargetRig, root: int, hips: int, hips_quats: np.ndarray, hips_location: np.ndarray,
                         facing: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(root quats (F, 4), root location (F, 3), hips quats, hips location): the root bone carries the hips'
    horizontal travel from their rest place (and their heading about the up axis with `facing`); the hips'
    pose basis compensates, so the hips (and all below) stay where they were in the armature."""
    up = rig.object_rotation.T @ np.array([0.0, 0.0, 1.0])
    forward = rig.object_rotation.T @ FACING_FORWARD
    hips_rest, root_rest = rig.rest[hips], rig.rest[root]
    posed = hips_rest @ _basis(hips_quats, hips_location)             # (F, 4, 4): R and between are at rest
    travel = posed[:, :3, 3] - hips_rest[:3, 3]
    travel -= np.outer(travel @ up, up)
    turn = _about_up(_yaw(posed[:, :3, :3] @ hips_rest[:3, :3].T, up, forward), up) if facing else \
        np.broadcast_to(np.eye(3), (len(travel), 3, 3))
    a = np.broadcast_to(np.eye(4), (len(travel), 4, 4)).copy()          # A: turn about R's head, then travel
    pivot = root_rest[:3, 3]
    a[:, :3, :3] = turn
    a[:, :3, 3] = pivot - turn @ pivot + travel
    root_basis = np.linalg.inv(root_rest) @ a @ root_rest
    hips_basis = np.linalg.inv(hips_rest) @ np.linalg.inv(a) @ posed
    root_q = make_continuous(from_matrix(root_basis[:, :3, :3]), axis=0)
    hips_q = make_continuous(from_matrix(hips_basis[:, :3, :3]), axis=0)
    return root_q, root_basis[:, :3, 3], hips_q, hips_basis[:, :3, 3]


def chain_is_free(rig: TargetRig, root: int, hips: int, posed_bones) -> str | None:
    """None when the bones from the root down to the hips can carry root motion, else why not: a posed bone
    between them, or one that does not inherit its parent's rotation."""
    chain, b = [], hips
    while b != root:
        chain.append(b)
        b = int(rig.parents[b])
    posed = set(posed_bones)
    for b in chain[1:]:
        if b in posed:
            return f"{rig.bone_names[b]!r} between the root bone and the hips is keyed"
    for b in chain:
        if not rig.inherit_rotation[b]:
            return f"{rig.bone_names[b]!r} does not inherit its parent's rotation"
    return None


def root_follows_by_constraints(rig: TargetRig, motion, named: str | None) -> bool:
    """True when the root bone `named` is not an ancestor of the mapped hips (Rigify's root and torso)."""
    if not named or motion.root_bone is None or not rig.has(named) or not rig.has(motion.root_bone):
        return False
    return rig.index(named) not in rig.ancestors(rig.index(motion.root_bone))


def apply_root_motion(motion, rig: TargetRig, facing: bool = False, named: str | None = None,
                      verify=None) -> str:
    """Move a BakedMotion's travel onto the root bone in place: the root bone joins motion.bone_names (its
    rotation keys) and motion.extras['locations'] (its location keys); the hips' keys compensate. Returns a
    sentence for the bake report.

    verify: for a root bone the hips follow through constraints, a callable (root, hips) -> None when
    Blender's evaluation shows the hips moving rigidly with the root, else why not. The root's desired
    rotation then joins motion.extras['desired'], and the caller runs the constrained solve afterwards."""
    if motion.root_bone is None:
        raise RootMotionError("root motion: no bone is mapped to the hips (the root joint)")
    hips = rig.index(motion.root_bone)
    root = find_root_bone(rig, hips, named, constrained=verify is not None)
    name = rig.bone_names[root]
    if name in motion.bone_names:
        raise RootMotionError(f"root motion: the root bone {name!r} is itself mapped to a joint")
    k = motion.bone_names.index(motion.root_bone)
    hips_quats = motion.quats[:, k]
    if root in rig.ancestors(hips):
        why = chain_is_free(rig, root, hips, [rig.index(b) for b in motion.bone_names])
    else:
        assert verify is not None  # find_root_bone refused this root otherwise
        why = verify(root, hips)
        # with the root at rest the hips' frame is their rest (verified): their pose rotation is Hᵀ·desired
        hips_quats = from_matrix(rig.rest[hips, :3, :3].T @ to_matrix(motion.extras["desired"][:, k]))
    if why:
        raise RootMotionError(f"root motion cannot use {name!r}: {why}")
    root_q, root_loc, hips_q, hips_loc = transfer_root_motion(rig, root, hips, hips_quats, motion.root_location,
                                                              facing)
    if root not in rig.ancestors(hips):  # the root's armature-space rotation, for the constrained solve after this
        root_desired = from_matrix(rig.rest[root, :3, :3] @ to_matrix(root_q))
        motion.extras["desired"] = np.concatenate([motion.extras["desired"], root_desired[:, None]], axis=1)
    motion.quats = np.concatenate([motion.quats, root_q[:, None]], axis=1)
    motion.quats[:, k] = hips_q
    motion.root_location = hips_loc
    motion.bone_names = tuple(motion.bone_names) + (name,)
    motion.extras.setdefault("locations", {})[name] = root_loc
    travel = float(np.linalg.norm(root_loc[-1] - root_loc[0]))
    return f"root motion on {name!r}" + (" with facing" if facing else "") + f" ({travel:.2f} m start to end)"
