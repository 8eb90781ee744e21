"""Map any humanoid armature's bones to Kinect joints from its hierarchy and rest pose (issue 16).

The armature goes through the one structural mapper (structure_mapping.py) as nodes: every bone's head, plus
the tail of each bone without children. Twist and helper bones that hang beside a limb bone as leaves (Unreal's
upperarm_twist_01, Character Creator's UpperarmTwist01) are left out first, since a fork there would look like
a hand; twist bones inside a chain are skipped by the mapper's armature mode. The joints found become a
mapping in the presets' form (bone -> the Kinect joint at the end of the segment the bone follows):

* the pelvis bone (where the spine and legs leave) -> HipCenter; the chest bone (where the arms leave) ->
  ShoulderCenter; the first bone of some length above the pelvis -> Spine; the first bone above the chest ->
  Neck (when it is not the head bone); the head bone -> Head;
* a limb bone whose head is at a joint -> the next joint (upper arm -> Elbow, forearm -> Wrist, hand -> Hand,
  thigh -> Knee, shin -> Ankle, foot -> Foot); the first bone between the chest and the shoulder (clavicle)
  -> Shoulder, between the pelvis and the hip -> Hip.

Every other bone (fingers, toes, face, twist, roll, helpers) stays unmapped. Pure numpy.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .structure_mapping import SHORT, StructureMapping, map_structure

TWIST_PARALLEL = np.cos(np.radians(25))  # a leaf within 25° of its parent's direction...
TWIST_ALONG = (-0.05, 1.1)               # ...lying within the parent bone (head and tail, as fractions of it),
TWIST_HEAD_BEFORE = 0.95                 # its head before the parent's tail, is a twist/helper bone (a head
                                         # bone that continues a neck starts at the neck's tail)
LIMBS = (("Shoulder", "ShoulderCenter"), ("Elbow", "Shoulder"), ("Wrist", "Elbow"), ("Hand", "Wrist"),
         ("Hip", "HipCenter"), ("Knee", "Hip"), ("Ankle", "Knee"), ("Foot", "Ankle"))
FORKS = ("ShoulderCenter", "HipCenter")


@dataclass
class ArmatureMapping:
    mapping: dict[str, str]                  # bone -> Kinect joint (presets' form)
    joints: dict[str, str]                   # Kinect joint -> 'bone (how it was found)', for reports
    notes: list[str] = field(default_factory=list)


def twist_leaves(parents, heads, tails) -> set[int]:
    """Leaf bones lying along their parent bone (or of zero length) beside a sibling that continues the limb."""
    parents = np.asarray(parents)
    has_kids = np.zeros(len(parents), bool)
    has_kids[parents[parents >= 0]] = True
    out = set()
    for b, p in enumerate(parents):
        if p < 0 or has_kids[b]:
            continue
        axis = tails[p] - heads[p]
        length = np.linalg.norm(axis)
        own = tails[b] - heads[b]
        if length <= 0 or np.linalg.norm(own) <= 0:
            out.add(b)  # zero-length helper
            continue
        along = (heads[b] - heads[p]) @ axis / length ** 2
        tail_along = (tails[b] - heads[p]) @ axis / length ** 2
        cos = abs(own @ axis) / (np.linalg.norm(own) * length)
        off = np.linalg.norm(heads[b] - heads[p] - along * axis)
        inside = TWIST_ALONG[0] <= min(along, tail_along) and max(along, tail_along) <= TWIST_ALONG[1]
        if cos >= TWIST_PARALLEL and inside and along < TWIST_HEAD_BEFORE and off < 0.2 * length:
            out.add(b)
    # only beside a sibling that continues the limb (a hand without fingers is a leaf too)
    return {b for b in out if any(s not in out for s in np.flatnonzero(parents == parents[b]))}


def armature_structure(bone_names, parents, heads, tails) -> tuple[StructureMapping, list[int | None]]:
    """The mapper's result for an armature and, per node, the bone whose head it is (None: a leaf's tail)."""
    parents = np.asarray(parents, dtype=np.int64)
    heads, tails = np.asarray(heads, float), np.asarray(tails, float)
    skip = twist_leaves(parents, heads, tails)
    keep = [b for b in range(len(bone_names)) if b not in skip]
    where = {b: i for i, b in enumerate(keep)}

    def kept_parent(b: int) -> int:
        p = int(parents[b])
        while p >= 0 and p not in where:
            p = int(parents[p])
        return where.get(p, -1)

    node_parent = [kept_parent(b) for b in keep]
    has_kids = set(node_parent)
    leaves = [i for i in range(len(keep)) if i not in has_kids]
    names = [bone_names[b] for b in keep] + [f"{bone_names[keep[i]]} (tail)" for i in leaves]
    rest = np.concatenate([heads[keep], tails[[keep[i] for i in leaves]]])
    node_parent += leaves
    ends = np.zeros(len(names), bool)
    ends[len(keep):] = True
    sm = map_structure(names, node_parent, rest, end_site=ends, armature=True)
    return sm, keep + [None] * len(leaves)


def structure_mapping_for(bone_names, parents, heads, tails) -> ArmatureMapping:
    """Bone mapping of an armature from its structure (StructureError when it is no humanoid)."""
    parents = np.asarray(parents, dtype=np.int64)
    lengths = np.linalg.norm(np.asarray(tails, float) - np.asarray(heads, float), axis=1)
    sm, bone_of = armature_structure(bone_names, parents, heads, tails)
    size = float(np.linalg.norm(np.ptp(np.concatenate([heads, tails]), axis=0)))
    role = {r: (bone_of[m.node] if m.node is not None else None) for r, m in sm.roles.items()}
    out: dict[str, str] = {}
    how: dict[str, str] = {}

    def put(bone, joint, why):
        if bone is not None and bone_names[bone] not in out:
            out[bone_names[bone]] = joint
            how[joint] = f"{bone_names[bone]} ({why})"

    def path(top: int | None, below: int | None) -> list[int]:
        """Bones from just below `top` down to `below` (inclusive); [] when `below` is not under `top`."""
        if top is None or below is None:
            return []
        chain = [below]
        while chain[-1] != top:
            p = int(parents[chain[-1]])
            if p < 0:
                return []
            chain.append(p)
        return chain[::-1][1:]

    pelvis, chest, head = role["HipCenter"], role["ShoulderCenter"], role["Head"]
    put(pelvis, "HipCenter", "where the spine and both legs leave")
    spine = [b for b in path(pelvis, chest)[:-1] if lengths[b] >= SHORT * size]
    if spine:
        put(spine[0], "Spine", "first spine bone of some length above the pelvis")
    if chest not in (None, pelvis):
        put(chest, "ShoulderCenter", "where the arms leave the spine")
    neck = path(chest, head)
    if len(neck) > 1:
        put(neck[0], "Neck", "first bone above the chest")
    put(head, "Head", "head bone")

    def between(fork: str, joint: str, side: str) -> list[int]:
        return path(role.get(fork), role.get(joint + side))[:-1]

    for side in ("Left", "Right"):
        for joint, parent in LIMBS:
            top = role.get(parent if parent in FORKS else parent + side)
            if parent in FORKS:  # a bone both sides share (Daz's pelvis) belongs to neither
                other = set(between(parent, joint, "Right" if side == "Left" else "Left"))
                own = [b for b in between(parent, joint, side) if b not in other]
                put(own[0] if own else None, joint + side, f"bone from the {parent} bone to the joint")
            else:
                put(top, joint + side, f"bone whose head is the {parent.lower()} of the {side.lower()} side")
    return ArmatureMapping(out, how, list(sm.notes))
