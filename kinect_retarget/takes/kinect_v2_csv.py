"""Kinect v2 CSV as written by Microsoft's KinectReader (LabanotationSuite).

One frame per line: `timestamp, (x, y, z, state) x 25`; timestamp in 100 ns sensor ticks (only differences
matter; the unit is inferred from the spacing, _timebase, as other tools write ms or s), joints in Kinect v2
SDK order, camera space metres, state 0/1/2. Some files end lines with a comma.
"""
from __future__ import annotations

import os

import numpy as np

from ..core.skeletons import KINECT_V2, NOT_TRACKED
from ..core.take import Take, TakeError, nominal_rate
from ._numeric import parse_table, read_bytes
from ._screening import screen_joints
from ._timebase import stamps_to_seconds

NCOL = 1 + 4 * len(KINECT_V2)


def looks_like(head: bytes) -> bool:
    first = head.split(b"\n", 1)[0].strip().rstrip(b",")
    fields = first.split(b",")
    if len(fields) != NCOL or not fields[0].strip().isdigit():
        return False
    try:
        states = [float(f) for f in fields[4::4]]
        [float(f) for f in fields]
    except ValueError:
        return False
    return all(s in (0.0, 1.0, 2.0) for s in states)


def read(path: str | os.PathLike) -> Take:
    path = os.fspath(path)
    values, lines = parse_table(path, read_bytes(path), NCOL, delimiters=b",", what="frame line")
    return make_take(path, values, lines)


def make_take(path: str, values: np.ndarray, lines: np.ndarray) -> Take:
    """Frames (timestamp ticks, 25 x (x, y, z, state)) -> Take; names the line of any bad value."""
    block = values[:, 1:].reshape(-1, len(KINECT_V2), 4)
    states = block[..., 3]
    bad = (states != 0) & (states != 1) & (states != 2)
    if bad.any():
        i = int(np.argmax(bad.any(axis=1)))
        raise TakeError(f"{path}:{int(lines[i])}: tracking state must be 0, 1 or 2")
    states = states.astype(np.uint8)
    if not np.any(states != NOT_TRACKED):
        raise TakeError(f"{path}: no joint is tracked in any frame")
    times, unit = stamps_to_seconds(path, values[:, 0], lines, default="100 ns ticks")
    meta = {"source_file": os.path.basename(path), "time_unit": unit, "first_timestamp": float(values[0, 0])}
    positions, states = screen_joints(path, block[..., :3], states, lines, meta)
    return Take(KINECT_V2, positions, states, times, nominal_rate(times), "kinect_v2_csv", meta)
