"""Ground truth for lifting tests: a CMU optical take at video rate, seen by a known camera."""
from __future__ import annotations

import numpy as np

from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.core.take import Take
from kinect_retarget.lift.video_camera import Camera, view_points
from kinect_retarget.takes import bvh

IMAGE = (1280, 720)
FOCAL = 1000.0


def walking_take(data_dir, seconds: float = 6.0, name: str = "131_02.bvh") -> Take:
    take = bvh.read(data_dir / "mocap_bvh" / name)
    step = int(round(take.rate / 30.0))
    frames = np.arange(0, take.frame_count, step)
    return take.slice(frames[take.times[frames] <= seconds])


def seen_from(take: Take, azimuth: float, elevation: float = 5.0, distance: float = 4.5) -> Take:
    pos = view_points(take.positions, azimuth, elevation, distance, take.positions[:, 0].mean(axis=0))
    return Take(KINECT_V1, pos, take.states, take.times, take.rate)


def camera() -> Camera:
    return Camera.for_image(*IMAGE, FOCAL)


def true_signs(pos: np.ndarray, perspective: bool = True) -> np.ndarray:
    from kinect_retarget.sim.lift_scoring import ray_sides
    return ray_sides(pos, KINECT_V1.parent_array, camera() if perspective else None)


def rigid(take: Take) -> Take:
    """The take with every bone at its median length (directions kept): the BVH reader averages a few
    joints (spine, head), which wobble by a fraction of a millimetre, and a bone lying in the image
    plane turns that into centimetres of depth. Exactness tests need a rigid skeleton."""
    from kinect_retarget.core.skeletons import topological_order
    from kinect_retarget.lift.bones import lengths_from_take
    lengths = lengths_from_take(take)
    par = KINECT_V1.parent_array
    out = take.positions.copy()
    for j in topological_order(KINECT_V1)[1:]:
        v = take.positions[:, j] - take.positions[:, par[j]]
        out[:, j] = out[:, par[j]] + lengths[j] * v / np.linalg.norm(v, axis=-1, keepdims=True)
    return Take(KINECT_V1, out, take.states, take.times, take.rate)
