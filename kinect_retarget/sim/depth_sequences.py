"""Depth image sequences to feed the emulated Kinect: libfreenect (fakenect) recordings, or a synthetic scene."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..device.disparity_calibration import mm_to_raw
from ..device.errors import BadInputFile
from ..device.protocol import DEPTH_HEIGHT, DEPTH_WIDTH

_PGM_HEADER = b"P5 640 480 65535\n"


def load_fakenect_pgm(path: str | Path) -> np.ndarray:
    """One fakenect depth dump: a PGM header, then 640x480 little-endian uint16 raw 11-bit values."""
    path = Path(path)
    data = path.read_bytes()
    if not data.startswith(b"P5"):
        raise BadInputFile(f"{path}: not a fakenect depth PGM (no 'P5' header)")
    header_end = data.find(b"\n", data.find(b"65535")) + 1 if b"65535" in data[:32] else len(_PGM_HEADER)
    body = data[header_end:]
    expected = DEPTH_WIDTH * DEPTH_HEIGHT * 2
    if len(body) != expected:
        raise BadInputFile(f"{path}: {len(body)} bytes of pixels, expected {expected} (truncated file?)")
    raw = np.frombuffer(body, dtype="<u2").reshape(DEPTH_HEIGHT, DEPTH_WIDTH)
    if raw.max() > 2047:
        raise BadInputFile(f"{path}: values above 2047, so this is not raw 11-bit depth")
    return raw.astype(np.uint16)


def load_fakenect_dir(folder: str | Path, limit: int | None = None) -> list[np.ndarray]:
    """All d-*.pgm depth frames of a fakenect recording, in recording order."""
    files = sorted(Path(folder).glob("d-*.pgm"))
    if not files:
        raise BadInputFile(f"{folder}: no fakenect depth frames (d-*.pgm) found")
    return [load_fakenect_pgm(f) for f in files[:limit]]


def synthetic_depth_frames(n: int = 30) -> list[np.ndarray]:
    """A simple scene (a wall at 3 m, a box-like figure at 1.5 m swaying side to side) as raw depth."""
    v, u = np.mgrid[0:DEPTH_HEIGHT, 0:DEPTH_WIDTH]
    frames = []
    for i in range(n):
        mm = np.full((DEPTH_HEIGHT, DEPTH_WIDTH), 3000.0) - 2.0 * (v - DEPTH_HEIGHT / 2)  # wall, floor-tilted
        cx = DEPTH_WIDTH / 2 + 120 * np.sin(2 * np.pi * i / n)
        body = (np.abs(u - cx) < 60) & (v > 140) & (v < 460)
        head = (u - cx) ** 2 + (v - 100) ** 2 < 35 ** 2
        mm[body | head] = 1500.0
        mm[:, :8] = 0                                   # the Kinect's blind left edge
        frames.append(mm_to_raw(mm))
    return frames
