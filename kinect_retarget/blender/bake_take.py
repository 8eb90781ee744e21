"""Bake a take onto an armature: the one function behind the operator, the CLI and the demo."""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, replace
from typing import Callable

import bpy
import numpy as np
from bpy.utils import escape_identifier

from ..core.bake_options import BakeOptions, take_range
from ..core.key_reduction import Reduction, reduce_keys
from ..core.foot_lock import FeetReport, FootLock, key_rate
from ..core.kinect_rig_layout import median_segment_lengths
from ..core.pipeline import BakedMotion, RetargetPipeline, RetargetSettings
from ..core.presets import PRESET_INFO, STRUCTURE, build_mapping, mapping_problems
from ..core.resample import resample_motion
from ..core.root_motion import apply_root_motion, followed_root, root_follows_by_constraints
from ..core.rotation_modes import channel_values
from ..core.skeletons import Skeleton
from ..core.take import Take
from .io.action_writer import bake_motion, push_to_nla
from .io.armature_probe import constrained_summary, solve_baked
from .io.finger_rig import apply_hands, hands_on_rig
from .io.kinect_rig import build_kinect_rig
from .io.rig_reader import fk_switch_bones, has_constrained_ancestry, target_rig_from_object
from .io.root_follow import root_follow_problem

Report = Callable[[set, str], None]


@dataclass
class BakeResult:
    action: bpy.types.Action
    motion: BakedMotion
    preset: str
    frame_range: tuple[int, int]
    reduction: Reduction | None = None
    strip: str | None = None
    feet: FeetReport | None = None


def _no_report(level: set, message: str) -> None:
    pass


def new_generated_rig(scene: bpy.types.Scene, take: Take, name: str = "KinectRig") -> bpy.types.Object:
    return build_kinect_rig(scene, take.skeleton, median_segment_lengths(take), name)


def set_scene_rate(scene: bpy.types.Scene, rate: float) -> None:
    """Run the scene at `rate` frames per second (an integer fps and the base that makes it exact)."""
    scene.render.fps = max(1, int(round(rate)))
    scene.render.fps_base = scene.render.fps / rate


def make_pipeline(obj: bpy.types.Object, skeleton: Skeleton, preset: str = "auto",
                  overrides: dict[str, str] | None = None,
                  settings: RetargetSettings | None = None) -> tuple[RetargetPipeline, str]:
    """The pipeline from `skeleton` onto armature `obj` (bake and live), and the preset used."""
    rig = target_rig_from_object(obj)
    used, mapping = build_mapping(preset, rig.bone_names, overrides, rig)
    return RetargetPipeline(skeleton, rig, mapping, settings), used


def scene_rate(scene: bpy.types.Scene) -> float:
    return scene.render.fps / scene.render.fps_base


def _reduce(obj, motion: BakedMotion, options: BakeOptions) -> Reduction | None:
    if not options.reduce:
        return None
    pose_bones = obj.pose.bones
    rotations = []
    for k, bone in enumerate(motion.bone_names):
        mode = pose_bones[bone].rotation_mode
        rotations.append((channel_values(motion.quats[:, k], mode)[1], mode))
    location = motion.root_location if motion.root_bone is not None else None
    return reduce_keys(motion.frames, rotations, location, options.tolerance_deg, options.tolerance_mm,
                       motion.extras.get("locations"))


def _update_scene(scene: bpy.types.Scene, rate: float, first: int, last: int, options: BakeOptions) -> str:
    """Apply the scene options; a sentence saying what the scene is now (and when keys run past its range)."""
    changed = []
    if options.set_scene_fps and abs(scene_rate(scene) - rate) > 1e-6:
        set_scene_rate(scene, rate)
        changed.append("frame rate")
    if options.extend_scene_range and (first < scene.frame_start or last > scene.frame_end):
        # never shortens: only the ends the keys pass move
        scene.frame_start, scene.frame_end = min(scene.frame_start, first), max(scene.frame_end, last)
        changed.append("range")
    now = f"{scene_rate(scene):g} fps, frames {scene.frame_start}-{scene.frame_end}"
    if changed:
        return f"scene {' and '.join(changed)} set: {now}"
    outside = first < scene.frame_start or last > scene.frame_end
    return f"scene unchanged ({now}" + ("; keys run outside it: Extend Scene Range grows it)" if outside else ")")


def bake_take(obj: bpy.types.Object, take: Take, *, preset: str = "auto",
              overrides: dict[str, str] | None = None, settings: RetargetSettings | None = None,
              action_name: str | None = None, options: BakeOptions | None = None,
              report: Report = _no_report, progress: Callable[[float], None] | None = None) -> BakeResult:
    """Retarget `take` onto armature `obj` and key it into a new Action assigned to `obj` (or as `options`
    say: part of the take, key step, key reduction, the current Action, an NLA strip).

    Keys follow the scene's frame rate (settings.fps when given; the take's own with Set Scene Frame Rate),
    resampled from the take's samples; the scene's rate and range change only when the options ask.
    Only pose channels are keyed; the rig's bones, rolls, constraints and settings are left as they are.
    Raises ValueError (wrong armature, no mapped bone, empty range) before anything in the scene changes.
    """
    settings = settings or RetargetSettings()
    options = options or BakeOptions()
    scene = bpy.context.scene
    whole = take
    take, part = take_range(take, options)
    rate = float(settings.fps or (take.rate if options.set_scene_fps else scene_rate(scene)))
    # at the take's own rate each sample keys its frame; otherwise solve at the take's samples and key on the
    # scene's frame grid
    on_samples = options.step == 1 and (options.keys_on_samples or abs(rate - take.rate) < 1e-6)
    pipeline, used = make_pipeline(obj, take.skeleton, preset, overrides,
                                   replace(settings, fps=rate if on_samples else None))
    for problem in mapping_problems(pipeline.rig.bone_names, overrides):
        report({"WARNING"}, problem)
    for warning in take.metadata.get("warnings", ()):  # what the reader dropped (bad samples, a cut-off line)
        report({"WARNING"}, warning)
    motion = pipeline.process_take(take)
    if not on_samples:
        motion = resample_motion(motion, take.times[motion.samples] - take.times[0], rate, settings.frame_start,
                                 options.step)
    feet = FootLock(pipeline.retargeter).apply(motion, options.feet, key_rate(motion))
    if progress:
        progress(0.3)
    extra = []
    if used in ("rigify", STRUCTURE):  # Rigify's limbs switched to FK (no switch on other rigs)
        extra = [(f'pose.bones["{escape_identifier(b)}"]["IK_FK"]', b, np.ones(1)) for b in fk_switch_bones(obj)]
    # the root: named, the preset's (Mannequin's, Rigify's root), or the one a renamed Rigify's hips follow
    root_named = options.root_bone or PRESET_INFO.get(used, {}).get("root_motion_bone") or (
        followed_root(pipeline.rig, motion.root_bone) if used == STRUCTURE else None)
    root_note = ""
    if options.root_motion and root_follows_by_constraints(pipeline.rig, motion, root_named):
        # Rigify: the hips follow the root by constraints; once verified, the root joins the constrained solve,
        # which turns the hips (and whatever else follows the root) back
        root_note = "; " + apply_root_motion(motion, pipeline.rig, options.root_motion_facing, root_named,
                                             lambda r, h: root_follow_problem(obj, pipeline.rig, r, h))
    if has_constrained_ancestry(obj, motion.bone_names):
        n = len(motion.frames)
        model = solve_baked(obj, pipeline.rig, motion, {name: 1.0 for _, name, _ in extra},
                            (lambda f: progress(0.3 + 0.6 * f / n)) if progress else None, options.into_current)
        report({"INFO"}, constrained_summary(model))
    fingers = []
    if options.hands == "on" or (options.hands == "auto" and "HandTipLeft" in take.skeleton.joints):
        fingers = apply_hands(motion, hands_on_rig(obj, pipeline.retargeter.mapped), take, take.skeleton.joints,
                              settings.mirror)
    if options.root_motion and not root_note:  # after the constrained solve: the keys are final, only the hips change
        root_note = "; " + apply_root_motion(motion, pipeline.rig, options.root_motion_facing, root_named)
    take_name = whole.metadata.get("name", "take")
    name = action_name or f"{obj.name}_{take_name}"
    reduction = _reduce(obj, motion, options)
    action = bake_motion(obj, motion, name, extra, keys=reduction, into_current=options.into_current)
    first, last = int(motion.frames[0]), int(motion.frames[-1])
    strip = push_to_nla(obj, take_name, first).name if options.push_nla else None
    scene_note = _update_scene(scene, rate, first, last, options)
    skipped = motion.extras.get("skipped_bones", ())
    every = f", every {options.step} frames" if options.step > 1 else ""
    report({"INFO"}, f"Baked {len(motion.frames)} keys at frames {first}-{last} ({rate:g} fps{every}; "
                     f"{part or 'whole take'}, {whole.rate:g} fps) for {len(motion.bone_names)} bones "
                     f"(preset {used}) onto {obj.name!r} as action {action.name!r}"
                     + (f", NLA strip {strip!r}" if strip else "") + f"; {scene_note}"
                     + (f"; hands: {len(fingers)} finger bones keyed (thumb roll, hand-tip bend"
                        f"{', hand states' if take.hand_states is not None else ''})" if fingers else "")
                     + (f"; key reduction removed {reduction.removed} keys (max error {reduction.max_deg:.3f}°, "
                        f"{reduction.max_mm:.3f} mm)" if reduction else "")
                     + (f"; left alone (the take has no position for their joints): {', '.join(skipped)}"
                        if skipped else "") + root_note + f"; {feet.summary()}" + _reading(take.metadata))
    if progress:
        progress(1.0)
    return BakeResult(action, motion, used, (first, last), reduction, strip, feet)


def _reading(meta: dict) -> str:
    """What was guessed while reading a BVH file, for the bake report."""
    if "bvh_unit" not in meta:
        return ""
    up, axis = meta.get("bvh_up"), meta["bvh_up_axis"]
    tilt = math.degrees(math.acos(min(1.0, abs(up["XYZ".index(axis[1])])))) if up else 0.0
    tilted = f" (the floor tilted {tilt:.1f} degrees from it)" if tilt > 0.05 else ""
    return (f"; BVH read in {meta['bvh_unit']}, {axis} up{tilted}, figure "
            f"{meta['bvh_standing_height_m']:.2f} m tall, {meta['bvh_position_channels']}")


def take_display_name(path: str) -> str:
    return os.path.splitext(os.path.basename(path))[0]
