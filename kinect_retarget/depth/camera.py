"""Kinect v1 depth camera model: intrinsics, raw 11-bit disparity <-> millimetres.

The raw-to-metre fit z = 1 / (raw * -0.0030711016 + 3.3309495161) is the common libfreenect fit (data
README §5a); raw 2047 means "no reading", as does 0 mm.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

RAW_A, RAW_B = -0.0030711016, 3.3309495161
NO_READING_RAW = 2047
WIDTH, HEIGHT = 640, 480


@dataclass(frozen=True)
class DepthCamera:
    f: float = 575.0
    cx: float = 319.5
    cy: float = 239.5
    width: int = WIDTH
    height: int = HEIGHT
    baseline: float = 0.075   # IR projector to IR camera, metres
    projector_x: float = -0.075  # projector position along Kinect X (it sits on the sensor's right)


def raw_to_metres(raw: np.ndarray) -> np.ndarray:
    raw = np.asarray(raw, dtype=np.float64)
    denom = raw * RAW_A + RAW_B
    ok = (raw < NO_READING_RAW) & (denom > 0)
    return np.where(ok, 1.0 / np.where(ok, denom, 1.0), 0.0)


def metres_to_raw(z: np.ndarray) -> np.ndarray:
    """Continuous raw disparity for depth z (metres); callers round and clip it."""
    z = np.asarray(z, dtype=np.float64)
    return (1.0 / np.maximum(z, 1e-6) - RAW_B) / RAW_A


def raw_to_mm(raw: np.ndarray) -> np.ndarray:
    """uint16 millimetres, 0 where there is no reading."""
    return np.round(raw_to_metres(raw) * 1000.0).astype(np.uint16)
