"""UTKinect-Action3D joint files (Kinect v1, 20 joints, 30 fps video).

One frame per line, whitespace-separated: the video frame number (with gaps where frames were dropped), then
20 joints x (x, y, z) in Kinect v1 SDK order, camera space metres. A joint at (0, 0, 0) was not tracked.
The first column's unit is inferred from its spacing like every reader's (_timebase): frame numbers in the
data set's files.
"""
from __future__ import annotations

import os

import numpy as np

from ..core.skeletons import KINECT_V1, NOT_TRACKED, TRACKED
from ..core.take import Take, TakeError, nominal_rate
from ._numeric import numeric_first_row, parse_table, read_bytes
from ._screening import screen_joints
from ._timebase import UNITS, stamps_to_seconds

NCOL = 1 + 3 * len(KINECT_V1)


def looks_like(head: bytes) -> bool:
    first = numeric_first_row(head, NCOL)
    return first is not None and first[0].isdigit()  # a video frame number, not a timestamp


def read(path: str | os.PathLike) -> Take:
    path = os.fspath(path)
    values, lines = parse_table(path, read_bytes(path), NCOL, what="frame line")
    numbers = values[:, 0]
    if np.any(~np.isfinite(numbers) | (numbers != np.round(numbers)) | (numbers < 0)):
        i = int(np.argmax(~np.isfinite(numbers) | (numbers != np.round(numbers)) | (numbers < 0)))
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
    numbers, lines = numbers[keep], lines[keep]
    times, unit = stamps_to_seconds(path, numbers, lines, what="frame number", default="frame numbers")
    meta = {"source_file": os.path.basename(path), "time_unit": unit, "first_video_frame": int(numbers[0]),
            "repeated_frames_dropped": int(np.sum(~keep))}
    positions, states = screen_joints(path, positions, states, lines, meta)
    rate = UNITS[unit] if unit == "frame numbers" else nominal_rate(times)
    return Take(KINECT_V1, positions, states, times, rate, "utkinect", meta)
