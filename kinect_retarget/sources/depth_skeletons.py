"""Skeleton frames from a (real or emulated) USB Kinect: DepthStream -> SkeletonTracker.

`open_skeleton_producer()` is what the "USB Kinect" live source looks for (sources/usb_kinect.py): an object with
`read(timeout) -> (positions (20, 3), states (20,), time_s) | None`, `skeleton`, `rate`, `close()`.
The tracker runs on the caller's (source) thread; nothing here touches bpy. `preview()` gives the newest
depth image with the segmented person and the fitted skeleton, for the sidebar (drawn by the main thread).
"""
from __future__ import annotations

import queue
import threading

from ..core.skeletons import KINECT_V1
from ..depth.skeleton_tracker import SkeletonTracker
from ..device.protocol import TIMESTAMP_HZ, ticks_between


class DepthSkeletonProducer:
    skeleton = KINECT_V1
    rate = 30.0

    def __init__(self, stream, tracker: SkeletonTracker | None = None, own_stream: bool = True):
        self.stream = stream
        self.tracker = tracker or SkeletonTracker()
        self._own = own_stream
        self._elapsed = 0
        self._last_tick: int | None = None   # None until the first frame
        self._lock = threading.Lock()
        self._preview = None

    def read(self, timeout: float):
        try:
            frame = self.stream.frames.get(timeout=timeout)
        except queue.Empty:
            return None
        if self._last_tick is None:
            self._last_tick = frame.timestamp
        self._elapsed += ticks_between(self._last_tick, frame.timestamp)
        self._last_tick = frame.timestamp
        t = self._elapsed / TIMESTAMP_HZ
        mm = frame.mm if frame.mm is not None else frame.calibration.to_mm(frame.raw)
        positions, states = self.tracker.update(mm, t)
        with self._lock:
            self._preview = (mm, self.tracker.last_mask, positions.copy(), states.copy())
        return positions, states, t

    def preview(self):
        """(depth_mm, person mask on the tracker grid or None, positions, states) of the newest frame."""
        with self._lock:
            return self._preview

    def preview_image(self, scale: int = 2):
        """RGBA float32 (rows bottom-up) of the newest frame for a Blender image, or None before the first."""
        from ..depth.tracking_preview import preview_rgba
        p = self.preview()
        return None if p is None else preview_rgba(*p, camera=self.tracker.camera, scale=scale)

    def close(self) -> None:
        if self._own:
            self.stream.stop()


def open_skeleton_producer(source=None, simulate: bool = False, frames: int = 90, gravity=None):
    """Start a DepthStream (real Kinect, or the emulated one streaming rendered mocap when `simulate`) and
    return a producer of skeleton frames."""
    from ..device.depth_stream import DepthStream
    if simulate and source is None:
        from .simulated_kinect import emulated_kinect, simulated_frames
        source = emulated_kinect(simulated_frames(frames))
    stream = DepthStream(source, queue_size=2).start()   # live wants the newest frame: a short queue
    return DepthSkeletonProducer(stream, SkeletonTracker(gravity=gravity))
