"""Partly broken frames: joint samples no sensor could have produced become not-tracked; the take keeps the rest.

Real recordings carry the odd NaN, infinity or wild value (a joint kilometres away) in otherwise good frames.
Refusing the whole file for one of them loses the user's recording, so every reader passes its joints through
`screen_joints`: such a sample is marked NOT_TRACKED in its frame (as if the sensor had lost the joint), the
count and the first line are recorded in the take's metadata and warnings, and only a file with no usable
frame left is refused. Structural damage (wrong column count, text, truncation) is not handled here: the
parsers still refuse it with the line named.
"""
from __future__ import annotations

import numpy as np

from ..core.skeletons import NOT_TRACKED
from ..core.take import TakeError
from ._numeric import at

MAX_DISTANCE_M = 20.0  # a Kinect sees about 0.5-8 m; anything past 20 m is a corrupt value, not a person


def screen_joints(path: str, positions: np.ndarray, states: np.ndarray, where: np.ndarray | None, meta: dict, *,
                  label: str = "line", values_ok: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(positions, states) with every seen joint sample that is NaN, infinite or farther than
    MAX_DISTANCE_M from the sensor turned NOT_TRACKED (position NaN).

    positions (F, J, 3) Kinect camera space metres; states (F, J); `where` (F,) each frame's line (or
    record) number in the file, or (F, J) each joint's, `label` the word for it; `values_ok` (F, J)
    optionally False where a joint's
    other values in the file (2D pixels, orientation) are NaN or infinite. Adds `dropped_joint_samples`,
    `first_dropped_<label>` and a warning to `meta` when anything was dropped. Raises TakeError when no
    frame keeps a usable joint.
    """
    seen = states != NOT_TRACKED
    with np.errstate(invalid="ignore", over="ignore"):
        near = np.sqrt(np.sum(positions * positions, axis=-1)) <= MAX_DISTANCE_M  # False for NaN and inf
    bad = seen & ~near
    if values_ok is not None:
        bad |= seen & ~values_ok
    if not bad.any():
        return positions, states
    if where is None:   # no line numbers kept: name frames by their index
        where = np.arange(positions.shape[0])
    rows = np.flatnonzero(bad.any(axis=1))
    first = int(where[rows[0]] if where.ndim == 1 else where.reshape(bad.shape)[np.unravel_index(
        np.argmax(bad), bad.shape)])
    n = int(bad.sum())
    if not np.any(seen & ~bad):
        raise TakeError(f"{at(path, label, first)}: no usable frame: all {n} tracked joint samples are NaN, "
                        f"infinite or farther than {MAX_DISTANCE_M:g} m from the sensor")
    positions = positions.copy()
    states = states.copy()
    positions[bad] = np.nan
    states[bad] = NOT_TRACKED
    meta["dropped_joint_samples"] = n
    meta[f"first_dropped_{label}"] = first
    meta.setdefault("warnings", []).append(
        f"{at(path, label, first)}: {n} joint sample{'s' if n != 1 else ''} in {rows.size} "
        f"frame{'s' if rows.size != 1 else ''} {'were' if n != 1 else 'was'} NaN, infinite or farther than "
        f"{MAX_DISTANCE_M:g} m from the sensor; loaded as not tracked (first at {label} {first})")
    return positions, states
