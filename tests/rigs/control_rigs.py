"""The generated Rigify control rig as arrays, for numpy tests of the control-rig structure mapping: names,
parents, rest heads and tails, plus RigLinks (use_deform, custom shapes, constraints with their target bones).
tests/data/rigs/rigify_generated.json is written from Blender's own Rigify (metarig + Generate Rig, Blender
5.0.1) by tests/blender/test_structure_rigify_controls.py (KR_WRITE_RIGIFY_FIXTURE=1), which also checks
that it still matches what Blender generates."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from kinect_retarget.core.control_rig_mapping import Constraint, RigLinks
from tests.rigs.humanoid_rigs import Rig

RIGIFY_FIXTURE = Path(__file__).resolve().parents[1] / "data" / "rigs" / "rigify_generated.json"


def rig_record(names, parents, heads, tails, links: RigLinks) -> dict:
    """A JSON-ready record of an armature and its links (positions to 0.01 mm)."""
    return {"names": list(names), "parents": [int(p) for p in parents],
            "heads": np.round(np.asarray(heads, float), 5).tolist(),
            "tails": np.round(np.asarray(tails, float), 5).tolist(),
            "deform": [bool(d) for d in links.deform], "shaped": [bool(s) for s in links.shaped],
            "constraints": [[[c.kind, list(c.targets), round(c.influence, 4), c.chain] for c in cons]
                            for cons in links.constraints]}


def from_record(data: dict) -> tuple[Rig, RigLinks]:
    rig = Rig(list(data["names"]), np.array(data["parents"]), np.array(data["heads"]), np.array(data["tails"]))
    links = RigLinks(np.array(data["deform"], bool), np.array(data["shaped"], bool),
                     tuple(tuple(Constraint(k, tuple(t), i, c) for k, t, i, c in cons)
                           for cons in data["constraints"]))
    return rig, links


def rigify_controls() -> tuple[Rig, RigLinks]:
    return from_record(json.loads(RIGIFY_FIXTURE.read_text(encoding="utf-8")))


def reordered(rig: Rig, links: RigLinks, seed: int) -> tuple[Rig, RigLinks]:
    """The same armature with its bones listed in a random order (parents and constraint targets follow)."""
    order = np.random.default_rng(seed).permutation(len(rig.names))
    new = np.empty_like(order)
    new[order] = np.arange(len(order))
    remap = lambda b: int(new[b]) if b >= 0 else -1  # noqa: E731
    out = Rig([rig.names[b] for b in order], np.array([remap(rig.parents[b]) for b in order]),
              rig.heads[order], rig.tails[order])
    cons = tuple(tuple(Constraint(c.kind, tuple(remap(t) for t in c.targets), c.influence, c.chain)
                       for c in links.constraints[b]) for b in order)
    return out, RigLinks(links.deform[order], links.shaped[order], cons)


def rename_bones(obj, seed: int) -> dict[str, str]:
    """Rename every bone of a Blender armature object to a seeded random string (constraints and most driver
    paths follow by themselves); returns {new name: old name}."""
    rng = np.random.default_rng(seed)
    letters = list("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789")
    back = {}
    for bone in list(obj.data.bones):
        new = "".join(rng.choice(letters, 10))
        back[new] = bone.name
        bone.name = new
    _fix_driver_paths(obj, {old: new for new, old in back.items()})
    return back


def _renamed_path(path: str, prefix: str, new_name: dict[str, str]) -> str:
    if path.startswith(prefix + '["') and path.split('"')[1] in new_name:
        old = path.split('"')[1]
        return path.replace(f'"{old}"', f'"{new_name[old]}"', 1)
    return path


def _fix_driver_paths(obj, new_name: dict[str, str]) -> None:
    """Blender's bone rename leaves two kinds of driver paths with the old name: variables reading
    `pose.bones["old"].scale.y` (Rigify's finger curls) and the Armature's own drivers of `bones["old"]`
    (B-Bone eases); a renamed rig that works has the new names there too."""
    for owner in (obj, obj.data):
        for d in owner.animation_data.drivers if owner.animation_data else ():
            d.data_path = _renamed_path(d.data_path, "bones", new_name)
            for target in (t for v in d.driver.variables for t in v.targets):
                target.data_path = _renamed_path(target.data_path, "pose.bones", new_name)
