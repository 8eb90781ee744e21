"""Planted feet (issue 16): foot slide during detected contacts and floor penetration before and after the
feet pass (core/foot_lock.py, core/toe_floor.py) for the ankles and the toe tips, and how much the limbs'
directions change where it does not act, on every sample take with walking, hopping or jumping and on the
Kinect v2 gestures, baked onto the generated Kinect rig, MakeHuman's default skeleton (a real third-party rig
with twist bones and fifteen toe bones) and Unreal's UE4 bone layout (a ball bone under each foot).

    .venv/bin/python benchmarks/bench_feet.py

Without Blender: the solver and its Blender-like forward kinematics (the bpy tests check Blender agrees).
Slide: the ankle's horizontal distance from its contact's mean place, over every contact frame (median and
95th percentile, cm), measured on the rig's forward kinematics before and after. Ankle below: the deepest
ankle under its rest height over the floor (cm). Toe below: the deepest tip of the foot bone or of any toe bone
in front of the ankle under the floor (the rest pose's lowest point), cm; pitched: frames whose foot the pass
turned up about the ankle to keep them there. Directions: the largest change (degrees) of any mapped bone's
direction on frames the pass leaves alone (legs outside contacts, their eases and floor fixes; every other bone
on every frame). Body: the one vertical shift that stands planted feet on the floor. Prints figures only.

Then, with bpy, the generated Rigify rig (its legs hang from constraint-driven MCH parents, so the pass's
numpy forward kinematics is only an approximation there): each take baked in Blender with --feet off and
lock (the bake's constrained solve follows the edited desired rotations), and the slide and floor measured on
Blender's own evaluation of DEF-foot's head (what the mesh follows) at every key, during the contacts the
lock bake detected, beside the pass's own numpy figure.
"""
from __future__ import annotations

import copy

import _common
import numpy as np

from kinect_retarget.core.foot_lock import FootLock
from kinect_retarget.core.kinect_rig_layout import generated_mapping, generated_rig, median_segment_lengths
from kinect_retarget.core.pipeline import RetargetPipeline, RetargetSettings
from kinect_retarget.core.presets import PRESETS
from kinect_retarget.core.target_rig import evaluate_pose
from kinect_retarget.takes import load_take
from tests.rigs.humanoid_rigs import build, makehuman_rig
from tests.rigs.layouts import LAYOUTS

TAKES = ["kinect_v1_cmu_131_01_walk", "kinect_v1_cmu_131_02_walk", "kinect_v1_cmu_131_03_hop",
         "kinect_v1_cmu_01_01_jumps"] + [f"kinect_v2_ges0{i}_{n}" for i, n in enumerate(
             ("wavehand", "balancinghands", "drawlines", "comehere", "demopoint", "chickenwing"), start=1)]


def directions(rig, motion):
    idx = np.array([rig.index(b) for b in motion.bone_names])
    root = rig.index(motion.root_bone) if motion.root_bone else None
    return evaluate_pose(rig, idx, motion.quats, root, motion.root_location)[:, idx][..., :3, 1]


def measure(take, rig, mapping):
    pipe = RetargetPipeline(take.skeleton, rig, mapping, RetargetSettings())
    before = pipe.process_take(take)
    after = copy.deepcopy(before)
    report = FootLock(pipe.retargeter).apply(after, "lock", take.rate)
    d0, d1 = directions(rig, before), directions(rig, after)
    angle = np.degrees(np.arccos(np.clip(np.sum(d0 * d1, -1), -1, 1)))     # (F, M)
    leave = np.ones_like(angle, bool)
    legs = {side: bones for side, bones in FootLock(pipe.retargeter).legs.items()}
    for leg in report.legs:
        for m in legs[leg.side]:
            if m is not None and m.bone in after.bone_names:
                leave[leg.changed, after.bone_names.index(m.bone)] = False
    return report, float(angle[leave].max()) if leave.any() else 0.0


def main() -> None:
    rigs = {"generated": None, "makehuman": makehuman_rig().target("MakeHuman"),
            "ue4": build(LAYOUTS["ue4-mannequin"], a_pose_deg=30).target("UE4")}
    print(f"{'take':<36} {'rig':<10} {'side':<5} {'contacts':>8} {'slide before':>14} {'slide after':>13} "
          f"{'ankle below':>12} {'toe below':>12} {'pitched':>7} {'body':>6} {'dir. change':>11}")
    print(f"{'':<36} {'':<10} {'':<5} {'(frames)':>8} {'med/p95 cm':>14} {'med/p95 cm':>13} {'cm bef/aft':>12} "
          f"{'cm bef/aft':>12} {'frames':>7} {'cm':>6} {'deg':>11}")
    worst, toes_after, changes = [], [], []
    for name in TAKES:
        take = load_take(_common.SAMPLE_TAKES / f"{name}.krtake")
        for rig_name, rig in rigs.items():
            if rig is None:
                target, mapping = generated_rig(take.skeleton, median_segment_lengths(take)), generated_mapping(
                    take.skeleton)
            else:
                target, mapping = rig, PRESETS["makehuman" if rig_name == "makehuman" else "ue4-mannequin"]
            report, change = measure(take, target, mapping)
            changes.append(change)
            for leg in report.legs:
                worst.append(leg.slide_after_cm[1])
                toes_after.append(leg.toe_below_after_cm)
                print(f"{name:<36} {rig_name:<10} {leg.side:<5} {leg.contacts:>3} ({leg.contact_frames:>4}) "
                      f"{leg.slide_before_cm[0]:>6.2f}/{leg.slide_before_cm[1]:<6.2f} "
                      f"{leg.slide_after_cm[0]:>5.2f}/{leg.slide_after_cm[1]:<6.2f} "
                      f"{leg.below_floor_before_cm:>5.1f}/{leg.below_floor_after_cm:<5.2f} "
                      f"{leg.toe_below_before_cm:>5.1f}/{leg.toe_below_after_cm:<5.2f} {leg.toe_frames:>7} "
                      f"{report.height_shift_cm:>6.1f} {change:>11.2e}")
    print(f"worst slide p95 after: {max(worst):.3f} cm (goal <= 1 cm); deepest toe after: {max(toes_after):.2g} cm; "
          f"largest direction change where the pass does not act: {max(changes):.2e} deg (goal <= 0.01)")
    rigify()


def _ankles(bpy, obj, frames, bones, toes):
    """(F, 2, 3) world heads of `bones` and (F, 2) lowest world tail (z) of each side's `toes`, as Blender
    evaluates the rig at each frame."""
    out, low = [], []
    for f in frames:
        bpy.context.scene.frame_set(int(f))
        out.append([np.array(obj.matrix_world @ obj.pose.bones[b].head) for b in bones])
        low.append([min((obj.matrix_world @ obj.pose.bones[b].tail)[2] for b in side) for side in toes])
    return np.array(out), np.array(low)


def _slide_cm(ankle, contact):
    """Median and p95 horizontal distance (cm) from each contact's mean place, over its frames."""
    from kinect_retarget.core.foot_contacts import intervals
    d = [np.linalg.norm(ankle[a:b + 1, :2] - ankle[a:b + 1, :2].mean(axis=0), axis=-1)
         for a, b in intervals(contact)]
    d = np.concatenate(d) if d else np.zeros(1)
    return 100 * float(np.median(d)), 100 * float(np.percentile(d, 95))


def rigify() -> None:
    try:
        import bpy  # noqa: I001 (addon_utils needs bpy first)
        import addon_utils
    except ImportError:
        print("Rigify: skipped (no bpy)")
        return
    import tempfile

    from bench_constrained_bake import rigify_file

    from kinect_retarget.blender.bake_take import bake_take
    from kinect_retarget.core.bake_options import BakeOptions
    path = f"{tempfile.mkdtemp()}/rigify.blend"
    rigify_file(path, body=False)
    addon_utils.enable("rigify", default_set=True)  # its load handlers expect its properties
    bpy.ops.wm.open_mainfile(filepath=path)
    obj = bpy.data.objects["rig"]
    bones = {"Left": "DEF-foot.L", "Right": "DEF-foot.R"}
    toes = {s: [b, b.replace("foot", "toe")] for s, b in bones.items()}   # the deform foot's and toe's tails
    floor = {s: obj.data.bones[b].head_local[2] for s, b in bones.items()}
    ground = min(min(b.head_local[2], b.tail_local[2]) for b in obj.data.bones)   # the pass's floor
    print("\nRigify, measured on Blender's evaluation of DEF-foot's head and DEF-foot/DEF-toe's tails (numpy FK "
          "estimate of the slide in brackets)")
    print(f"{'take':<36} {'side':<5} {'contacts':>8} {'slide before':>14} {'slide after':>13} {'(numpy)':>8} "
          f"{'ankle below':>12} {'toe below':>12}")
    worst, deepest = [], []
    for name in TAKES:
        take = load_take(_common.SAMPLE_TAKES / f"{name}.krtake")
        settings = RetargetSettings(fps=take.rate)
        off = bake_take(obj, take, preset="rigify", settings=settings, options=BakeOptions(feet="off"))
        before, low0 = _ankles(bpy, obj, off.motion.frames, bones.values(), toes.values())
        lock = bake_take(obj, take, preset="rigify", settings=settings, options=BakeOptions(feet="lock"))
        after, low1 = _ankles(bpy, obj, lock.motion.frames, bones.values(), toes.values())
        toe_low = {s: [100 * max(0.0, ground - float(x[:, i].min())) for x in (low0, low1)]
                   for i, s in enumerate(bones)}
        assert lock.feet is not None
        for leg in lock.feet.legs:
            k = list(bones).index(leg.side)
            b, a = _slide_cm(before[:, k], leg.contact), _slide_cm(after[:, k], leg.contact)
            low = [100 * max(0.0, floor[leg.side] - float(x[:, k, 2].min())) for x in (before, after)]
            worst.append(a[1])
            deepest += [low[1], toe_low[leg.side][1]]
            print(f"{name:<36} {leg.side:<5} {leg.contacts:>3} ({leg.contact_frames:>4}) {b[0]:>6.2f}/{b[1]:<6.2f} "
                  f"{a[0]:>5.2f}/{a[1]:<6.2f} ({leg.slide_after_cm[1]:>5.2f}) {low[0]:>5.1f}/{low[1]:<5.2f} "
                  f"{toe_low[leg.side][0]:>5.1f}/{toe_low[leg.side][1]:<5.2f}")
    print(f"Rigify worst slide p95 after: {max(worst):.3f} cm (goal <= 1 cm); deepest ankle or toe after: "
          f"{max(deepest):.2g} cm")


if __name__ == "__main__":
    main()
