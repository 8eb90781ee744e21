"""The one source factory: `take:FILE`, `osc:PORT` or `usb`, as the CLI spells them and the sidebar builds them."""
from __future__ import annotations

from .frame_source import FrameSource, SourceError
from .osc_receiver import OscReceiver
from .take_playback import TakePlayback
from .usb_kinect import UsbKinectSource


def open_source(spec: str, speed: float = 1.0, loop: bool = False, host: str = "127.0.0.1",
                simulate: bool = False, usb_backend=None, bodies: tuple[int, ...] = (0,)) -> FrameSource:
    """A frame source, not started. `simulate`: the USB source is the emulated Kinect streaming rendered depth
    of real mocap (emulated USB -> depth -> skeleton); `usb_backend`: a pyusb backend to open instead of the
    system's (the sidebar's prepared simulated Kinect); `bodies`: the performers of a take file to play
    together (OSC sends every user it sees)."""
    kind, _, arg = spec.partition(":")
    if kind == "take" and arg:
        return TakePlayback(arg, speed=speed, loop=loop, bodies=bodies)
    if kind == "osc":
        try:
            port = int(arg or 7000)
        except ValueError:
            raise SourceError(f"OSC port must be a number, got {arg!r}") from None
        return OscReceiver(port, host=host)
    if kind == "usb" and not arg:
        if simulate or usb_backend is not None:
            from .depth_skeletons import open_skeleton_producer
            return UsbKinectSource(factory=lambda: open_skeleton_producer(source=usb_backend, simulate=simulate))
        return UsbKinectSource()
    raise SourceError(f"unknown source {spec!r}: use take:FILE, osc:PORT or usb")
