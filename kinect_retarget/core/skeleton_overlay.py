"""The source skeleton as line and point geometry for the 3D View (blender/ui/source_overlay.py draws it with
`gpu`), so a user sees at once whether a glitch is the sensor's or the retarget's.

Pure numpy. Bones are lines from each joint to its parent; joints are points coloured by tracking state
(tracked green, inferred amber); a bone takes the colour of its less certain end; untracked joints (whose
positions mean nothing) and their bones are left out. Kinect camera space goes to Blender axes
(core/conventions.py). `OverlayPlacement` puts the skeleton beside its character: the performer's first
tracked root (horizontally) and the lowest foot seen land at the character's origin plus the user's offset,
so the skeleton travels as the character's root does and stands on the character's floor.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .conventions import kinect_to_blender
from .skeletons import INFERRED, NOT_TRACKED, TRACKED, Skeleton

COLORS = {TRACKED: (0.25, 0.9, 0.35, 1.0), INFERRED: (1.0, 0.72, 0.1, 1.0)}
FOOT_JOINTS = ("FootLeft", "FootRight", "AnkleLeft", "AnkleRight")


@dataclass
class OverlayGeometry:
    """lines (2B, 3) float32 endpoint pairs with colors (2B, 4); points (P, 3) with colors (P, 4)."""
    lines: np.ndarray
    line_colors: np.ndarray
    points: np.ndarray
    point_colors: np.ndarray

    @property
    def empty(self) -> bool:
        return len(self.points) == 0


class OverlayPlacement:
    """The performer's reference (first tracked root, horizontal; lowest foot, vertical) in Blender axes.
    Live learns it from the frames as they come (the floor can only go down); a take fixes it up front."""

    def __init__(self, reference_xy: np.ndarray | None = None, floor: float | None = None):
        self.reference_xy = None if reference_xy is None else np.asarray(reference_xy, dtype=np.float64)
        self.floor = floor

    @classmethod
    def for_take(cls, skeleton: Skeleton, positions: np.ndarray, states: np.ndarray) -> OverlayPlacement:
        """From a whole take: (F, J, 3) positions, (F, J) states."""
        placement = cls()
        for f in np.flatnonzero(states[:, skeleton.root] != NOT_TRACKED)[:1]:
            placement.reference_xy = kinect_to_blender(positions[f, skeleton.root])[:2]
        placement.floor = _lowest_foot(skeleton, kinect_to_blender(positions), states)
        return placement

    def shift(self, skeleton: Skeleton, points: np.ndarray, states: np.ndarray) -> np.ndarray:
        """The (3,) translation that moves this frame's Blender-axis points (J, 3) to the reference."""
        if self.reference_xy is None and states[skeleton.root] != NOT_TRACKED:
            self.reference_xy = points[skeleton.root, :2].copy()
        low = _lowest_foot(skeleton, points[None], states[None])
        if low is not None and (self.floor is None or low < self.floor):
            self.floor = low
        xy = self.reference_xy if self.reference_xy is not None else np.zeros(2)
        return -np.array([xy[0], xy[1], self.floor if self.floor is not None else 0.0])


def _lowest_foot(skeleton: Skeleton, points: np.ndarray, states: np.ndarray) -> float | None:
    """Lowest Blender Z of the tracked feet (or of any tracked joint when the skeleton has no feet)."""
    cols = [skeleton.index(n) for n in FOOT_JOINTS if n in skeleton.joints] or list(range(len(skeleton)))
    z = points[:, cols, 2]
    seen = (states[:, cols] != NOT_TRACKED) & np.isfinite(z)
    return float(z[seen].min()) if seen.any() else None


def skeleton_overlay(skeleton: Skeleton, positions: np.ndarray, states: np.ndarray, origin=(0.0, 0.0, 0.0),
                     placement: OverlayPlacement | None = None) -> OverlayGeometry:
    """One frame, (J, 3) Kinect camera space and (J,) states, as geometry in Blender world space: placed by
    `placement` (None: where the sensor saw it, in Blender axes) and moved by `origin` (the character's
    origin plus the user's offset)."""
    states = np.asarray(states, dtype=np.uint8)
    points = kinect_to_blender(positions)
    if placement is not None:
        points = points + placement.shift(skeleton, points, states)
    points = points + np.asarray(origin, dtype=np.float64)
    shown = (states != NOT_TRACKED) & np.all(np.isfinite(points), axis=1)
    parents = skeleton.parent_array
    bones = np.flatnonzero((parents >= 0) & shown & shown[np.maximum(parents, 0)])
    ends = np.stack([parents[bones], bones], axis=1).ravel()          # (2B,) joint of each line endpoint
    palette = np.zeros((3, 4), dtype=np.float32)
    for state, color in COLORS.items():
        palette[state] = color
    worse = np.minimum(states[parents[bones]], states[bones])         # the less certain end colours the bone
    joints = np.flatnonzero(shown)
    return OverlayGeometry(lines=points[ends].astype(np.float32),
                           line_colors=np.repeat(palette[worse], 2, axis=0),
                           points=points[joints].astype(np.float32), point_colors=palette[states[joints]])
