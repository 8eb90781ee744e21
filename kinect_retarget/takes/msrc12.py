"""MSRC-12 Kinect gesture data set skeleton files (Kinect v1, 20 joints).

One frame per line, space-separated (commas accepted): a timestamp, then 20 joints x (x, y, z, w) in Kinect
v1 SDK order, camera space metres (w is the SDK's homogeneous coordinate, 1). The data set's files stamp
frames with a microsecond-like counter (e.g. 642926216, ~33,150 per frame); the unit is inferred from the
spacing (_timebase). A joint whose four values are all zero was not tracked; a row of zeros means no
skeleton in that frame (the files start with about 20 of them).
"""
from __future__ import annotations

import os

import numpy as np

from ..core.skeletons import KINECT_V1, NOT_TRACKED, TRACKED
from ..core.take import Take, TakeError, nominal_rate
from ._numeric import numeric_first_row, parse_table, read_bytes
from ._screening import screen_joints
from ._timebase import stamps_to_seconds

NCOL = 1 + 4 * len(KINECT_V1)


def looks_like(head: bytes) -> bool:
    return numeric_first_row(head, NCOL, b",") is not None


def read(path: str | os.PathLike) -> Take:
    path = os.fspath(path)
    values, lines = parse_table(path, read_bytes(path), NCOL, delimiters=b",", what="frame line")
    block = values[:, 1:].reshape(-1, len(KINECT_V1), 4)
    states = np.where(np.any(block != 0, axis=2), TRACKED, NOT_TRACKED).astype(np.uint8)
    if not np.any(states != NOT_TRACKED):
        raise TakeError(f"{path}: no joint is tracked in any frame (all rows are zeros)")
    rel, unit = stamps_to_seconds(path, values[:, 0], lines)
    meta = {"source_file": os.path.basename(path), "time_unit": unit, "first_timestamp": float(values[0, 0])}
    positions = np.where(states[..., None] == TRACKED, block[..., :3], np.nan)
    positions, states = screen_joints(path, positions, states, lines, meta,
                                      values_ok=np.isfinite(block[..., 3]))
    return Take(KINECT_V1, positions, states, rel, nominal_rate(rel), "msrc12", meta)
