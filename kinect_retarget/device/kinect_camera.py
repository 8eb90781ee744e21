"""The Kinect camera device over pyusb: claim it, send GM commands, read calibration, start/stop depth.

Works on any pyusb Device: a real one through the libusb1 backend or the emulated one.
"""
from __future__ import annotations

import errno
import sys
import time

import usb.core
import usb.util

from . import protocol as P
from .disparity_calibration import Calibration, calibration_from_replies
from .errors import AccessDenied, DeviceGone, KinectError, ProtocolError
from .usb_backend import LIBUSB_ERROR_NO_DEVICE

REPLY_TIMEOUT_S = 1.0
USB_TIMEOUT_MS = 500


def is_gone(exc: BaseException) -> bool:
    """True when a pyusb error means the device is no longer there."""
    return isinstance(exc, usb.core.USBError) and (
        exc.errno in (errno.ENODEV, errno.EIO) or getattr(exc, "backend_error_code", None) == LIBUSB_ERROR_NO_DEVICE)


def access_advice(exc: BaseException) -> str:
    """Why the OS refused to open the device, and the fix for this platform."""
    if sys.platform.startswith("linux"):
        if getattr(exc, "errno", None) == errno.EBUSY:
            return ("the device is busy: another program (libfreenect, a previous Blender session) holds it; "
                    "close it and try again")
        return ("permission denied: install the udev rule (print it with "
                "'python -m kinect_retarget devices --udev-rule'), then unplug and replug the Kinect")
    if sys.platform == "win32":
        return ("Windows has no usable driver bound to the Kinect camera: install WinUSB or libusbK for "
                "'Xbox NUI Camera' with Zadig (https://zadig.akeo.ie)")
    return f"the OS refused to open the device ({exc})"


class KinectCamera:
    """An opened Kinect camera. Use as a context manager, or call close()."""

    def __init__(self, device: usb.core.Device):
        self.device = device
        self.product_id = device.idProduct
        self.bcd_device = device.bcdDevice
        self.model = P.camera_model(self.product_id, self.bcd_device)
        self._tag = 0
        self._claimed = False
        self.calibration = Calibration()

    # --- open / close -----------------------------------------------------------------------------------
    def open(self) -> "KinectCamera":
        dev = self.device
        try:
            try:
                if dev.is_kernel_driver_active(P.CAMERA_INTERFACE):   # Linux: gspca_kinect grabs it
                    dev.detach_kernel_driver(P.CAMERA_INTERFACE)
            except (NotImplementedError, usb.core.USBError) as exc:
                if is_gone(exc):
                    raise
            try:
                dev.get_active_configuration()
            except usb.core.USBError:
                dev.set_configuration()      # unconfigured (rare): pick the only configuration
            usb.util.claim_interface(dev, P.CAMERA_INTERFACE)
            if self.product_id == P.PID_CAMERA_K4W:
                dev.set_interface_altsetting(P.CAMERA_INTERFACE, 1)
            self._claimed = True
        except usb.core.USBError as exc:
            if is_gone(exc):
                raise DeviceGone("the Kinect was unplugged while opening it") from exc
            if exc.errno in (errno.EACCES, errno.EPERM, errno.EBUSY) or sys.platform == "win32":
                raise AccessDenied(f"cannot open the Kinect camera: {access_advice(exc)}") from exc
            raise KinectError(f"cannot open the Kinect camera: {exc}") from exc
        except NotImplementedError as exc:
            raise AccessDenied(f"cannot open the Kinect camera: {access_advice(exc)}") from exc
        self.calibration = self.read_calibration()
        return self

    def close(self) -> None:
        if self._claimed:
            try:
                usb.util.release_interface(self.device, P.CAMERA_INTERFACE)
            except (usb.core.USBError, NotImplementedError):
                pass                                  # already gone: nothing to release
            self._claimed = False
        usb.util.dispose_resources(self.device)

    def __enter__(self):
        return self.open()

    def __exit__(self, *exc):
        self.close()

    # --- command channel --------------------------------------------------------------------------------
    def command(self, opcode: int, payload: bytes = b"") -> bytes:
        """Send one GM command and return the validated RB reply payload."""
        tag = self._tag
        message = P.build_command(opcode, tag, payload)
        try:
            self.device.ctrl_transfer(P.CMD_REQUEST_OUT, 0, 0, 0, message, USB_TIMEOUT_MS)
            deadline = time.monotonic() + REPLY_TIMEOUT_S
            while True:
                reply = self.device.ctrl_transfer(P.CMD_REQUEST_IN, 0, 0, 0, P.CMD_REPLY_LENGTH, USB_TIMEOUT_MS)
                # Empty means "not ready"; a full 0x200 is a known USB 3 host quirk: poll again.
                if 0 < len(reply) < P.CMD_REPLY_LENGTH:
                    break
                if time.monotonic() > deadline:
                    raise ProtocolError(f"no reply to camera command {opcode:#x} within {REPLY_TIMEOUT_S} s")
                time.sleep(0.001)
        except usb.core.USBError as exc:
            if is_gone(exc):
                raise DeviceGone("the Kinect was unplugged") from exc
            raise ProtocolError(f"camera command {opcode:#x} failed: {exc}") from exc
        payload_back = P.parse_reply(bytes(reply), opcode, tag)
        self._tag = (tag + 1) & 0xFFFF
        return payload_back

    def read_register(self, reg: int) -> int:
        payload = self.command(P.OP_READ_REGISTER, P.words(reg))
        if len(payload) != 4:
            raise ProtocolError(f"register {reg:#x} read returned {len(payload)} bytes, expected 4")
        return int.from_bytes(payload[2:4], "little")

    def write_register(self, reg: int, value: int) -> None:
        payload = self.command(P.OP_WRITE_REGISTER, P.words(reg, value))
        if payload != b"\x00\x00":
            raise ProtocolError(f"register {reg:#x} write was not acknowledged (reply {payload.hex()})")

    def read_calibration(self) -> Calibration:
        fixed = self.command(P.OP_FIXED_PARAMS, P.words(0, 0, 0, 0, 0))
        shift = self.command(P.OP_ALGORITHM_PARAMS, P.words(P.ALGO_CONST_SHIFT, 0, 1, 30, 0))
        return calibration_from_replies(fixed, shift)

    def start_depth(self) -> None:
        """Call after the iso transfers are queued (the device starts sending at once)."""
        for reg, value in P.DEPTH_START_SEQUENCE:
            self.write_register(reg, value)

    def stop_depth(self) -> None:
        for reg, value in P.DEPTH_STOP_SEQUENCE:
            self.write_register(reg, value)
