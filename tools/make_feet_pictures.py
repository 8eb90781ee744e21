"""Regenerate the pictures of docs/feet_and_any_rig.md (Workbench, headless; repository files only):

    .venv/bin/python tools/make_feet_pictures.py

1. feet_before_after.png: MakeHuman's default skeleton (CC0) walking (CMU 131_02, sample_takes), side view of
   one stance of the left foot: the leg at the stance's start, middle and end and the ankle's path during the
   stance (red: as retargeted, sliding; green: with the feet locked).
2. toes_before_after.png: Unreal's UE4 bone layout walking with its feet turned 40 degrees further down than
   the performer's (tests/takes/steep_feet.py), side view of the left shin, foot and ball at the frame whose
   toes dip deepest (left: as retargeted, the toes under the floor; right: with the feet locked, the foot
   pitched up about the ankle).
3. structure_mapping.png: Blender's human metarig with every bone renamed to a random string, mapped by
   structure alone: the bones that drive a Kinect segment coloured (spine blue, left green, right red), the
   rest (face, fingers, palms, heels, breasts) grey.
"""
from __future__ import annotations

import copy
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
HERE = REPO / "docs" / "images"
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "tools"))

import bpy  # noqa: E402
from make_autorig_pictures import markers, material, sticks  # noqa: E402

from kinect_retarget.blender.io.workbench_render import (  # noqa: E402
    contact_sheet, frame_camera, render_still, setup_workbench, stage)
from kinect_retarget.core.armature_mapping import structure_mapping_for  # noqa: E402
from kinect_retarget.core.foot_contacts import intervals  # noqa: E402
from kinect_retarget.core.foot_lock import FootLock  # noqa: E402
from kinect_retarget.core.pipeline import RetargetPipeline, RetargetSettings  # noqa: E402
from kinect_retarget.core.presets import PRESETS  # noqa: E402
from kinect_retarget.core.target_rig import evaluate_pose  # noqa: E402
from kinect_retarget.takes import load_take  # noqa: E402
from tests.rigs.humanoid_rigs import makehuman_rig  # noqa: E402

LEG = ("lowerleg02.L", "foot.L")  # the lower shin and the foot: the camera comes close


def _posed(rig, motion):
    idx = np.array([rig.index(b) for b in motion.bone_names])
    return evaluate_pose(rig, idx, motion.quats, rig.index(motion.root_bone), motion.root_location)


def feet_pictures() -> str:
    take = load_take(REPO / "sample_takes" / "kinect_v1_cmu_131_02_walk.krtake")
    rig = makehuman_rig().target("MakeHuman")
    pipe = RetargetPipeline(take.skeleton, rig, PRESETS["makehuman"], RetargetSettings())
    before = pipe.process_take(take)
    after = copy.deepcopy(before)
    report = FootLock(pipe.retargeter).apply(after, "lock", take.rate)
    contact = next(g for g in report.legs if g.side == "Left").contact
    a, b = max(intervals(contact), key=lambda ab: ab[1] - ab[0])
    frames = [a, (a + b) // 2, b]
    shift = report.height_shift_cm / 100
    paths = []
    for label, motion, colour, lift in (("before", before, (0.85, 0.15, 0.1, 1), shift),
                                        ("after", after, (0.1, 0.6, 0.2, 1), 0.0)):
        bpy.ops.wm.read_factory_settings(use_empty=True)
        scene = bpy.context.scene
        posed = _posed(rig, motion)
        posed[:, :, 2, 3] += lift  # the same body height in both pictures
        legs = [rig.index(n) for n in LEG]
        bone = material("leg", (0.35, 0.35, 0.4, 1))
        shown = []
        for f in frames:
            heads = posed[f, legs, :3, 3]
            tails = heads + posed[f, legs, :3, 1] * rig.lengths[legs, None]
            shown.append(sticks(heads, tails, 0.003, bone, f"leg{f}"))
        ankle = posed[a:b + 1, rig.index("foot.L"), :3, 3]
        trail = material("trail", colour)
        shown.append(markers(ankle, 0.004, trail, "trail"))
        moved = np.linalg.norm(np.diff(ankle, axis=0), axis=1) > 1e-5
        if moved.any():
            shown.append(sticks(ankle[:-1][moved], ankle[1:][moved], 0.0025, trail, "path"))
        left = next(g for g in report.legs if g.side == "Left")
        slide = (left.slide_before_cm if label == "before" else left.slide_after_cm)[1]
        stage(scene, shown, [1], note=f"{label}: ankle slide p95 {slide:.1f} cm", resolution=(480, 360),
              azimuth_deg=60)
        paths.append(render_still(scene, str(HERE / f"feet_{label}.png"), 1))
    return contact_sheet(paths, str(HERE / "feet_before_after.png"), step=1)


def toe_pictures() -> str:
    from kinect_retarget.core.toe_floor import tips
    from tests.rigs.humanoid_rigs import build
    from tests.rigs.layouts import LAYOUTS
    from tests.takes.steep_feet import steep_feet
    take = steep_feet(load_take(REPO / "sample_takes" / "kinect_v1_cmu_131_02_walk.krtake"))
    rig = build(LAYOUTS["ue4-mannequin"], a_pose_deg=30).target("UE4")
    pipe = RetargetPipeline(take.skeleton, rig, PRESETS["ue4-mannequin"], RetargetSettings())
    before = pipe.process_take(take)
    after = copy.deepcopy(before)
    lock = FootLock(pipe.retargeter)
    report = lock.apply(after, "lock", take.rate)
    legs = [rig.index(n) for n in ("calf_l", "foot_l", "ball_l")]
    toes = [rig.index(n) for n in ("foot_l", "ball_l")]
    shift = report.height_shift_cm / 100
    p0 = _posed(rig, before)
    p0[:, :, 2, 3] += shift  # the same body height in both pictures
    f = int(np.argmin(tips(rig, p0, toes)[..., 2].min(axis=1)))
    sticks_at = {}
    for label, posed in (("before", p0), ("after", _posed(rig, after))):
        heads = posed[f, legs, :3, 3]
        sticks_at[label] = heads, heads + posed[f, legs, :3, 1] * rig.lengths[legs, None]
    ends = np.concatenate([np.concatenate(v) for v in sticks_at.values()])
    lo, hi = ends.min(axis=0), ends.max(axis=0)
    lo[2] = min(lo[2], lock.floor)
    paths = []
    for label, (heads, tails) in sticks_at.items():
        bpy.ops.wm.read_factory_settings(use_empty=True)
        scene = bpy.context.scene
        sticks(heads, tails, 0.006, material("leg", (0.35, 0.35, 0.4, 1)), "leg")
        x = (lo[0] + hi[0]) / 2  # the floor seen edge-on: a red line at the rig's floor across the view
        sticks(np.array([[x, lo[1] - 0.15, lock.floor]]), np.array([[x, hi[1] + 0.15, lock.floor]]), 0.003,
               material("floor", (0.85, 0.15, 0.1, 1)), "floor")
        depth = 100 * max(0.0, lock.floor - float(tails[1:, 2].min()))
        setup_workbench(scene, (480, 360), f"{label}: toes {depth:.1f} cm under the floor (red)")
        frame_camera(scene, lo - [0, 0.15, 0.05], hi + [0, 0.15, 0], azimuth_deg=90, elevation_deg=0)
        paths.append(render_still(scene, str(HERE / f"toes_{label}.png"), 1))
    return contact_sheet(paths, str(HERE / "toes_before_after.png"), step=1)


def structure_picture() -> str:
    import addon_utils
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("rigify", default_set=True)
    bpy.ops.object.armature_human_metarig_add()
    obj = bpy.context.object
    rng = np.random.default_rng(16)
    for bone in obj.data.bones:
        bone.name = "".join(rng.choice(list("qwertyuiopasdfghjklzxcvbnm0123456789"), 9))
    bones = obj.data.bones
    names = [b.name for b in bones]
    heads = np.array([b.head_local for b in bones])
    tails = np.array([b.tail_local for b in bones])
    parents = [names.index(b.parent.name) if b.parent else -1 for b in bones]
    mapping = structure_mapping_for(names, parents, heads, tails).mapping
    groups = {"spine": [], "left": [], "right": [], "none": []}
    for i, n in enumerate(names):
        joint = mapping.get(n)
        key = "none" if joint is None else "left" if joint.endswith("Left") else "right" if joint.endswith(
            "Right") else "spine"
        groups[key].append(i)
    bpy.data.objects.remove(obj)
    colours = {"spine": (0.15, 0.3, 0.85, 1), "left": (0.1, 0.6, 0.2, 1), "right": (0.85, 0.15, 0.1, 1),
               "none": (0.6, 0.6, 0.62, 1)}
    shown = []
    for key, idx in groups.items():
        if idx:
            shown.append(sticks(heads[idx], tails[idx], 0.008 if key != "none" else 0.003,
                                material(key, colours[key]), key))
    scene = bpy.context.scene
    stage(scene, shown, [1], note=f"renamed metarig mapped by structure: {len(mapping)} of {len(names)} bones "
                                  "drive a joint (blue spine, green left, red right)", resolution=(480, 640))
    return render_still(scene, str(HERE / "structure_mapping.png"), 1)


if __name__ == "__main__":
    print(feet_pictures())
    print(toe_pictures())
    print(structure_picture())
