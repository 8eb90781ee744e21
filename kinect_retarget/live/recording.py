"""Recording while live: every received frame goes straight to a .krtake file (nothing piles up in memory)."""
from __future__ import annotations

import os

import numpy as np

from ..core.skeletons import Skeleton
from ..takes.krtake import TakeWriter


class Recorder:
    """Writes frames with times relative to the start of recording; times are kept strictly increasing."""

    def __init__(self, path: str | os.PathLike, skeleton: Skeleton, rate: float, start_time: float,
                 metadata: dict | None = None):
        os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
        self.path = os.fspath(path)
        self.start_time = float(start_time)
        self._writer = TakeWriter(self.path, skeleton, rate, {"recorded_by": "kinect_retarget live",
                                                                **(metadata or {})})
        self._last = -np.inf

    @property
    def frames(self) -> int:
        return self._writer.frames

    def write(self, session_time: float, positions: np.ndarray, states: np.ndarray) -> float:
        """Returns the time exactly as stored (microseconds), which the live pipeline then uses too, so
        time-dependent filters see the same steps live and in the bake."""
        t = round(max(session_time - self.start_time, self._last + 1e-6), 6)  # a Take needs rising times
        self._writer.write(t, positions, states)
        self._last = t
        return t

    def close(self) -> None:
        self._writer.close()


def unused_path(folder: str, base: str, ext: str) -> tuple[str, str]:
    """A file name in `folder` that does not exist yet: `base`, else `base_2`, `base_3`... (two recordings
    started within one second must not overwrite each other). Returns the path and the suffix used."""
    suffix, n = "", 1
    while os.path.exists(os.path.join(folder, base + suffix + ext)):
        n += 1
        suffix = f"_{n}"
    return os.path.join(folder, base + suffix + ext), suffix
