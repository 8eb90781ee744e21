"""Ground truth for checking the auto-rigger on MakeHuman's base mesh (kinect_retarget/assets/makehuman,
tests/data/README.md §4a): the reference skeleton from default.mhskel, the mesh's own skin weights, and linear
blend skinning to pose the mesh from MakeHuman's BVH poses or from CMU motions (global bone rotations carried
over by bone correspondence)."""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..core import quat
from ..core.skeletons import KINECT_V1
from ..autorig.mesh import Mesh, mesh_from_obj
from .makehuman_body import linear_blend_skinning, read_makehuman

# Kinect v1 joint -> (MakeHuman bone that carries it, how the point is defined from bone heads/tails).
_REF = {
    "HipCenter": ("spine05", [("h", "spine05")]),
    "Spine": ("spine02", [("h", "spine02")]),
    "ShoulderCenter": ("neck01", [("h", "neck01")]),
    "Head": ("head", [("h", "head"), ("t", "head")]),
    "ShoulderSIDE": ("upperarm01.S", [("h", "upperarm01.S")]),
    "ElbowSIDE": ("lowerarm01.S", [("h", "lowerarm01.S")]),
    "WristSIDE": ("wrist.S", [("h", "wrist.S")]),
    "HandSIDE": ("wrist.S", [("h", "wrist.S"), ("h", "finger3-1.S")]),
    "HipSIDE": ("upperleg01.S", [("h", "upperleg01.S")]),
    "KneeSIDE": ("lowerleg01.S", [("h", "lowerleg01.S")]),
    "AnkleSIDE": ("foot.S", [("h", "foot.S")]),
    "FootSIDE": ("foot.S", [("t", "foot.S"), ("h", "toe3-1.S")]),
}

# MakeHuman bone-name prefix -> CMU joint (01_01 and 131_xx spellings) whose motion it follows.
_CMU = [("spine05", ("LowerBack", "lowerback")), ("spine04", ("LowerBack", "lowerback")),
        ("spine03", ("Spine", "Chest")), ("spine02", ("Spine", "Chest")), ("spine01", ("Spine1", "Chest2")),
        ("neck", ("Neck", "lowerneck")), ("head", ("Head", "Head")),
        ("clavicle.S", ("SIDEShoulder", "SIDECollar")), ("shoulder01.S", ("SIDEShoulder", "SIDECollar")),
        ("upperarm", ("SIDEArm", "SIDEShoulder")), ("lowerarm", ("SIDEForeArm", "SIDEElbow")),
        ("wrist.S", ("SIDEHand", "SIDEWrist")),
        ("pelvis.S", ("Hips", "Hips")), ("upperleg", ("SIDEUpLeg", "SIDEHip")),
        ("lowerleg", ("SIDELeg", "SIDEKnee")), ("foot.S", ("SIDEFoot", "SIDEAnkle"))]


@dataclass
class MakeHuman:
    full: Mesh                 # the whole base.obj (weights index it)
    body: Mesh                 # group 'body' (body.source_index -> full)
    bones: tuple[str, ...]
    parents: np.ndarray        # (B,)
    heads: np.ndarray          # (B, 3) rest, OBJ axes (decimetres, Y up, facing +Z)
    tails: np.ndarray
    weights: np.ndarray        # (V_full, B) dense

    @property
    def height(self) -> float:
        return float(np.ptp(self.body.vertices[:, 1]))


def load_makehuman(folder: str | Path) -> MakeHuman:
    files = read_makehuman(os.fspath(folder))
    full = mesh_from_obj(files.obj_path, files.vertices, files.polygons, files.groups)
    body = mesh_from_obj(files.obj_path, files.vertices, files.polygons, files.groups, group="body")
    sk = files.skeleton
    joint = {k: full.vertices[v].mean(axis=0) for k, v in sk["joints"].items()}
    names = list(sk["bones"])
    order, placed = [], set()
    while len(order) < len(names):  # parents first
        for n in names:
            p = sk["bones"][n]["parent"]
            if n not in placed and (p is None or p in placed):
                order.append(n)
                placed.add(n)
    parents = np.array([-1 if sk["bones"][n]["parent"] is None else order.index(sk["bones"][n]["parent"])
                        for n in order])
    heads = np.array([joint[sk["bones"][n]["head"]] for n in order])
    tails = np.array([joint[sk["bones"][n]["tail"]] for n in order])
    w = np.zeros((len(full.vertices), len(order)))
    for bone, pairs in files.weights.items():
        if bone in order and pairs:
            p = np.asarray(pairs)
            w[p[:, 0].astype(int), order.index(bone)] = p[:, 1]
    s = w.sum(axis=1, keepdims=True)
    w = np.where(s > 0, w / np.where(s > 0, s, 1), 0)
    w[s[:, 0] == 0, 0] = 1.0  # unweighted helpers follow the root
    return MakeHuman(full, body, tuple(order), parents, heads, tails, w)


def _names(side_name: str) -> list[tuple[str, str]]:
    return [(side_name.replace("SIDE", s), m) for s, m in (("Left", "L"), ("Right", "R"))] \
        if "SIDE" in side_name else [(side_name, "")]


def reference_joints(mh: MakeHuman, rotations: np.ndarray | None = None) -> np.ndarray:
    """(20, 3) reference Kinect joints, at rest or for a pose given as global bone rotations (B, 3, 3)."""
    heads, tails = posed_bones(mh, rotations) if rotations is not None else (mh.heads, mh.tails)
    out = np.zeros((len(KINECT_V1), 3))
    for key, (_, pts) in _REF.items():
        for name, suffix in _names(key):
            acc = [(heads if kind == "h" else tails)[mh.bones.index(b.replace(".S", "." + suffix))]
                   for kind, b in pts]
            out[KINECT_V1.index(name)] = np.mean(acc, axis=0)
    return out


def posed_bones(mh: MakeHuman, rotations: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bone heads and tails after applying global rotations (B, 3, 3) down the hierarchy (root fixed)."""
    heads = mh.heads.copy()
    for b, p in enumerate(mh.parents):
        if p >= 0:
            heads[b] = heads[p] + rotations[p] @ (mh.heads[b] - mh.heads[p])
    tails = heads + np.einsum("bij,bj->bi", rotations, mh.tails - mh.heads)
    return heads, tails


def pose_body(mh: MakeHuman, rotations: np.ndarray) -> Mesh:
    """The body mesh posed by linear blend skinning with MakeHuman's own weights."""
    heads, _ = posed_bones(mh, rotations)
    v = mh.full.vertices[mh.body.source_index]
    w = mh.weights[mh.body.source_index]
    return Mesh(linear_blend_skinning(v, w, rotations, mh.heads, heads), mh.body.faces, "makehuman-posed")


def _procrustes(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """Rotation R minimising |R (src - mean) - (dst - mean)|."""
    a, b = src - src.mean(0), dst - dst.mean(0)
    u, _, vt = np.linalg.svd(b.T @ a)
    d = np.sign(np.linalg.det(u @ vt))
    return u @ np.diag([1, 1, d]) @ vt


def rotations_from_makehuman_bvh(mh: MakeHuman, motion, frame: int = 0) -> np.ndarray:
    """Global bone rotations in OBJ axes from a MakeHuman BVH (same bone names), via the lab-axes rotation
    that best maps the BVH rest joints onto the skeleton's heads."""
    names = motion.skeleton.names
    common = [b for b in mh.bones if b in names]
    a = _procrustes(motion.rest_positions[[names.index(b) for b in common]],
                    mh.heads[[mh.bones.index(b) for b in common]])
    rot = np.tile(np.eye(3), (len(mh.bones), 1, 1))
    g = quat.to_matrix(motion.rotations[frame])
    for i, b in enumerate(mh.bones):
        if b in names:
            rot[i] = a @ g[names.index(b)] @ a.T
        elif mh.parents[i] >= 0:
            rot[i] = rot[mh.parents[i]]
    return rot


def rotations_from_cmu(mh: MakeHuman, motion, frame: int) -> np.ndarray:
    """Global bone rotations (rest -> frame) of a CMU motion carried onto MakeHuman bones by body part,
    in OBJ axes (the CMU lab axes are turned so its subject faces +Z with +X on its left, as MakeHuman)."""
    names = motion.skeleton.names
    spell = 0 if "LeftUpLeg" in names else 1
    rest = motion.rest_positions
    up = motion.up
    left = rest[names.index(("LeftUpLeg", "LeftHip")[spell])] - rest[names.index(("RightUpLeg", "RightHip")[spell])]
    left -= up * (left @ up)
    left /= np.linalg.norm(left)
    front = np.cross(left, up)
    a = np.stack([left, up, front])  # rows: CMU lab -> (x left, y up, z front) = MakeHuman OBJ axes
    g = quat.to_matrix(motion.rotations[frame])
    # The root's heading is removed: only the body's own articulation matters here.
    root = a @ g[0] @ a.T
    yaw = np.arctan2(root[0, 2], root[2, 2])
    unyaw = np.array([[np.cos(yaw), 0, -np.sin(yaw)], [0, 1, 0], [np.sin(yaw), 0, np.cos(yaw)]])
    rot = np.tile(np.eye(3), (len(mh.bones), 1, 1))
    for i, b in enumerate(mh.bones):
        src = None
        for prefix, cmu in _CMU:
            for side, s in (("Left", "L"), ("Right", "R")):
                pfx = prefix.replace(".S", "." + s)
                if b.startswith(pfx) and (".S" in prefix or "." not in b or b.endswith("." + s)) and \
                        (".S" in prefix or not prefix.endswith(("arm", "leg")) or b.endswith("." + s)):
                    src = cmu[spell].replace("SIDE", side)
                    break
            if src:
                break
        if src in names:
            rot[i] = unyaw @ a @ g[names.index(src)] @ a.T
        elif mh.parents[i] >= 0:
            rot[i] = rot[mh.parents[i]]
        else:
            rot[i] = unyaw @ root
    return rot


def joint_errors(found: np.ndarray, reference: np.ndarray, height: float) -> np.ndarray:
    """(20,) distance of each joint from the reference, in % of body height."""
    return np.linalg.norm(found - reference, axis=1) / height * 100


def symmetry_error(joints: np.ndarray, left_axis: np.ndarray, centre: np.ndarray, height: float) -> float:
    """Largest distance (% of height) between a joint and its mirrored counterpart, mirroring across the
    plane through `centre` normal to `left_axis`."""
    m = KINECT_V1.mirror
    p = joints - centre
    reflected = p - 2 * np.outer(p @ left_axis, left_axis)
    return float(np.linalg.norm(reflected[m] - p, axis=1).max() / height * 100)
