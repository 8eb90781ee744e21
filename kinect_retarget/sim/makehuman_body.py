"""The MakeHuman base mesh (CC0) as a skinnable body: skin quads, skeleton joints, weights per driver.

Only the `body` group (the skin) is kept. The 139 weighted MakeHuman bones are folded onto the few
"drivers" the mocap retarget poses (pelvis, chest, upper arm, ...), so skinning is one small matrix product.
Units: metres (the OBJ is in decimetres), MakeHuman axes (Y up, the character faces +Z, .L at +X).
"""
from __future__ import annotations

import json
import os
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..autorig.mesh import group_polygons, read_obj

# Drivers: name -> (parent driver, MakeHuman bones that belong to it). Bones not listed follow the nearest
# listed ancestor (face bones follow the head, fingers the hand, toes the foot).
DRIVERS: dict[str, tuple[str | None, tuple[str, ...]]] = {
    "pelvis": (None, ("root", "pelvis.L", "pelvis.R", "spine05")),
    "abdomen": ("pelvis", ("spine04", "spine03")),
    "chest": ("abdomen", ("spine02", "spine01", "breast.L", "breast.R", "clavicle.L", "clavicle.R",
                          "shoulder01.L", "shoulder01.R")),
    "head": ("chest", ("neck01", "neck02", "neck03", "head")),
    **{f"{part}.{s}": (par if par in ("chest", "pelvis") else f"{par}.{s}", tuple(f"{b}.{s}" for b in bones))
       for s in ("L", "R") for part, par, bones in (
           ("upperarm", "chest", ("upperarm01", "upperarm02")),
           ("lowerarm", "upperarm", ("lowerarm01", "lowerarm02")),
           ("hand", "lowerarm", ("wrist",)),
           ("upperleg", "pelvis", ("upperleg01", "upperleg02")),
           ("lowerleg", "upperleg", ("lowerleg01", "lowerleg02")),
           ("foot", "lowerleg", ("foot",)))},
}
DRIVER_NAMES = tuple(DRIVERS)


@dataclass(frozen=True)
class BodyModel:
    rest_vertices: np.ndarray   # (V, 3) metres, skin vertices only
    quads: np.ndarray           # (Q, 4) indices into rest_vertices
    weights: np.ndarray         # (V, D) skin weight per driver, rows sum to 1
    joints: dict                # MakeHuman joint name -> (3,) rest position


@dataclass(frozen=True)
class MakeHumanFiles:
    """MakeHuman's base mesh as shipped (kinect_retarget/assets/makehuman): read once, used by the depth
    renderer's body (load_body) and the auto-rig check (sim/autorig_scoring.load_makehuman)."""
    vertices: np.ndarray        # (V, 3) decimetres, OBJ axes (Y up, facing +Z)
    polygons: list              # 0-based vertex lists, as in base.obj
    groups: list                # each polygon's OBJ group ('body' is the skin)
    skeleton: dict              # default.mhskel
    weights: dict               # default_weights.mhw "weights": bone -> [[vertex, weight], ...]
    obj_path: str


@lru_cache(maxsize=2)
def read_makehuman(folder: str) -> MakeHumanFiles:
    """base.obj, default.mhskel and default_weights.mhw from `folder` (the one MakeHuman reader)."""
    obj = os.path.join(folder, "base.obj")
    verts, polys, groups = read_obj(obj)
    with open(os.path.join(folder, "default.mhskel"), encoding="utf-8") as fh:
        skel = json.load(fh)
    with open(os.path.join(folder, "default_weights.mhw"), encoding="utf-8") as fh:
        weights = json.load(fh)["weights"]
    return MakeHumanFiles(verts, polys, groups, skel, weights, obj)


def _driver_of_bone(bones: dict) -> dict[str, str]:
    owner = {b: d for d, (_, bs) in DRIVERS.items() for b in bs}
    out = {}
    for name in bones:
        b = name
        while b is not None and b not in owner:
            b = bones[b]["parent"]
        out[name] = owner.get(b, "pelvis")
    return out


@lru_cache(maxsize=2)
def load_body(mesh_dir: str) -> BodyModel:
    """Load base.obj, default.mhskel and default_weights.mhw from `mesh_dir` (kinect_retarget/assets/makehuman)."""
    files = read_makehuman(os.fspath(mesh_dir))
    verts_all = files.vertices * 0.1    # decimetres -> metres
    faces = np.asarray(group_polygons(files.obj_path, files.polygons, files.groups, "body"), dtype=np.int64)
    skel, wfile = files.skeleton, files.weights
    joints = {k: verts_all[v].mean(axis=0) for k, v in skel["joints"].items()}
    used = np.unique(faces)
    remap = np.full(len(verts_all), -1)
    remap[used] = np.arange(len(used))
    driver_of = _driver_of_bone(skel["bones"])
    w = np.zeros((len(verts_all), len(DRIVER_NAMES)))
    for bone, pairs in wfile.items():
        if not pairs:
            continue
        pv = np.asarray(pairs, dtype=np.float64)
        np.add.at(w[:, DRIVER_NAMES.index(driver_of.get(bone, "pelvis"))], pv[:, 0].astype(np.int64), pv[:, 1])
    w = w[used]
    total = w.sum(axis=1, keepdims=True)
    w = np.where(total > 0, w / np.maximum(total, 1e-12), np.eye(len(DRIVER_NAMES))[0])
    bone_joint = {b: (joints[v["head"]], joints[v["tail"]]) for b, v in skel["bones"].items()}
    return BodyModel(verts_all[used], remap[faces], w, {"joints": joints, "bones": bone_joint})


def linear_blend_skinning(rest_vertices: np.ndarray, weights: np.ndarray, rotations: np.ndarray,
                          rest_origins: np.ndarray, posed_origins: np.ndarray) -> np.ndarray:
    """x' = sum_d w_d (R_d (x - o_d) + o'_d): vertices (V, 3), weights (V, D), rotations (..., D, 3, 3) about
    rest origins (D, 3) moved to (..., D, 3) -> (..., V, 3). The depth renderer's drivers and the auto-rig
    check's MakeHuman bones are both posed with it."""
    local = rest_vertices[:, None, :] - rest_origins[None]                                  # (V, D, 3)
    moved = np.einsum("...dij,vdj->...vdi", rotations, local) + posed_origins[..., None, :, :]
    return np.einsum("vd,...vdi->...vi", weights, moved)

