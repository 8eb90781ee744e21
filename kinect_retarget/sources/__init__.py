"""Frame sources: the frame type (skeleton_frame), the bounded queue (frame_queue), the source protocol
(frame_source), and the sources themselves (take playback, OSC, the USB Kinect through the depth tracker),
each a thread putting whole frames on a FrameQueue."""
from __future__ import annotations

from .frame_source import FrameSource, SourceError
from .osc_receiver import OscReceiver
from .take_playback import TakePlayback
from .usb_kinect import UsbKinectSource


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
            from .depth_skeletons import open_skeleton_producer
            return UsbKinectSource(factory=lambda: open_skeleton_producer(simulate=True))
        return UsbKinectSource()
    raise SourceError(f"unknown source {spec!r}: use take:FILE, osc:PORT or usb")


__all__ = ["FrameSource", "SourceError", "TakePlayback", "OscReceiver", "UsbKinectSource", "open_source"]
