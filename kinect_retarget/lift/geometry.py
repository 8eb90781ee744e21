"""Where a joint can be: on the line its 2D position defines (the image ray, or the orthographic line along
the optical axis), at its bone's length from the parent, on one side or the other."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .video_camera import Camera
from .bone_depth import depth_magnitude


@dataclass
class JointLines:
    """origin (F, J, 3) and unit direction (F, J, 3) of each joint's line, in Kinect camera space."""

    origin: np.ndarray
    direction: np.ndarray
    focal_px: float
    sigma_px: float  # 2D noise left in the tracks (0: use the exact square root)

    @classmethod
    def build(cls, uv: np.ndarray, cam: Camera, z_root: np.ndarray, perspective: bool,
              sigma_px: float) -> "JointLines":
        rays = cam.rays(np.nan_to_num(uv))
        if perspective:
            return cls(np.zeros_like(rays), rays / np.linalg.norm(rays, axis=-1, keepdims=True),
                       cam.focal_px, sigma_px)
        origin = rays.copy()
        origin[..., :2] *= z_root[:, None, None]
        origin[..., 2] = 0.0
        return cls(origin, np.broadcast_to([0.0, 0.0, 1.0], rays.shape).copy(), cam.focal_px, sigma_px)

    def offsets(self, j: int, parent: np.ndarray, length: float):
        """For parents (F, ..., 3): the foot of the perpendicular on joint j's line and the (noise-aware)
        distance from it to the joint, so the joint is at foot +/- along * direction."""
        extra = parent.ndim - 2
        o = self.origin[:, j].reshape((-1,) + (1,) * extra + (3,))
        u = self.direction[:, j].reshape((-1,) + (1,) * extra + (3,))
        foot = o + np.sum((parent - o) * u, axis=-1, keepdims=True) * u
        c = np.linalg.norm(parent - foot, axis=-1) / length
        px_per_m = self.focal_px / np.maximum(foot[..., 2], 1e-6)
        along = length * depth_magnitude(c, np.sqrt(2.0) * self.sigma_px / (px_per_m * length))
        return foot, along, u

    def end(self, j: int, parent: np.ndarray, length: float, sign) -> np.ndarray:
        foot, along, u = self.offsets(j, parent, length)
        return foot + (np.asarray(sign) * along)[..., None] * u
