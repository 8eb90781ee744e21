"""Take playback at real time (times speed), optionally looping, on its own thread."""
from __future__ import annotations

import os
import time

from ..core.take import Take, TakeError
from .frame_source import FrameSource, SourceError


class TakePlayback(FrameSource):
    """Plays a loaded Take (or a path, loaded in start()). Frame times on the source clock are wall
    seconds since the start of playback, so keys later land where the frames happened."""

    kind = "take"

    def __init__(self, take: Take | str | os.PathLike, speed: float = 1.0, loop: bool = False):
        if not (speed > 0):
            raise SourceError(f"playback speed must be positive, got {speed}")
        self.path = None if isinstance(take, Take) else os.fspath(take)
        self.take = take if isinstance(take, Take) else None
        self.speed = float(speed)
        self.loop = bool(loop)
        self.position = 0  # index of the next frame, for the panel
        if self.take is None:
            self.take = self._load()
        super().__init__(self.take.skeleton, self.take.rate)

    def describe(self) -> str:
        return f"take {self.path}" if self.path else "take playback"

    def _load(self) -> Take:
        from ..takes import load_take
        if self.path is None or not os.path.isfile(self.path):
            raise SourceError(f"take file {self.path} does not exist")
        try:
            return load_take(self.path)
        except TakeError as exc:
            raise SourceError(str(exc)) from None
        except OSError as exc:
            raise SourceError(f"cannot read take {self.path}: {exc.strerror or exc}") from None

    def _open(self) -> None:
        # The file vanishing between load and start still means the user's source is gone: say so.
        if self.path is not None and not os.path.isfile(self.path):
            raise SourceError(f"take file {self.path} has vanished")

    def _run(self) -> None:
        take = self.take
        times = take.times - take.times[0]
        period = times[-1] + (1.0 / take.rate)  # one loop lasts the take plus one frame interval
        start = time.perf_counter()
        lap = 0
        while not self.stopping:
            for i in range(take.frame_count):
                t = (lap * period + times[i]) / self.speed
                if not self._sleep(start + t - time.perf_counter()):
                    return
                self.position = i
                if self.path is not None and i % 30 == 0 and not os.path.isfile(self.path):
                    raise SourceError(f"take file {self.path} has vanished during playback")
                self._emit(take.positions[i], take.states[i], t, where=f" frame {i}")
            if not self.loop:
                return
            lap += 1
