"""One source, several performers: each body's frames go to the queue of the live session that drives its
rig, so two rigs follow two performers of one OSC stream (NI mate numbers its users) or one take.

`BodyFanout(source)` stands where a FrameQueue would for the source's thread (`put` routes a frame by its
`body`); `fanout.body(n)` is a FrameSource-shaped view a LiveSession starts and stops like any source. The
real source starts with the first view and stops with the last; frames of bodies no rig follows are counted
and dropped. Nothing here touches bpy.
"""
from __future__ import annotations

import threading

from .frame_source import FrameSource, SourceError
from .skeleton_frame import SkeletonFrame


class BodyFanout:
    def __init__(self, source: FrameSource):
        self.source = source
        self.unrouted = 0  # frames of bodies nobody follows
        self._queues: dict = {}
        self._lock = threading.Lock()

    def body(self, n: int) -> BodySource:
        if isinstance(n, bool) or not isinstance(n, int) or n < 0:
            raise ValueError(f"body must be a whole number from 0, got {n!r}")
        return BodySource(self, n)

    # -- the source's thread ---------------------------------------------------------------------------
    def put(self, frame: SkeletonFrame) -> None:
        with self._lock:
            queue = self._queues.get(frame.body)
            if queue is None:
                self.unrouted += 1
                return
        queue.put(frame)

    # -- the views, on the main thread -----------------------------------------------------------------
    def _attach(self, body: int, queue) -> None:
        with self._lock:
            if body in self._queues:
                raise SourceError(f"{self.source.describe()}: body {body} already drives a rig")
            first = not self._queues
            self._queues[body] = queue
        if first:
            try:
                self.source.start(self)  # type: ignore[arg-type]  # routes like a queue
            except Exception:
                with self._lock:
                    self._queues.pop(body, None)
                raise

    def _detach(self, body: int) -> None:
        with self._lock:
            self._queues.pop(body, None)
            last = not self._queues
        if last:
            self.source.stop()


class BodySource:
    """The part of a shared source one LiveSession sees: body `n`'s frames; status, errors and the end of
    the source are the shared source's."""

    def __init__(self, fanout: BodyFanout, body: int):
        self.fanout, self.body = fanout, body
        self._started = False

    def __getattr__(self, name):  # skeleton, rate, status, error, warning, kind, position, take, ...
        return getattr(self.fanout.source, name)

    def describe(self) -> str:
        return f"{self.fanout.source.describe()} body {self.body}"

    @property
    def alive(self) -> bool:
        return self._started and self.fanout.source.alive

    def start(self, queue) -> None:
        self.fanout._attach(self.body, queue)
        self._started = True

    def stop(self, timeout: float = 2.0) -> None:
        if self._started:
            self._started = False
            self.fanout._detach(self.body)
