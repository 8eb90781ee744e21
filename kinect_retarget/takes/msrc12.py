"""MSRC-12 Kinect gesture data set skeleton files (Kinect v1, 20 joints).

One frame per line, space-separated: a timestamp in seconds, then 20 joints x (x, y, z, w) in Kinect v1
SDK order, camera space metres (w is the SDK's homogeneous coordinate, 1). A joint whose four values are all
zero was not tracked; a row of zeros means no skeleton in that frame.
"""
from __future__ import annotations

import os

import numpy as np

from ..core.skeletons import KINECT_V1, NOT_TRACKED, TRACKED
from ..core.take import Take, TakeError, nominal_rate
from ._numeric import check_rising, numeric_first_row, parse_table, read_bytes

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
    times = values[:, 0]
    check_rising(path, lines, times, show=lambda t: f"{t:g} s")
    positions = np.where(states[..., None] == TRACKED, block[..., :3], np.nan)
    rel = times - times[0]
    meta = {"source_file": os.path.basename(path), "first_timestamp_s": float(times[0])}
    return Take(KINECT_V1, positions, states, rel, nominal_rate(rel), "msrc12", meta)
