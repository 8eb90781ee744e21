""""Lift Clip Tracks to 3D": a tracked Movie Clip (tracks named after joints) -> a take baked onto a rig.

Only the Blender glue lives here: reading markers in bulk, the clip's camera, the operator and its menu
entry. Naming, lifting and the take are kinect_retarget.lift (pure numpy); baking is bake_take().
"""
from __future__ import annotations

import os

import bpy
import numpy as np

from ..core.pipeline import RetargetSettings
from ..lift import LiftError, LiftSettings, lift
from ..lift.clip_tracks import NamedTrack, tracks_from_named
from ..lift.tracks2d import Tracks2D

NEW_HANIM = "__NEW_HANIM__"
NEW_RIG = "__new__"


def named_tracks_from_clip(clip: bpy.types.MovieClip) -> list[NamedTrack]:
    """Every track of every tracking object, markers copied out with foreach_get (co is normalised with
    the origin at the bottom-left; pixels have v growing downward)."""
    w, h = clip.size
    out = []
    for obj in clip.tracking.objects:
        for track in obj.tracks:
            n = len(track.markers)
            co = np.zeros(2 * n, dtype=np.float32)
            frames = np.zeros(n, dtype=np.int32)
            mute = np.zeros(n, dtype=bool)
            track.markers.foreach_get("co", co)
            track.markers.foreach_get("frame", frames)
            track.markers.foreach_get("mute", mute)
            co = co.reshape(n, 2).astype(np.float64)
            uv = np.stack([co[:, 0] * w, (1.0 - co[:, 1]) * h], axis=1)
            out.append(NamedTrack(track.name, frames.astype(np.int64), uv, ~mute))
    return out


def clip_focal_px(clip: bpy.types.MovieClip) -> float:
    return float(clip.tracking.camera.focal_length_pixels)


def tracks_from_clip(clip: bpy.types.MovieClip, scene: bpy.types.Scene) -> Tracks2D:
    if clip.size[0] <= 0 or clip.size[1] <= 0:
        raise LiftError(f"clip '{clip.name}': its footage could not be loaded (size {tuple(clip.size)})")
    fps = clip.fps if clip.fps > 0 else scene.render.fps / scene.render.fps_base
    return tracks_from_named(named_tracks_from_clip(clip), fps, tuple(float(v) for v in clip.size),
                             f"clip '{clip.name}'")


def tracks_from_blend(path: str, clip_name: str | None = None) -> tuple[Tracks2D, float]:
    """For the CLI: open a .blend and read one Movie Clip's joint tracks; returns (tracks, focal px)."""
    if not os.path.isfile(path):
        raise LiftError(f"{path}: no such .blend file")
    bpy.ops.wm.open_mainfile(filepath=os.path.abspath(path))
    clips = list(bpy.data.movieclips)
    if clip_name:
        clip = bpy.data.movieclips.get(clip_name)
        if clip is None:
            raise LiftError(f"{path}: no Movie Clip named {clip_name!r} (clips: {', '.join(c.name for c in clips)})")
    elif len(clips) == 1:
        clip = clips[0]
    else:
        raise LiftError(f"{path}: {len(clips)} Movie Clips; choose one with --clip "
                        f"({', '.join(c.name for c in clips) or 'none'})")
    return tracks_from_clip(clip, bpy.context.scene), clip_focal_px(clip)


def load_image_rgb(path: str) -> np.ndarray:
    """Any image Blender reads -> (H, W, 3) float32 RGB, row 0 at the top (for the 2D tracker)."""
    img = bpy.data.images.load(os.path.abspath(path), check_existing=False)
    try:
        w, h = img.size
        if w == 0 or h == 0:
            raise LiftError(f"{path}: Blender could not read this image")
        px = np.empty(w * h * img.channels, dtype=np.float32)
        img.pixels.foreach_get(px)
        return px.reshape(h, w, img.channels)[::-1, :, :3].copy()
    finally:
        bpy.data.images.remove(img)


def lift_clip_and_bake(context, clip, armature: str, preset: str = "auto", height: float = 1.70,
                       use_clip_camera: bool = True, signs: str = "viterbi", take_path: str = "",
                       report=lambda level, msg: None, method: str = "ours"):
    """The operator's work, callable from scripts. Returns the BakeResult (the H-Anim armature object
    for armature=NEW_HANIM)."""
    from ..takes import krtake
    from .bake_take import bake_take, new_generated_rig

    tracks = tracks_from_clip(clip, context.scene)
    focal = clip_focal_px(clip) if use_clip_camera else None
    res = lift(tracks, LiftSettings(height_m=height, focal_px=focal, signs=signs, method=method))
    res.take.metadata["name"] = clip.name
    for msg in res.problems[:5]:
        report({"WARNING"}, msg)
    if len(res.problems) > 5:
        report({"WARNING"}, f"... and {len(res.problems) - 5} more problems (see the system console)")
        for msg in res.problems[5:]:
            print(f"kinect_retarget: {msg}")
    if take_path:
        krtake.write(take_path, res.take)
    if armature == NEW_HANIM:
        from .io.hanim_figure import build_hanim_figure
        first = int(tracks.frame_numbers[0]) + clip.frame_start - 1
        obj = build_hanim_figure(context, res.take, f"{clip.name}_HAnim", frame_start=first)
        report({"INFO"}, f"Lifted {res.take.frame_count} frames of clip '{clip.name}' ({method}) onto the "
                         f"H-Anim figure {obj.name}")
        return obj
    if armature == NEW_RIG or armature not in context.scene.objects:
        obj = new_generated_rig(context.scene, res.take, f"{clip.name}_Rig")
    else:
        obj = context.scene.objects[armature]
    # keys line up with the footage: the first tracked clip frame lands on its scene frame, at the clip rate
    first = int(tracks.frame_numbers[0]) + clip.frame_start - 1
    settings = RetargetSettings(fps=res.take.rate, frame_start=first)
    out = bake_take(obj, res.take, preset=preset, settings=settings, report=report)
    report({"INFO"}, f"Lifted {res.take.frame_count} frames of clip '{clip.name}' "
                     f"({'focal ' + format(focal, '.0f') + ' px' if focal else 'orthographic'})")
    return out


def sequence_files(clip: bpy.types.MovieClip) -> list[str]:
    """The image files of an image-sequence clip, clip frame 1 first."""
    import re

    from ..lift.image_sequence import list_frames
    path = bpy.path.abspath(clip.filepath)
    stem = re.sub(r"\d+(\.\w+)$", "", os.path.basename(path))
    files = [f for f in list_frames(os.path.dirname(path)) if os.path.basename(f).startswith(stem)]
    return files[clip.frame_offset:]


def track_clip_joints(clip: bpy.types.MovieClip, start: int, end: int | None = None,
                      settings=None, report=lambda level, msg: None) -> dict:
    """Paper 004's tracker on an image-sequence clip: every joint-named track with a marker on clip frame
    `start` is followed to `end` (default: the clip's last frame); its markers are written as it goes,
    muted where the joint is lost."""
    from ..lift.clip_naming import joint_for_track
    from ..lift.joint_tracker import JointTracker, TrackerSettings

    if clip.source != "SEQUENCE":
        raise LiftError(f"clip '{clip.name}': the joint tracker reads image sequences (this clip is a "
                        f"{clip.source.lower()}); render the footage to images, or track with Blender's tracker")
    files = sequence_files(clip)
    end = min(end or len(files), len(files))
    w, h = clip.size
    tracks = {}
    for obj in clip.tracking.objects:
        for t in obj.tracks:
            m = t.markers.find_frame(start, exact=True)
            if m is not None and not m.mute and joint_for_track(t.name):
                tracks[t.name] = (t, (m.co[0] * w, (1.0 - m.co[1]) * h))
    if not tracks:
        raise LiftError(f"clip '{clip.name}': no joint-named track has a marker on frame {start} "
                        f"(place one marker per joint there; see docs/lifting.md for names)")
    first = load_image_rgb(files[start - 1])
    tracker = JointTracker(first, {n: uv for n, (_, uv) in tracks.items()}, settings or TrackerSettings())
    lost = 0
    for frame in range(start + 1, end + 1):
        r = tracker.step(load_image_rgb(files[frame - 1]))
        for k, name in enumerate(tracker.names):
            marker = tracks[name][0].markers.insert_frame(frame, co=(r.uv[k, 0] / w, 1.0 - r.uv[k, 1] / h))
            marker.mute = not bool(r.found[k])
        lost += int((~r.found).sum())
    n = max(end - start, 1) * len(tracker.names)
    report({"INFO"}, f"Tracked {len(tracker.names)} joints over frames {start}-{end}; lost {lost / n:.1%} "
                     f"of joint-frames")
    return {"joints": list(tracker.names), "frames": (start, end), "lost_fraction": lost / n}
