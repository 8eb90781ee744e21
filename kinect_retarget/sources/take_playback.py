"""Take playback at real time (times speed), optionally looping, on its own thread."""
from __future__ import annotations

import os
import time

from ..core.take import Take, TakeError
from .frame_source import FrameSource, SourceError


class TakePlayback(FrameSource):
    """Plays a loaded Take (or a path, loaded in start()). Frame times on the source clock are wall
    seconds since the start of playback, so keys later land where the frames happened. `bodies`: the
    performers of a take file with several to play together, each frame tagged with its body (a
    BodyFanout routes them to their rigs); `take` is the first of them."""

    kind = "take"

    def __init__(self, take: Take | str | os.PathLike, speed: float = 1.0, loop: bool = False,
                 bodies: tuple[int, ...] = (0,)):
        if not (speed > 0):
            raise SourceError(f"playback speed must be positive, got {speed}")
        self.path = None if isinstance(take, Take) else os.fspath(take)
        self.take = take if isinstance(take, Take) else None
        self.speed = float(speed)
        self.loop = bool(loop)
        self.position = 0  # index of the next frame, for the panel
        self.bodies = tuple(sorted(set(bodies))) or (0,)
        if self.take is None:
            self.takes = {b: self._load(b) for b in self.bodies}
            self.take = self.takes[self.bodies[0]]
        elif self.bodies != (0,):
            raise SourceError("several bodies play from a take file, not from a loaded take")
        else:
            self.takes = {0: self.take}
        if len({t.frame_count for t in self.takes.values()}) > 1:
            raise SourceError(f"take file {self.path}: its bodies have different frame counts")
        super().__init__(self.take.skeleton, self.take.rate)
        read = [w for t in self.takes.values() for w in t.metadata.get("warnings", ())]
        if read:  # what the reader dropped (bad samples, a cut-off line): shown as bake shows it
            self.warning = "; ".join(dict.fromkeys(read))

    def describe(self) -> str:
        return f"take {self.path}" if self.path else "take playback"

    def _load(self, body: int = 0) -> Take:
        from ..takes import load_take
        if self.path is None or not os.path.isfile(self.path):
            raise SourceError(f"take file {self.path} does not exist")
        try:
            return load_take(self.path, body=body)
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
                for body, each in self.takes.items():
                    self._emit(each.positions[i], each.states[i], t, where=f" frame {i}", body=body)
            if not self.loop:
                return
            lap += 1
