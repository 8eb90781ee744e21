"""Structure mapping of generated control rigs (Rigify's, issue 16): the bones an animator poses are found
without names, from the hierarchy, the rest pose and what else the rig says about its bones (RigLinks:
use_deform, custom shapes, constraints and their targets).

A control rig is no body tree: its FK controls hang from mechanism bones, its torso controls from a parentless
bone an Armature constraint ties to the root, and its deform bones follow the controls through constraints.
So the body is found on the deform bones and the controls from them:

1. a deform tree: each deform bone is linked to its nearest ancestor that is a deform bone, or that has the
   rest segment of one (Rigify's ORG bone beside its DEF twin); that tree goes through the armature mapper
   (armature_mapping.py) like any rig;
2. each limb, neck and head joint's control is the custom-shaped bone spanning the mapped deform bone (its
   head and either its tail or the next joint); where an IK and an FK control both span it, the one inside an
   IK constraint's chain is left out, and of the rest the one continuing the limb's chain in the hierarchy wins
   (forearm under upper arm, hand under forearm);
3. the torso controls sit at pivots, not joints, so they are found by what they move. HipCenter: of the shaped
   bones moving both the pelvis and the chest deform bones, the one the others all move (the torso control,
   not the root that carries it); ShoulderCenter: of those moving the chest deform bone but not the pelvis's,
   the one no other moves (the chest control). The spine between them follows those two controls through the
   rig's constraints, so Spine (and Hip) are left to them, as the rigify preset does.

Pure numpy.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .armature_mapping import ArmatureMapping, structure_mapping_for
from .structure_mapping import StructureError

COINCIDE = 1e-3        # points within this fraction of the rig's size are one point (generated copies: exact)
DRIVEN_SHARE = 0.5     # a control rig: at least this share of its deform bones follow others by constraints


@dataclass(frozen=True)
class Constraint:
    kind: str                  # Blender's constraint type: COPY_TRANSFORMS, IK, ARMATURE, ...
    targets: tuple[int, ...]   # bones of the same armature it reads
    influence: float = 1.0
    chain: int = 0             # IK: chain_count (0: up to the root)


@dataclass
class RigLinks:
    """What an armature says about its bones besides hierarchy and rest pose (blender/io/rig_links.py)."""
    deform: np.ndarray                                # (B,) bool: the bone deforms the mesh
    shaped: np.ndarray                                # (B,) bool: a custom shape, a control the animator poses
    constraints: tuple[tuple[Constraint, ...], ...]   # per bone


def is_control_rig(parents, links: RigLinks | None) -> bool:
    """Shaped controls beside deform bones that mostly follow other bones (constraints, a non-deform parent)."""
    if links is None or not links.deform.any() or not (links.shaped & ~links.deform).any():
        return False
    parents = np.asarray(parents)
    deform = np.flatnonzero(links.deform)
    driven = sum(bool(links.constraints[b]) or bool(parents[b] >= 0 and not links.deform[parents[b]])
                 for b in deform)
    return driven >= DRIVEN_SHARE * len(deform)


def map_armature(bone_names, parents, heads, tails, links: RigLinks | None = None) -> ArmatureMapping:
    """The structure mapping of any armature: control rigs through their deform bones, others directly."""
    if links is not None and is_control_rig(parents, links):
        try:
            return control_rig_mapping(bone_names, parents, heads, tails, links)
        except StructureError as exc:  # its deform bones are no body: its own tree may still be one
            try:
                return structure_mapping_for(bone_names, parents, heads, tails)
            except StructureError:
                raise exc from None
    return structure_mapping_for(bone_names, parents, heads, tails)


def near(a, b, tol) -> np.ndarray:
    """Which points of a (..., 3) lie within tol of b."""
    return np.linalg.norm(np.asarray(a) - np.asarray(b), axis=-1) < tol


def deform_parents(parents, heads, tails, links: RigLinks, tol: float) -> dict[int, int]:
    """Deform bone -> its parent in the deform tree (-1 for a root): the nearest ancestor that deforms or has
    the rest segment of a deform bone."""
    deform = np.flatnonzero(links.deform)
    out = {}
    for d in deform:
        out[int(d)] = -1
        a = int(parents[d])
        while a >= 0:
            if links.deform[a]:
                out[int(d)] = a
                break
            twins = deform[near(heads[deform], heads[a], tol) & near(tails[deform], tails[a], tol)]
            twins = twins[twins != d]
            if len(twins):
                out[int(d)] = int(twins[0])
                break
            a = int(parents[a])
    for d in out:  # a twin below its own bone would close a loop: cut it there
        seen, b = {d}, out[d]
        while b >= 0 and b not in seen:
            seen.add(b)
            b = out.get(b, -1)
        if b >= 0:
            out[d] = -1
    return out


def movers(b: int, parents, links: RigLinks, cache: dict) -> frozenset[int]:
    """Every bone whose pose moves bone b: its parent (unless a full Copy Transforms or Armature constraint
    replaces what the parent gives) and its constraints' targets, and theirs, and so on."""
    if b in cache:
        return cache[b]
    cache[b] = frozenset()  # a cycle (targets reading each other) ends here
    cons = links.constraints[b]
    replaced = any(c.kind in ("COPY_TRANSFORMS", "ARMATURE") and c.influence >= 0.999 for c in cons)
    direct = {t for c in cons for t in c.targets if t >= 0}
    if parents[b] >= 0 and not replaced:
        direct.add(int(parents[b]))
    out = set(direct)
    for d in direct:
        out |= movers(d, parents, links, cache)
    out.discard(b)
    cache[b] = frozenset(out)
    return cache[b]


def ik_chains(parents, links: RigLinks) -> set[int]:
    """Bones an IK constraint moves: each IK owner and its chain of ancestors."""
    out = set()
    for b, cons in enumerate(links.constraints):
        for c in cons:
            if c.kind == "IK":
                a, n = b, 0
                while a >= 0 and (c.chain == 0 or n < c.chain):
                    out.add(a)
                    a, n = int(parents[a]), n + 1
    return out


NEXT = {"Shoulder": "Elbow", "Elbow": "Wrist", "Wrist": "Hand", "Knee": "Ankle", "Ankle": "Foot", "Neck": "Head"}
CHAINS = (("Elbow", "Wrist", "Hand"), ("Knee", "Ankle", "Foot"))
SPANNED = ("Shoulder", "Elbow", "Wrist", "Hand", "Knee", "Ankle", "Foot", "Neck", "Head")


def _split(joint: str) -> tuple[str, str]:
    """'ElbowLeft' -> ('Elbow', 'Left'); 'Neck' -> ('Neck', '')."""
    for side in ("Left", "Right"):
        if joint.endswith(side):
            return joint[:-len(side)], side
    return joint, ""


def _ancestor(a: int, b: int, parents) -> bool:
    """True when a is b's ancestor in the hierarchy."""
    b = int(parents[b])
    while b >= 0:
        if b == a:
            return True
        b = int(parents[b])
    return False


def control_rig_mapping(bone_names, parents, heads, tails, links: RigLinks) -> ArmatureMapping:
    """Bone -> Kinect joint for a control rig's controls (StructureError when its deform bones are no body)."""
    parents = np.asarray(parents, dtype=np.int64)
    heads, tails = np.asarray(heads, float), np.asarray(tails, float)
    tol = COINCIDE * float(np.linalg.norm(np.ptp(np.concatenate([heads, tails]), axis=0)))
    link = deform_parents(parents, heads, tails, links, tol)
    deform = sorted(link)
    where = {b: i for i, b in enumerate(deform)}
    body = structure_mapping_for([bone_names[b] for b in deform], [where.get(link[b], -1) for b in deform],
                                 heads[deform], tails[deform])
    index = {n: i for i, n in enumerate(bone_names)}
    bone_of = {j: index[b] for b, j in body.mapping.items()}  # Kinect joint -> deform bone
    controls = np.flatnonzero(links.shaped & ~links.deform)
    in_ik = ik_chains(parents, links)
    notes = list(body.notes) + [f"control rig: {len(deform)} deform bones mapped, controls found from them"]

    def spanning(joint: str) -> list[int]:
        """Controls (outside IK chains) from the deform bone's head to its tail or to the next joint."""
        d = bone_of[joint]
        base, side = _split(joint)
        ends = [tails[d]] + ([heads[bone_of[NEXT[base] + side]]] if NEXT.get(base, "") + side in bone_of else [])
        at = controls[near(heads[controls], heads[d], tol)]
        return [int(c) for c in at if any(near(tails[c], e, tol) for e in ends) and c not in in_ik]

    found: dict[str, list[int]] = {}
    for joint in bone_of:
        if _split(joint)[0] in SPANNED:
            found[joint] = spanning(joint)
    for side in ("Left", "Right"):  # of FK and IK controls, the one continuing the limb's chain
        for chain in CHAINS:
            joints = [j + side for j in chain if j + side in found]
            for k, j in enumerate(joints):
                linked = [c for c in found[j] if any(
                    _ancestor(c, o, parents) for o in (found[joints[k + 1]] if k + 1 < len(joints) else ())) or any(
                    _ancestor(o, c, parents) for o in (found[joints[k - 1]] if k else ()))]
                if len(found[j]) > 1 and linked:
                    found[j] = linked
    cache: dict = {}
    pelvis, chest = bone_of.get("HipCenter"), bone_of.get("ShoulderCenter")
    if pelvis is not None and chest is not None:
        low, high = movers(pelvis, parents, links, cache), movers(chest, parents, links, cache)
        both = [int(c) for c in controls if c in low and c in high]
        found["HipCenter"] = [c for c in both if all(o in movers(c, parents, links, cache) for o in both if o != c)]
        upper = [int(c) for c in controls if c in high and c not in low]
        found["ShoulderCenter"] = [c for c in upper if not any(o in movers(c, parents, links, cache)
                                                              for o in upper if o != c)]
    out: dict[str, str] = {}
    how: dict[str, str] = {}
    order = ("HipCenter", "ShoulderCenter", "Neck", "Head") + tuple(
        j + s for s in ("Left", "Right") for j in ("Shoulder", "Elbow", "Wrist", "Hand", "Knee", "Ankle", "Foot"))
    for joint in order:
        picks = sorted(found.get(joint, ()), key=lambda c: bone_names[c])  # names only break a tie
        if not picks:
            if joint in bone_of:
                notes.append(f"{joint}: no control found for deform bone {bone_names[bone_of[joint]]}")
            continue
        if len(picks) > 1:
            notes.append(f"{joint}: {len(picks)} controls fit, {bone_names[picks[0]]} taken by name order")
        out[bone_names[picks[0]]] = joint
        why = ("moves the pelvis and chest; the others moving both move it" if joint == "HipCenter" else
               "moves the chest but not the pelvis; nothing else moving it does" if joint == "ShoulderCenter"
               else "control spanning the deform bone")
        how[joint] = f"{bone_names[picks[0]]} ({why}; deform bone {bone_names[bone_of[joint]]})"
    left = [j for j in bone_of if j not in order]  # Spine, Hip: the rig moves them from the torso controls
    if left:
        notes.append(f"left to the torso controls, which the rig's constraints carry them with: {', '.join(left)}")
    return ArmatureMapping(out, how, notes)
