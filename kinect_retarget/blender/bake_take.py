"""Bake a take onto an armature: the one function behind the operator, the CLI and the demo."""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Callable

import bpy
import numpy as np
from bpy.utils import escape_identifier

from ..core.kinect_rig_layout import median_segment_lengths
from ..core.pipeline import BakedMotion, RetargetPipeline, RetargetSettings
from ..core.presets import build_mapping, mapping_problems
from ..core.skeletons import Skeleton
from ..core.take import Take
from .io.action_writer import bake_motion
from .io.evaluated_solve import correct_for_evaluation
from .io.kinect_rig import build_kinect_rig
from .io.pose_apply import restore_pose, snapshot_pose
from .io.rig_reader import fk_switch_bones, has_constrained_ancestry, target_rig_from_object

Report = Callable[[set, str], None]


@dataclass
class BakeResult:
    action: bpy.types.Action
    motion: BakedMotion
    preset: str
    frame_range: tuple[int, int]


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
    used, mapping = build_mapping(preset, rig.bone_names, overrides)
    return RetargetPipeline(skeleton, rig, mapping, settings), used


def bake_take(obj: bpy.types.Object, take: Take, *, preset: str = "auto",
              overrides: dict[str, str] | None = None, settings: RetargetSettings | None = None,
              action_name: str | None = None, set_scene_range: bool = True,
              report: Report = _no_report, progress: Callable[[float], None] | None = None) -> BakeResult:
    """Retarget `take` onto armature `obj` and key it into a new Action assigned to `obj`.

    Only pose channels are keyed; the rig's bones, rolls, constraints and settings are left as they are.
    Raises ValueError (wrong armature, no mapped bone) before anything in the scene changes.
    """
    settings = settings or RetargetSettings()
    pipeline, used = make_pipeline(obj, take.skeleton, preset, overrides, settings)
    for problem in mapping_problems(pipeline.rig.bone_names, overrides):
        report({"WARNING"}, problem)
    for warning in take.metadata.get("warnings", ()):  # what the reader dropped (bad samples, a cut-off line)
        report({"WARNING"}, warning)
    motion = pipeline.process_take(take)
    if progress:
        progress(0.3)
    extra = []
    if used == "rigify":
        extra = [(f'pose.bones["{escape_identifier(b)}"]["IK_FK"]', b, np.ones(1)) for b in fk_switch_bones(obj)]
    if has_constrained_ancestry(obj, motion.bone_names):
        saved = {name: obj.pose.bones[name]["IK_FK"] for _, name, _ in extra}
        saved_pose = snapshot_pose(obj)
        try:
            for _, name, _ in extra:
                obj.pose.bones[name]["IK_FK"] = 1.0
            n = len(motion.frames)
            motion.quats = correct_for_evaluation(
                obj, motion.bone_names, motion.quats, motion.root_bone, motion.root_location,
                motion.extras["desired"], (lambda f: progress(0.3 + 0.6 * f / n)) if progress else None)
        finally:  # the evaluation posed the rig; put the pose and the switches back whatever happened
            restore_pose(obj, saved_pose)
            for name, value in saved.items():
                obj.pose.bones[name]["IK_FK"] = value
    name = action_name or f"{obj.name}_{take.metadata.get('name', 'take')}"
    action = bake_motion(obj, motion, name, extra)
    first, last = int(motion.frames[0]), int(motion.frames[-1])
    if set_scene_range:
        scene = bpy.context.scene
        set_scene_rate(scene, motion.fps)
        scene.frame_start, scene.frame_end = first, last
    skipped = motion.extras.get("skipped_bones", ())
    report({"INFO"}, f"Baked {len(motion.frames)} frames ({len(motion.bone_names)} bones, preset {used}) "
                     f"onto {obj.name!r} as action {action.name!r}"
                     + (f"; left alone (the take has no position for their joints): {', '.join(skipped)}"
                        if skipped else ""))
    if progress:
        progress(1.0)
    return BakeResult(action, motion, used, (first, last))


def take_display_name(path: str) -> str:
    return os.path.splitext(os.path.basename(path))[0]
