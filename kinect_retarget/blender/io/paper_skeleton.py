"""The paper's skeleton (003 §4.1) as an armature: one bone per connection of its tree of skeleton points,
beside the Kinect-named rig, so the result the paper draws (its figs. 8-9) can be seen and compared."""
from __future__ import annotations

from collections import deque

import bpy
import numpy as np

from ...autorig.features import LABELS
from ...autorig.levels import SkeletonPoints


def tree_bones(sk: SkeletonPoints) -> list[tuple[int, int, int]]:
    """(parent point, child point, parent bone or -1) for every tree link, walked breadth first from the
    trunk's lowest skeleton point (the pelvis), so each bone starts where its parent bone ends."""
    n = len(sk.points)
    links = [[] for _ in range(n)]
    for a, b in sk.tree.tolist():
        links[a].append(b)
        links[b].append(a)
    trunk = np.flatnonzero(sk.segment == 0)
    root = int(trunk[np.argmax(sk.level[trunk])]) if len(trunk) else 0
    into = {root: -1}  # point -> index of the bone ending there
    bones, queue = [], deque([root])
    while queue:
        p = queue.popleft()
        for c in links[p]:
            if c not in into:
                into[c] = len(bones)
                bones.append((p, c, into[p]))
                queue.append(c)
    return bones


def point_name(sk: SkeletonPoints, i: int) -> str:
    seg = int(sk.segment[i])
    return f"{LABELS[seg] if 0 <= seg < len(LABELS) else 'reeb'}.L{int(sk.level[i])}.{i:03d}"


def build_paper_skeleton(context, sk: SkeletonPoints, name: str, collection) -> bpy.types.Object:
    """A non-deforming armature, shown as sticks in front of the mesh: bone '<segment>.L<level>.<i>' runs
    from the parent skeleton point to skeleton point i."""
    arm = bpy.data.armatures.new(name)
    arm.display_type = "STICK"
    obj = bpy.data.objects.new(name, arm)
    obj.show_in_front = True
    collection.objects.link(obj)
    obj["kinect_retarget_paper_points"] = len(sk.points)
    from ..mesh_autorig import armature_edit
    with armature_edit(context, obj):
        edit = []
        for p, c, parent in tree_bones(sk):
            eb = arm.edit_bones.new(point_name(sk, c))
            eb.head, eb.tail = sk.points[p].tolist(), sk.points[c].tolist()
            if np.allclose(eb.head, eb.tail):  # two coincident points: keep the bone (Blender drops zero ones)
                eb.tail = (sk.points[c] + np.array([0, 0, 1e-3])).tolist()
            eb.use_deform = False
            if parent >= 0:
                eb.parent = edit[parent]
            edit.append(eb)
    return obj
