"""Kinect v1 depth camera model: intrinsics, raw 11-bit disparity <-> millimetres.

Raw values convert with the USB driver's own formula and default calibration (device/disparity_calibration.py), so
rendered frames streamed through the emulated Kinect decode to the same millimetres; raw 2047 means "no
reading", as does 0 mm.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..device.disparity_calibration import Calibration

DEFAULT_CALIBRATION = Calibration()
WIDTH, HEIGHT = 640, 480


@dataclass(frozen=True)
class DepthCamera:
    f: float = 575.0
    cx: float = 319.5
    cy: float = 239.5
    width: int = WIDTH
    height: int = HEIGHT
    projector_x: float = -0.075  # projector position along Kinect X (it sits on the sensor's right)


def metres_to_raw(z: np.ndarray, calibration: Calibration = DEFAULT_CALIBRATION) -> np.ndarray:
    """Continuous raw disparity for depth z (metres), the inverse of the driver's formula; callers round
    and clip it (the rounding is the device's disparity quantisation)."""
    c = calibration
    d = np.maximum(np.asarray(z, dtype=np.float64), 1e-3) * 100.0   # the table's mm / 10
    m = (d - c.reference_distance) * c.dcmos_emitter_dist / d       # offset on the reference plane
    return 4.0 * (m / c.reference_pixel_size + 0.375) + 4.0 * c.const_shift


def raw_to_mm(raw: np.ndarray, calibration: Calibration = DEFAULT_CALIBRATION) -> np.ndarray:
    """uint16 millimetres, 0 where there is no reading (same table as the USB driver)."""
    return calibration.to_mm(np.asarray(raw, dtype=np.int64))
