"""Structure mapping of the generated Rigify control rig (issue 16): how long mapping its 706 bones takes, and
how far a bake onto the rig with every bone renamed (mapped by structure) is from the bake onto the
original-named rig (mapped by the 'rigify' preset).

    .venv/bin/python benchmarks/bench_control_rig_mapping.py [--repeat 20]

Times: reading the armature (TargetRig with its links), the control-rig mapping alone (numpy), and
build_mapping('auto') end to end, best of --repeat. Bakes: each sample take with the default options (on v2
takes the hands too: finger controls found by structure on the renamed rig) and once with root motion;
compared are the keyed rotations and Blender's evaluation of all 160 deform bones and the root at every keyed
frame (angle and position).
"""
from __future__ import annotations

import argparse
import os
import tempfile

import _common
import numpy as np
from bench_constrained_bake import rigify_file

from kinect_retarget.core.bake_options import BakeOptions
from kinect_retarget.core.pipeline import RetargetSettings
from kinect_retarget.core.quat import angle_between, from_matrix
from kinect_retarget.takes import load_take
from tests.rigs.control_rigs import rename_bones

TAKES = ("kinect_v1_cmu_131_03_hop.krtake", "kinect_v1_cmu_131_01_walk.krtake", "kinect_v2_ges01_wavehand.krtake",
         "kinect_v2_ges06_chickenwing.krtake")


def open_rig(path: str, seed: int | None):
    import bpy  # noqa: I001 (addon_utils needs bpy first)
    import addon_utils
    addon_utils.enable("rigify", default_set=True)  # its load handlers expect its properties
    bpy.ops.wm.open_mainfile(filepath=path)
    obj = bpy.data.objects["rig"]
    return obj, (rename_bones(obj, seed) if seed is not None else {b.name: b.name for b in obj.data.bones})


def timings(path: str, repeat: int) -> None:
    from kinect_retarget.blender.io.rig_reader import target_rig_from_object
    from kinect_retarget.core.control_rig_mapping import map_armature
    from kinect_retarget.core.presets import PRESETS, build_mapping
    obj, back = open_rig(path, 16)
    rig = target_rig_from_object(obj)
    read = _common.best_of(lambda: target_rig_from_object(obj), repeat)
    core = _common.best_of(lambda: map_armature(rig.bone_names, rig.parents, rig.heads, rig.tails, rig.links),
                           repeat)
    whole = _common.best_of(lambda: build_mapping("auto", rig.bone_names, None, target_rig_from_object(obj)),
                            repeat)
    used, mapping = build_mapping("auto", rig.bone_names, None, rig)
    same = {back[b]: j for b, j in mapping.items()} == PRESETS["rigify"]
    print(f"{len(rig.bone_names)} bones, renamed: preset {used}, mapping equals the rigify preset's: {same}")
    print(f"read armature + links {read * 1000:.1f} ms; control-rig mapping (numpy) {core * 1000:.1f} ms; "
          f"build_mapping('auto') from the object {whole * 1000:.1f} ms (best of {repeat})")


def bake(path: str, seed: int | None, take, root_motion: bool):
    """Keys by original bone name and (frames, deform bones, 4, 4) as Blender evaluates the baked rig."""
    import bpy

    from kinect_retarget.blender.bake_take import bake_take
    obj, back = open_rig(path, seed)
    res = bake_take(obj, take, preset="auto", settings=RetargetSettings(),
                    options=BakeOptions(root_motion=root_motion))
    keys = {back[b]: res.motion.quats[:, k] for k, b in enumerate(res.motion.bone_names)}
    deform = sorted((back[b.name], b.name) for b in obj.data.bones if b.use_deform or back[b.name] == "root")
    posed = []
    for f in res.motion.frames:
        bpy.context.scene.frame_set(int(f))
        posed.append([np.array(obj.pose.bones[name].matrix) for _, name in deform])
    return res.preset, keys, np.array(posed)


def rotation(m: np.ndarray) -> np.ndarray:
    r = m[..., :3, :3]
    return from_matrix(r / np.linalg.norm(r, axis=-2, keepdims=True))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=20)
    args = ap.parse_args()
    path = os.path.join(tempfile.mkdtemp(), "rigify.blend")
    rigify_file(path, body=False)
    timings(path, args.repeat)
    for name, root_motion in [(t, False) for t in TAKES] + [(TAKES[0], True)]:
        take = load_take(_common.SAMPLE_TAKES / name)
        p1, k1, m1 = bake(path, None, take, root_motion)
        p2, k2, m2 = bake(path, 11, take, root_motion)
        key_deg = max(float(np.degrees(angle_between(k1[b], k2[b])).max()) for b in k1) if k1.keys() == k2.keys() \
            else float("nan")
        deform_deg = float(np.degrees(angle_between(rotation(m1), rotation(m2))).max())
        deform_mm = float(np.abs(m1[..., :3, 3] - m2[..., :3, 3]).max() * 1000)
        print(f"{name}{' (root motion)' if root_motion else ''}: {len(m1)} frames, {p1} vs {p2}: same "
              f"{len(k1)} keyed bones {k1.keys() == k2.keys()}; max difference keys {key_deg:.2e} deg, "
              f"{m1.shape[1] - 1} deform bones + root {deform_deg:.2e} deg / {deform_mm:.2e} mm")


if __name__ == "__main__":
    main()
