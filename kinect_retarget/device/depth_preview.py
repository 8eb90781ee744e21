"""A small greyscale preview of a depth frame for the UI (near = bright, no reading = black)."""
from __future__ import annotations

import numpy as np

NEAR_MM, FAR_MM = 500, 4500


def depth_preview(mm: np.ndarray, shape: tuple[int, int] = (120, 160)) -> np.ndarray:
    """(480, 640) uint16 millimetres -> `shape` uint8 image, rows top to bottom as the camera sees them.

    Downsamples by striding (cheap enough for the main thread at a few frames per second); `shape` must
    divide the frame size.
    """
    h, w = mm.shape
    if h % shape[0] or w % shape[1]:
        raise ValueError(f"preview shape {shape} must divide the frame size {mm.shape}")
    small = mm[::h // shape[0], ::w // shape[1]].astype(np.float32)
    level = 255.0 - 225.0 * (np.clip(small, NEAR_MM, FAR_MM) - NEAR_MM) / (FAR_MM - NEAR_MM)
    return np.where(small > 0, level, 0).astype(np.uint8)
