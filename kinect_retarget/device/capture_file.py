"""Depth capture files (.npz): what `capture` writes and `track` reads, in one place.

Arrays: raw (F, 480, 640) uint16 11-bit disparity and/or mm (F, 480, 640) uint16 millimetres, timestamp (F,)
device ticks (60 MHz, wrapping at 2**32), lost_packets (F,), calibration (JSON) and its fields; a capture made
elsewhere may instead carry times (F,) seconds and gravity (3,).
"""
from __future__ import annotations

import json
import zipfile

import numpy as np

from ..core.take import TakeError
from .disparity_calibration import Calibration
from .protocol import TIMESTAMP_HZ, ticks_between

SHAPE = (480, 640)


def save_capture(path: str, raws, mms, stamps, lost, calibration: Calibration) -> None:
    empty = np.zeros((0, *SHAPE), np.uint16)
    with open(path, "wb") as f:     # an open file keeps numpy from appending ".npz" to other suffixes
        np.savez(f, raw=np.array(raws, dtype=np.uint16).reshape(-1, *SHAPE) if raws else empty,
                 mm=np.array(mms, dtype=np.uint16).reshape(-1, *SHAPE) if mms else empty,
                 timestamp=np.array(stamps, dtype=np.int64), lost_packets=np.array(lost, dtype=np.int32),
                 calibration=json.dumps(calibration.as_dict()),
                 **{f"calibration_{k}": v for k, v in calibration.as_dict().items() if k != "source"})


def calibration_from(path: str) -> Calibration:
    """The calibration a capture was made with."""
    try:
        with np.load(path) as data:
            fields = json.loads(str(data["calibration"]))
        return Calibration(**fields)
    except (OSError, KeyError, ValueError, TypeError) as exc:
        raise ValueError(f"{path}: no usable calibration in it ({exc})") from exc


def times_from(data, n: int, path: str) -> np.ndarray:
    """(n,) seconds from the first frame: `times`, else the device `timestamp` unwrapped, else 30 fps."""
    if "times" in data:
        t = np.asarray(data["times"], dtype=np.float64)
    elif "timestamp" in data:
        ticks = np.asarray(data["timestamp"], dtype=np.int64)
        t = np.concatenate([[0.0], np.cumsum(ticks_between(ticks[:-1], ticks[1:]))]) / TIMESTAMP_HZ
    else:
        t = np.arange(n) / 30.0
    if t.shape != (n,):
        raise TakeError(f"{path}: {n} depth frames but {t.shape[0]} timestamps")
    if n > 1 and np.any(np.diff(t) <= 0):
        bad = int(np.argmax(np.diff(t) <= 0)) + 1
        raise TakeError(f"{path}: frame {bad} is not later than frame {bad - 1} (timestamps must increase)")
    return t


def load_capture(path: str):
    """(mm (F, 480, 640) uint16, times (F,), gravity or None); TakeError names the problem."""
    try:
        data = np.load(path, allow_pickle=False)
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:  # empty or cut-off files included
        raise TakeError(f"{path}: not a readable depth capture (.npz): {exc or type(exc).__name__}") from None
    if not hasattr(data, "files"):  # a single .npy array, not an archive of named arrays
        raise TakeError(f"{path}: not a depth capture (.npz): the file holds one unnamed array (.npy)")
    with data:
        keys = set(data.files)
        if "mm" in keys:
            mm = data["mm"]
        elif "raw" in keys:
            mm = Calibration().to_mm(np.asarray(data["raw"], dtype=np.int64))   # the driver's default table
        else:
            raise TakeError(f"{path}: no depth frames in the capture (expected an array named 'mm' or 'raw'; "
                            f"found {', '.join(sorted(keys)) or 'nothing'})")
        if mm.ndim != 3 or mm.shape[1:] != SHAPE:
            raise TakeError(f"{path}: depth frames have shape {mm.shape}, expected (frames, 480, 640)")
        if mm.shape[0] == 0:
            raise TakeError(f"{path}: the capture has no frames")
        times = times_from(data, mm.shape[0], path)
        gravity = np.asarray(data["gravity"], dtype=np.float64) if "gravity" in keys else None
    return np.asarray(mm), times, gravity
