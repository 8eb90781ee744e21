"""2D tracks from named point tracks (Blender Movie Clip tracking, or anything shaped like it).

The Blender side (blender/clip_lift.py) only copies each track's markers out as arrays; everything else
(naming, frame range, joints derived from others) is here, without bpy.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.skeletons import KINECT_V1
from .clip_naming import match_tracks
from .schemes import HAND_EXTENSION, SPINE_FRACTION
from .tracks2d import LiftError, Tracks2D

SK = KINECT_V1


@dataclass
class NamedTrack:
    """frames (n,) int clip frames; uv (n, 2) pixels (u right, v down); enabled (n,) False where the
    marker is disabled (the tracker lost the point or the user switched it off)."""

    name: str
    frames: np.ndarray
    uv: np.ndarray
    enabled: np.ndarray


def tracks_from_named(tracks: list[NamedTrack], fps: float, image_size, source: str,
                      frame_range: tuple[int, int] | None = None) -> Tracks2D:
    if not tracks:
        raise LiftError(f"{source}: the clip has no tracks (track the joints first; see docs/lifting.md)")
    mapping, problems = match_tracks([t.name for t in tracks])
    if not mapping:
        raise LiftError(f"{source}: no track is named after a joint. {problems[-1] if problems else ''}")
    problems = [f"{source}: {p}" for p in problems]
    used = [t for t in tracks if t.name in mapping]
    all_frames = np.concatenate([t.frames[t.enabled] for t in used]) if used else np.zeros(0, int)
    if all_frames.size == 0:
        raise LiftError(f"{source}: the joint tracks have no enabled markers")
    lo, hi = frame_range or (int(all_frames.min()), int(all_frames.max()))
    frames = np.arange(lo, hi + 1)
    uv = np.full((len(frames), len(SK), 2), np.nan)
    conf = np.zeros((len(frames), len(SK)))
    for t in used:
        j = SK.index(mapping[t.name])
        keep = t.enabled & (t.frames >= lo) & (t.frames <= hi) & np.isfinite(t.uv).all(axis=1)
        uv[t.frames[keep] - lo, j] = t.uv[keep]
        conf[t.frames[keep] - lo, j] = 1.0
    inferred = derive_missing(uv, conf)
    if not (conf[:, SK.root] > 0).any():
        problems.append(f"{source}: no HipCenter track and no pair of hip tracks: the body cannot be placed")
    times = (frames - lo) / float(fps)
    return Tracks2D(uv, conf, times, image_size, source, inferred, problems, frame_numbers=frames)


def derive_missing(uv: np.ndarray, conf: np.ndarray) -> np.ndarray:
    """Fill joints that follow from tracked neighbours (in place); returns the (F, J) inferred mask."""
    inferred = np.zeros(conf.shape, dtype=bool)

    def fill(j: str, parts: list[tuple[str, float]]):
        ji = SK.index(j)
        idx = [SK.index(p) for p, _ in parts]
        w = np.array([wt for _, wt in parts])
        ok = (conf[:, ji] <= 0) & np.all(conf[:, idx] > 0, axis=1)
        uv[ok, ji] = np.einsum("fkc,k->fc", uv[ok][:, idx], w)
        conf[ok, ji] = conf[ok][:, idx].min(axis=1)
        inferred[ok, ji] = True

    fill("HipCenter", [("HipLeft", 0.5), ("HipRight", 0.5)])
    fill("ShoulderCenter", [("ShoulderLeft", 0.5), ("ShoulderRight", 0.5)])
    fill("Spine", [("HipCenter", 1 - SPINE_FRACTION), ("ShoulderCenter", SPINE_FRACTION)])
    for side in ("Left", "Right"):
        fill(f"Hand{side}", [(f"Wrist{side}", 1 + HAND_EXTENSION), (f"Elbow{side}", -HAND_EXTENSION)])
    return inferred
