"""UTKinect-Action3D joint files (Kinect v1, 20 joints, 30 fps video).

One frame per line, whitespace-separated: the video frame number (with gaps where frames were dropped), then
20 joints x (x, y, z) in Kinect v1 SDK order, camera space metres. A joint at (0, 0, 0) was not tracked.
"""
from __future__ import annotations

import os

import numpy as np

from ..core.skeletons import KINECT_V1, NOT_TRACKED, TRACKED
from ..core.take import Take, TakeError
from ._numeric import numeric_first_row, parse_table, read_bytes

RATE = 30.0
NCOL = 1 + 3 * len(KINECT_V1)


def looks_like(head: bytes) -> bool:
    first = numeric_first_row(head, NCOL)
    return first is not None and first[0].isdigit()  # a video frame number, not a timestamp


def read(path: str | os.PathLike) -> Take:
    path = os.fspath(path)
    values, lines = parse_table(path, read_bytes(path), NCOL, what="frame line")
    numbers = values[:, 0]
    if np.any((numbers != np.round(numbers)) | (numbers < 0)):
        i = int(np.argmax((numbers != np.round(numbers)) | (numbers < 0)))
        raise TakeError(f"{path}:{int(lines[i])}: frame number must be a whole number, found {numbers[i]:g}")
    # Repeated frame numbers occur in the data set: keep the first line of each, report how many were dropped.
    step = np.diff(numbers)
    if np.any(step < 0):
        i = int(np.argmax(step < 0)) + 1
        raise TakeError(f"{path}:{int(lines[i])}: frame number {numbers[i]:.0f} comes after "
                        f"{numbers[i - 1]:.0f}")
    keep = np.concatenate([[True], step > 0])
    block = values[keep, 1:].reshape(-1, len(KINECT_V1), 3)
    states = np.where(np.any(block != 0, axis=2), TRACKED, NOT_TRACKED).astype(np.uint8)
    if not np.any(states != NOT_TRACKED):
        raise TakeError(f"{path}: no joint is tracked in any frame (all joints are zero)")
    positions = np.where(states[..., None] == TRACKED, block, np.nan)
    numbers = numbers[keep]
    meta = {"source_file": os.path.basename(path), "first_video_frame": int(numbers[0]),
            "repeated_frames_dropped": int(np.sum(~keep))}
    return Take(KINECT_V1, positions, states, (numbers - numbers[0]) / RATE, RATE, "utkinect", meta)
