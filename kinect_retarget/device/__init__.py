"""Kinect v1 over USB in pure Python (pyusb + numpy): discovery, depth stream, motor (the emulated Kinect lives in sim/).

The API the rest of the extension uses (no bpy anywhere in this package):

    list_devices(backend=None) -> [KinectInfo]          what is plugged in, and why it can't be used if so
    DepthStream(source).start() / .stop() / .frames      a bounded queue of DepthFrame, filled by a thread
    DepthStream.status -> StreamStatus                    state text, message, fps, frames, dropped frames
    set_tilt(angle) / open_motor().set_led(mode) / .state()
    depth_preview(frame.mm) -> (120, 160) uint8           for a live preview image
"""
from .disparity_calibration import Calibration
from .discovery import KinectInfo, find_kinect, list_devices
from .errors import (AccessDenied, BadInputFile, DeviceGone, DeviceNotFound, DumpError, KinectError, LibusbMissing,
                     MotorUnavailable, ProtocolError)
from .motor import KinectMotor, MotorState, open_motor, set_tilt
from .depth_preview import depth_preview
from .depth_stream import DepthFrame, DepthStream, StreamStatus

__all__ = ["Calibration", "KinectInfo", "find_kinect", "list_devices",
           "AccessDenied", "BadInputFile", "DeviceGone", "DeviceNotFound", "DumpError", "KinectError",
           "LibusbMissing", "MotorUnavailable", "ProtocolError", "KinectMotor", "MotorState", "open_motor",
           "set_tilt", "depth_preview", "DepthFrame", "DepthStream", "StreamStatus"]
