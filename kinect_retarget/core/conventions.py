"""The project's conventions, defined once (see docs/conventions.md).

* Units: metres.
* Quaternions: (w, x, y, z), Hamilton product, unit norm; rotations act on column vectors (v' = R v).
* Kinect camera space: +X toward the sensor's left (the performer's right when facing it), +Y up,
  +Z away from the sensor.
* Blender world: Z up. A performer facing the sensor drives a character facing -Y, so the Kinect point
  (x, y, z) maps to (-x, z, y). The matrix is a proper rotation (det +1): nothing is mirrored.
* Mirroring (swapping the performer's left and right) is an explicit option: `mirror_positions`.
* Depth images are kept as the camera sees them: pixel column u at depth z is Kinect X = -(u - cx) * z / f.
"""
from __future__ import annotations

import numpy as np

KINECT_TO_BLENDER = np.array([[-1.0, 0.0, 0.0],
                              [0.0, 0.0, 1.0],
                              [0.0, 1.0, 0.0]])


def kinect_to_blender(points: np.ndarray) -> np.ndarray:
    """(..., 3) Kinect camera-space points -> (..., 3) Blender world points (same units)."""
    p = np.asarray(points, dtype=np.float64)
    return np.stack([-p[..., 0], p[..., 2], p[..., 1]], axis=-1)


def blender_to_kinect(points: np.ndarray) -> np.ndarray:
    p = np.asarray(points, dtype=np.float64)
    return np.stack([-p[..., 0], p[..., 2], p[..., 1]], axis=-1)


def mirror_positions(positions: np.ndarray, mirror_index: np.ndarray) -> np.ndarray:
    """Swap left and right: reflect Kinect X and exchange each joint with its counterpart.

    positions: (..., J, 3) Kinect camera space; mirror_index: (J,) from Skeleton.mirror.
    """
    out = np.array(positions, dtype=np.float64)[..., mirror_index, :]
    out[..., 0] *= -1.0
    return out


def depth_pixel_to_kinect(u: np.ndarray, v: np.ndarray, z: np.ndarray,
                          f: float, cx: float, cy: float) -> np.ndarray:
    """Back-project depth pixels (column u, row v, depth z metres) to (..., 3) Kinect camera space.

    Row v grows downward in the image while Kinect Y points up; column u grows to the camera's right,
    which is Kinect -X.
    """
    z = np.asarray(z, dtype=np.float64)
    x = -(np.asarray(u, dtype=np.float64) - cx) * z / f
    y = -(np.asarray(v, dtype=np.float64) - cy) * z / f
    return np.stack([x, y, z], axis=-1)


def kinect_to_depth_pixel(points: np.ndarray, f: float, cx: float, cy: float) -> np.ndarray:
    """(..., 3) Kinect camera space -> (..., 2) pixel (u, v); inverse of depth_pixel_to_kinect."""
    p = np.asarray(points, dtype=np.float64)
    return np.stack([cx - f * p[..., 0] / p[..., 2], cy - f * p[..., 1] / p[..., 2]], axis=-1)
