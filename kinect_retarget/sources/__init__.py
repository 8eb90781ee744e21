"""Frame sources (take playback, OSC, USB Kinect): each a thread putting whole frames on a FrameQueue."""
from __future__ import annotations

from .base import FrameSource, SourceError
from .osc import OscReceiver
from .playback import TakePlayback
from .usb import UsbKinectSource


def open_source(spec: str, speed: float = 1.0, loop: bool = False, host: str = "127.0.0.1",
                simulate: bool = False) -> FrameSource:
    """`take:FILE`, `osc:PORT` or `usb`, as the CLI spells them. `simulate`: the USB source is the emulated
    Kinect streaming rendered depth of real mocap (emulated USB -> depth -> skeleton)."""
    kind, _, arg = spec.partition(":")
    if kind == "take" and arg:
        return TakePlayback(arg, speed=speed, loop=loop)
    if kind == "osc":
        try:
            port = int(arg or 7000)
        except ValueError:
            raise SourceError(f"OSC port must be a number, got {arg!r}") from None
        return OscReceiver(port, host=host)
    if kind == "usb" and not arg:
        if simulate:
            from ..depth.producer import open_skeleton_producer
            return UsbKinectSource(factory=lambda: open_skeleton_producer(simulate=True))
        return UsbKinectSource()
    raise SourceError(f"unknown source {spec!r}: use take:FILE, osc:PORT or usb")


__all__ = ["FrameSource", "SourceError", "TakePlayback", "OscReceiver", "UsbKinectSource", "open_source"]
