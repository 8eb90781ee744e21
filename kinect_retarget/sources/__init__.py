"""Frame sources: the frame type (skeleton_frame), the bounded queue (frame_queue), the source protocol
(frame_source), the sources themselves (take playback, OSC, the USB Kinect through the depth tracker), each a
thread putting whole frames on a FrameQueue, and the one factory that opens them (source_factory)."""
from __future__ import annotations

from .frame_source import FrameSource, SourceError
from .osc_receiver import OscReceiver
from .source_factory import open_source
from .take_playback import TakePlayback
from .usb_kinect import UsbKinectSource

__all__ = ["FrameSource", "SourceError", "TakePlayback", "OscReceiver", "UsbKinectSource", "open_source"]
