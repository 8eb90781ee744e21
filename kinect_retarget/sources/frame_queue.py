"""A bounded frame queue shared by one producer thread and the main thread.

Full queue: the oldest frame goes (the pose must follow the newest one), and it is counted, so nothing is
lost silently. queue.Queue would block or raise instead.
"""
from __future__ import annotations

import collections
import threading

from .skeleton_frame import SkeletonFrame

DEFAULT_CAPACITY = 512  # ~17 s at 30 fps: only a main thread stalled that long loses frames


class FrameQueue:
    def __init__(self, capacity: int = DEFAULT_CAPACITY):
        if capacity < 1:
            raise ValueError("queue capacity must be at least 1")
        self.capacity = capacity
        self._items: collections.deque[SkeletonFrame] = collections.deque()
        self._lock = threading.Lock()
        self.overflowed = 0  # frames thrown away because the consumer fell behind

    def put(self, frame: SkeletonFrame) -> None:
        with self._lock:
            if len(self._items) >= self.capacity:
                self._items.popleft()
                self.overflowed += 1
            self._items.append(frame)

    def drain(self) -> list[SkeletonFrame]:
        """Everything queued, oldest first; leaves the queue empty."""
        with self._lock:
            items = list(self._items)
            self._items.clear()
        return items

    def __len__(self) -> int:
        with self._lock:
            return len(self._items)
