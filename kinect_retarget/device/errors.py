"""Errors the device layer raises. Each message names the problem and, where one exists, the fix."""
from __future__ import annotations


class KinectError(Exception):
    """Base class: anything that went wrong talking to a Kinect (real or emulated)."""


class LibusbMissing(KinectError):
    """No libusb-1.0 library could be loaded, so no USB device can be opened."""


class DeviceNotFound(KinectError):
    """No Kinect camera matches the request."""


class DeviceGone(KinectError):
    """The device disappeared (unplugged, power lost) while in use."""


class AccessDenied(KinectError):
    """The OS refused to open the device (permissions, wrong driver, busy)."""


class ProtocolError(KinectError):
    """The device answered something the protocol does not allow (bad magic, wrong tag, wrong length)."""


class MotorUnavailable(KinectError):
    """This Kinect's tilt motor, LED or accelerometer cannot be reached (see the message for why)."""


class BadInputFile(KinectError):
    """A file the user gave (dump, fakenect recording) is missing or unusable: their input, not the device."""


class DumpError(BadInputFile):
    """A packet dump file is unreadable (names the file and the record)."""
