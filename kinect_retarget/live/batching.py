"""Advance the pipeline over a batch of frames but solve only the newest tracked one.

The filter must see every frame (so live equals the bake, which filters every frame), but only the newest
pose is shown; the solve is ~100x the filter's cost per frame. The result equals calling
`process_frame` on each frame in turn and keeping the last pose. Uses the engine's `process_frames` when it
has one; otherwise its filter and solver directly; otherwise `process_frame` frame by frame.
"""
from __future__ import annotations

import numpy as np

from ..core.skeletons import NOT_TRACKED


def process_batch(pipeline, positions: np.ndarray, states: np.ndarray, times: np.ndarray):
    """positions (K, J, 3), states (K, J), times (K,) -> FramePose of the last tracked frame, or None."""
    batch = getattr(pipeline, "process_frames", None)
    if batch is not None:
        return batch(positions, states, times)
    if not (hasattr(pipeline, "_filtered") and hasattr(pipeline, "retargeter")):
        pose = None
        for p, s, t in zip(positions, states, times):
            pose = pipeline.process_frame(p, s, float(t)) or pose
        return pose
    from ..core.pipeline import FramePose

    tracked = np.flatnonzero(np.any(states != NOT_TRACKED, axis=1))
    if tracked.size == 0:
        return None
    pos, st, tt = positions[tracked], states[tracked], times[tracked]
    bad = (st != NOT_TRACKED) & ~np.all(np.isfinite(pos), axis=-1)
    if bad.any():
        raise ValueError("frame has NaN or infinite positions for tracked joints")
    filtered = pipeline._filtered(pos, st, tt)
    if pipeline.root_reference is None:
        pipeline.root_reference = filtered[0, pipeline.skeleton.root].copy()
    quats, location, desired = pipeline.retargeter.solve(filtered[-1:], pipeline.root_reference,
                                                         pipeline.source_leg, want_desired=True)
    pose = FramePose(pipeline.bone_names, quats[0], pipeline.root_bone, location[0], float(tt[-1]))
    pose.desired = desired[0]  # for rigs with constrained parents (live/constrained.py)
    return pose
