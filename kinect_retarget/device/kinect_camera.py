"""The Kinect camera device over pyusb: claim it, send GM commands, read calibration, start/stop depth.

Works on any pyusb Device: a real one through the libusb1 backend or the emulated one.
"""
from __future__ import annotations

import errno
import logging
import sys
import time

import usb.core
import usb.util

from . import protocol as P
from .disparity_calibration import Calibration, calibration_from_replies
from .errors import AccessDenied, DeviceGone, KinectError, ProtocolError
from .usb_backend import LIBUSB_ERROR_IO, LIBUSB_ERROR_NO_DEVICE

log = logging.getLogger(__name__)

REPLY_TIMEOUT_S = 1.0
USB_TIMEOUT_MS = 500


def is_gone(exc: BaseException) -> bool:
    """True when a pyusb error means the device is no longer there. EIO is not one: libusb reports a failed
    transfer on a device that is still on the bus (bad cable, hub, power) that way."""
    return isinstance(exc, usb.core.USBError) and (
        exc.errno == errno.ENODEV or getattr(exc, "backend_error_code", None) == LIBUSB_ERROR_NO_DEVICE)


def is_io_error(exc: BaseException) -> bool:
    return isinstance(exc, usb.core.USBError) and (
        exc.errno == errno.EIO or getattr(exc, "backend_error_code", None) == LIBUSB_ERROR_IO)


IO_ERROR_ADVICE = ("a USB I/O error (EIO): the Kinect is still connected but the transfer failed. Check that its "
                   "12 V adapter is plugged in, plug it straight into the computer (not through an unpowered "
                   "hub), or try another port or cable")

# What Zadig lists each Kinect device as (its USB product string and id), to pick the right one there.
ZADIG_NAMES = {"camera": "'Xbox NUI Camera' (USB ID 045E 02AE; 'Kinect for Windows Camera', 045E 02BF, on a "
                         "Kinect for Windows)",
               "motor": "'Xbox NUI Motor' (USB ID 045E 02B0)",
               "audio": "'Xbox Kinect Audio' (USB ID 045E 02AD; 045E 02BE on a Kinect for Windows), which "
                        "carries the motor and LED on models 1473 and Kinect for Windows"}


def usb_failure(exc: usb.core.USBError, what: str, other=KinectError) -> KinectError:
    """The error to raise for a failed USB transfer: the device is gone, an I/O error, or `other`."""
    if is_gone(exc):
        return DeviceGone("the Kinect was unplugged")
    if is_io_error(exc):
        return KinectError(f"{what} failed with {IO_ERROR_ADVICE}")
    return other(f"{what} failed: {exc}")


def access_advice(exc: BaseException, role: str = "camera", platform: str | None = None) -> str:
    """Why the OS refused to open the device, and the fix for this platform. `role`: camera, motor, audio."""
    platform = platform or sys.platform
    code = getattr(exc, "errno", None)
    if is_io_error(exc):
        return IO_ERROR_ADVICE
    if code == errno.EBUSY:
        return ("the device is busy: another program (libfreenect, a previous Blender session) holds it; "
                "close it and try again")
    if platform.startswith("linux"):
        if code in (errno.EACCES, errno.EPERM):
            return ("permission denied: install the udev rule (print it with "
                    "'python -m kinect_retarget devices --udev-rule'), then unplug and replug the Kinect")
        return f"the OS refused to open the Kinect {role} ({exc})"
    if platform == "win32":
        return (f"Windows has no usable driver bound to the Kinect {role}: in Zadig (https://zadig.akeo.ie), "
                f"Options > List All Devices, pick {ZADIG_NAMES.get(role, role)} and install libusbK (or WinUSB)")
    if platform == "darwin":
        return (f"macOS needs no driver or permission setup for a Kinect, so the {role} could not be opened "
                f"for another reason ({exc}): unplug and replug it, and close other programs using it")
    return f"the OS refused to open the Kinect {role} ({exc})"


def padded_reply(reply: bytes, opcode: int, tag: int) -> bytes | None:
    """A reply returned in a full 0x200-byte buffer (some Windows hosts): the reply its header announces,
    if that header answers this command; None for a buffer that holds no reply (poll again)."""
    try:
        hdr = P.parse_header(reply)
    except ProtocolError:
        return None
    size = P.HEADER_SIZE + 2 * hdr.words
    if hdr.magic != P.MAGIC_REPLY or hdr.opcode != opcode or hdr.tag != tag or size > len(reply):
        return None
    return bytes(reply[:size])


def full_reply_advice(opcode: int) -> str:
    return (f"no reply to camera command {opcode:#x}: every poll came back as a full 0x200-byte buffer without "
            "one, a known problem of some USB host controllers and Windows drivers (libfreenect issue #494). "
            "Try another USB port or controller (a USB 2 port), and on Windows the libusbK driver "
            f"(Zadig: {ZADIG_NAMES['camera']})")


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
        self.padded_replies = 0            # replies taken out of a full 0x200-byte buffer
        self.odd_write_acks: list[tuple[int, str]] = []   # (register, reply hex) not answered 0000

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
            if is_io_error(exc):
                raise KinectError(f"cannot open the Kinect camera: {IO_ERROR_ADVICE}") from exc
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
        full = False
        try:
            self.device.ctrl_transfer(P.CMD_REQUEST_OUT, 0, 0, 0, message, USB_TIMEOUT_MS)
            deadline = time.monotonic() + REPLY_TIMEOUT_S
            while True:
                reply = self.device.ctrl_transfer(P.CMD_REQUEST_IN, 0, 0, 0, P.CMD_REPLY_LENGTH, USB_TIMEOUT_MS)
                if 0 < len(reply) < P.CMD_REPLY_LENGTH:
                    break
                if len(reply) == P.CMD_REPLY_LENGTH:
                    # libfreenect polls again on a full 0x200 (a USB 3 host quirk), which never ends on hosts
                    # that always fill the buffer: take the reply its header announces when it answers us
                    full = True
                    trimmed = padded_reply(bytes(reply), opcode, tag)
                    if trimmed is not None:
                        self.padded_replies += 1
                        reply = trimmed
                        break
                if time.monotonic() > deadline:
                    raise ProtocolError(full_reply_advice(opcode) if full else
                                        f"no reply to camera command {opcode:#x} within {REPLY_TIMEOUT_S} s")
                time.sleep(0.001)
        except usb.core.USBError as exc:
            raise usb_failure(exc, f"camera command {opcode:#x}", ProtocolError) from exc
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
            # libfreenect only warns: real devices have answered 4 bytes (its issue #598) and work
            self.odd_write_acks.append((reg, payload.hex()))
            if len(self.odd_write_acks) == 1:                 # once per opened camera
                log.warning("register %#x write answered %s instead of 0000; going on, as libfreenect does",
                            reg, payload.hex() or "nothing")

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
