"""Timestamps as files write them -> seconds: the unit is inferred from the spacing of consecutive samples.

Real recordings stamp frames in seconds, milliseconds, microsecond-like counters (MSRC-12: ~33,150 per
frame), 100 ns sensor ticks (Kinect v2: ~333,333) or video frame numbers (UTKinect). A Kinect delivers
about 30 frames a second, so the unit is the one that turns the typical (median) spacing into the frame
interval nearest 1/30 s, provided that interval is plausible for a skeleton stream at all (4 to 200 fps).
A spacing no unit explains is an error naming the file, a line with that spacing and the spacing.
"""
from __future__ import annotations

import numpy as np

from ..core.take import TakeError
from ._numeric import at

KINECT_RATE = 30.0
# name: units of the file's timestamp column per second (frame numbers: one per Kinect frame)
UNITS = {"s": 1.0, "ms": 1e3, "µs": 1e6, "100 ns ticks": 1e7, "frame numbers": KINECT_RATE}
FRAME_ORDER = "none (frame order, 30 fps)"  # for formats with no time column (NTU RGB+D, UI-PRMD)
FASTEST, SLOWEST = 1.0 / 200.0, 1.0 / 4.0  # plausible frame intervals, seconds


def infer_unit(spacing: float, whole: bool) -> str | None:
    """The unit that makes a typical `spacing` a plausible Kinect frame interval, or None.
    Frame numbers are only considered when every stamp is a whole number (`whole`)."""
    fits = [(abs(np.log(spacing / per_s * KINECT_RATE)), name) for name, per_s in UNITS.items()
            if (whole or name != "frame numbers") and FASTEST <= spacing / per_s <= SLOWEST]
    return min(fits)[1] if fits else None


def stamps_to_seconds(path: str, stamps: np.ndarray, where: np.ndarray, *, label: str = "line",
                      what: str = "timestamp", unit: str | None = None,
                      default: str = "s", keep_origin: bool = False) -> tuple[np.ndarray, str]:
    """(seconds from the first sample, or from the file's zero with `keep_origin`; unit name). `where` holds
    each sample's line (or record) number
    for messages, `what` names the column; `unit` forces a unit (one of UNITS) instead of inferring it,
    `default` is the format's documented unit, used when a single sample gives no spacing. Checks that
    stamps are finite and strictly increasing; frames with nothing tracked count like any other (they keep
    their time)."""
    stamps = np.asarray(stamps, dtype=np.float64)
    bad = ~np.isfinite(stamps)
    if bad.any():
        i = int(np.argmax(bad))
        raise TakeError(f"{at(path, label, where[i])}: {what} is NaN or infinite")
    step = np.diff(stamps)
    if np.any(step <= 0):
        i = int(np.argmax(step <= 0)) + 1
        raise TakeError(f"{at(path, label, where[i])}: {what} {_show(stamps[i])} is not after the previous "
                        f"{label}'s {_show(stamps[i - 1])}")
    if unit is None:
        if step.size == 0:
            unit = default
        else:
            spacing = float(np.median(step))
            unit = infer_unit(spacing, bool(np.all(stamps == np.round(stamps))))
            if unit is None:
                i = int(np.argmin(np.abs(step - spacing))) + 1
                raise TakeError(
                    f"{at(path, label, where[i])}: timestamps are {_show(spacing)} apart, which fits no time unit "
                    f"(s, ms, µs, 100 ns ticks or {KINECT_RATE:g} fps frame numbers give a frame every "
                    f"{FASTEST * 1000:g}-{SLOWEST * 1000:g} ms)")
    elif unit not in UNITS:
        raise TakeError(f"{path}: unknown time unit {unit!r} (known: {', '.join(UNITS)})")
    return (stamps - (0.0 if keep_origin else stamps[0])) / UNITS[unit], unit


def _show(v: float) -> str:
    return str(int(v)) if float(v).is_integer() and abs(v) < 1e15 else f"{v:.10g}"
