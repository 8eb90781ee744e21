"""The video camera: a pinhole in Kinect camera-space axes (+X toward the camera's left, +Y up, +Z ahead).

Pixel u grows to the right and v downward, so u = cx - f X/Z and v = cy - f Y/Z (conventions.py).
When the focal length is unknown the lifter assumes DEFAULT_FOV_FACTOR x the larger image side, a normal
lens (about 53 degrees across the larger side).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.conventions import depth_pixel_to_kinect, kinect_to_depth_pixel

DEFAULT_FOV_FACTOR = 1.0


@dataclass(frozen=True)
class Camera:
    focal_px: float
    cx: float
    cy: float
    focal_known: bool = True

    @classmethod
    def for_image(cls, width: float, height: float, focal_px: float | None = None) -> "Camera":
        known = focal_px is not None
        f = float(focal_px) if known else DEFAULT_FOV_FACTOR * max(width, height)
        return cls(f, width / 2.0, height / 2.0, known)

    def project(self, points: np.ndarray) -> np.ndarray:
        """(..., 3) Kinect camera space -> (..., 2) pixels."""
        return kinect_to_depth_pixel(points, self.focal_px, self.cx, self.cy)

    def rays(self, uv: np.ndarray) -> np.ndarray:
        """(..., 2) pixels -> (..., 3) rays with Z = 1 (a point at depth Z is Z * ray)."""
        uv = np.asarray(uv, dtype=np.float64)
        return depth_pixel_to_kinect(uv[..., 0], uv[..., 1], np.ones(uv.shape[:-1]), self.focal_px, self.cx, self.cy)


def look_at_rotation(azimuth_deg: float, elevation_deg: float = 0.0) -> np.ndarray:
    """Rotation taking a performer's Kinect-space coordinates (facing the camera) to a camera that has
    walked azimuth_deg around them (positive: toward the performer's left) and looks down elevation_deg."""
    a, e = np.radians(azimuth_deg), np.radians(elevation_deg)
    ry = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
    rx = np.array([[1, 0, 0], [0, np.cos(e), np.sin(e)], [0, -np.sin(e), np.cos(e)]])
    return rx @ ry


def view_points(points: np.ndarray, azimuth_deg: float, elevation_deg: float, distance_m: float,
                pivot: np.ndarray) -> np.ndarray:
    """Re-express (..., 3) Kinect-space points as seen by a camera orbiting `pivot` at distance_m."""
    r = look_at_rotation(azimuth_deg, elevation_deg)
    return (np.asarray(points) - pivot) @ r.T + np.array([0.0, 0.0, distance_m])
