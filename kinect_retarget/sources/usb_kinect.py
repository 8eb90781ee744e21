"""The USB Kinect as a frame source: wraps a skeleton-frame producer.

A producer is any object with `read(timeout) -> (positions (J,3), states (J,), time_s) | None` (None: no
skeleton this time), `skeleton` and optionally `rate` and `close()`. By default it is the depth tracker on the
USB driver's depth stream (sources/depth_skeletons.py), opened when the source starts.
"""
from __future__ import annotations

import time

from .frame_source import FrameSource, SourceError


class UsbKinectSource(FrameSource):
    kind = "usb"
    NO_FRAME_TIMEOUT = 5.0  # seconds without a depth frame (unplugged, no device) before live gives up
    # stream states that will not heal by themselves (device.stream.ERROR: no libusb, no permission): the
    # stream retries them slowly for a user fixing things, but live says so at once instead of waiting
    FAILED_STATES = ("error",)

    def __init__(self, producer=None, factory=None):
        self._producer = producer
        self._factory = factory
        skeleton = getattr(producer, "skeleton", None)
        if skeleton is None:
            from ..core.skeletons import KINECT_V1
            skeleton = KINECT_V1  # the Kinect v1 joint set, which a USB Kinect v1 tracker reports
        super().__init__(skeleton, getattr(producer, "rate", 30.0))

    @property
    def producer(self):
        """The skeleton producer while streaming (the sidebar's preview reads its depth and fit)."""
        return self._producer

    def describe(self) -> str:
        return "USB Kinect"

    def _open(self) -> None:
        if self._producer is None:
            factory = self._factory
            if factory is None:
                from .depth_skeletons import open_skeleton_producer  # numpy-heavy: only when the source starts
                factory = open_skeleton_producer
            try:
                self._producer = factory()
            except SourceError:
                raise
            except Exception as exc:  # unplugged device, permissions, libusb missing
                raise SourceError(f"USB Kinect: cannot open the device ({exc})") from None
            self.skeleton = getattr(self._producer, "skeleton", self.skeleton)
            self.rate = float(getattr(self._producer, "rate", self.rate))

    def _close(self) -> None:
        close = getattr(self._producer, "close", None)
        if callable(close):
            try:
                close()
            except Exception:
                pass  # closing an unplugged device may fail; the thread is gone either way

    def _stream_status(self):
        return getattr(getattr(self._producer, "stream", None), "status", None)

    @property
    def device_status(self) -> str | None:
        """The depth stream's own sentence (connecting, streaming, unplugged...), when the producer has one."""
        return getattr(self._stream_status(), "message", None)

    def device_failure(self) -> str | None:
        """The stream's sentence when it is in a failed state, else None."""
        status = self._stream_status()
        return getattr(status, "message", None) if getattr(status, "state", None) in self.FAILED_STATES else None

    def idle_reason(self) -> str | None:
        """Why nothing arrived, for a run that ends before the no-frame timeout (headless `live`)."""
        return f"{self.describe()}: no depth frame received ({self.device_status or 'no frames'})"

    def _run(self) -> None:
        n = 0
        last = time.monotonic()
        while not self.stopping:
            try:
                frame = self._producer.read(0.1)
            except SourceError:
                raise
            except Exception as exc:
                raise SourceError(f"USB Kinect stopped delivering frames ({exc})") from None
            if frame is None:
                failure = self.device_failure()
                if failure:
                    raise SourceError(f"USB Kinect: {failure}")
                if time.monotonic() - last > self.NO_FRAME_TIMEOUT:
                    why = self.device_status or "no frames"
                    raise SourceError(f"USB Kinect: no depth frame for {self.NO_FRAME_TIMEOUT:.0f} s ({why})")
                continue
            last = time.monotonic()
            positions, states, time_s = frame
            self._emit(positions, states, time_s, where=f" frame {n}")
            n += 1
