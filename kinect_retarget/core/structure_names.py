"""Joint names in the structural mapper (structure_mapping.py), where they only break ties: which side a name
says, and Kinect-named skeletons (v1 or v2 joint names), which map one to one."""
from __future__ import annotations

import re

from .skeletons import KINECT_V1, V1_FROM_V2

ROLES = KINECT_V1.joints


def name_side(name: str) -> int:
    """+1 if a node name says left ('LeftArm', 'thigh.L', 'l_hip', 'lShldr', 'LHipJoint'), -1 right, 0 neither."""
    low = name.lower()
    for word, side in (("left", 1), ("right", -1)):
        if word in low:
            return side
    tokens = re.split(r"[^a-z]+", low)
    for letter, side in (("l", 1), ("r", -1)):
        if letter in tokens or re.match(rf"[{letter}{letter.upper()}][A-Z]", name):
            return side
    return 0


def branch_side(names, kids, reach, branch: int) -> int:
    """+1 if the names of the first nodes down `branch`'s longest path say left, -1 right, 0 unknown."""
    j, votes = branch, 0
    for _ in range(4):
        votes += name_side(names[j])
        if not kids[j]:
            break
        j = max(kids[j], key=lambda c: reach[c])
    return (votes > 0) - (votes < 0)


def kinect_names(names, ends, roles: dict, notes: list) -> dict:
    """A Kinect-named skeleton (v1 or v2 joint names) maps one to one wherever it names the joint, provided
    the named nodes sit where the structure found those joints (`roles`: structure_mapping's RoleMatch)."""
    index = {n.lower(): i for i, n in enumerate(names) if not ends[i]}
    found = {}
    for role in ROLES:
        for name in (role, V1_FROM_V2.get(role, role)):
            if name.lower() in index:
                found[role] = index[name.lower()]
                break
    if len(found) < 10:
        return roles
    out = dict(roles)
    pairs = [(r, r.replace("Left", "Right")) for r in ROLES if "Left" in r]
    swap = any(found.get(a) in roles[b].average for a, b in pairs)  # the names put left where we saw right
    if swap:
        for a, b in pairs:
            out[a], out[b] = roles[b], roles[a]
    agree = sum(j in out[r].average or j == out[r].node for r, j in found.items())
    if agree < 0.6 * len(found):  # e.g. a rig whose bones carry the name of the joint at their tail
        notes.append(f"Kinect joint names ignored: only {agree} of {len(found)} sit where the structure puts "
                     "those joints")
        return roles
    if swap:
        notes.append("left and right follow the Kinect joint names")
    for role, j in found.items():
        if out[role].node not in (None, j) and j not in out[role].average:
            notes.append(f"{role}: the Kinect name {names[j]!r} overrides the structure's {names[out[role].node]!r}")
        out[role] = type(roles[role])(j, (j,), "Kinect name")
    return out
