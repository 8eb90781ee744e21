"""Kinect v2 image sizes and the image-coordinate flip, shared by the readers that carry 2D joints
(kinectron_json, ntu_skeleton)."""
from __future__ import annotations

import numpy as np

DEPTH_SIZE = (512, 424)     # Kinect v2 depth image, pixels (width, height)
COLOR_SIZE = (1920, 1080)   # Kinect v2 colour image


def unmirror(px: np.ndarray, width: int) -> np.ndarray:
    """(..., 2) pixel coordinates with u flipped (W - 1 - u) to the project convention; v unchanged."""
    out = px.copy()
    out[..., 0] = (width - 1) - px[..., 0]
    return out
