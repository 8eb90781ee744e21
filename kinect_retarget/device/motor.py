"""Tilt motor, LED and accelerometer.

Model 1414 has a motor USB device driven by vendor control transfers. Model 1473 and Kinect for Windows
route the same functions through the audio chip as bulk commands, which only exist once the audio firmware
(proprietary, not shipped) is running; without it MotorUnavailable says so plainly.
"""
from __future__ import annotations

import itertools
import logging
import struct
from dataclasses import dataclass

import numpy as np
import usb.core
import usb.util

from . import protocol as P
from .kinect_camera import IO_ERROR_ADVICE, access_advice, is_gone, is_io_error
from .discovery import KinectInfo, find_kinect
from .audio_firmware import boot_audio_chip, find_firmware
from .errors import AccessDenied, BadInputFile, DeviceGone, KinectError, MotorUnavailable, ProtocolError

log = logging.getLogger(__name__)

TILT_LIMIT_DEG = 27.0
COUNTS_PER_G = 819.0
LED_MODES = {"off": 0, "green": 1, "red": 2, "yellow": 3, "blink": 4, "blink-green": 4, "blink-red-yellow": 6}
_ALT_LED = {0: 1, 1: 3, 2: 4, 3: 3, 4: 2, 6: 2}     # audio-chip LED codes: 1 off, 2 blink, 3 green, 4 red
STATUS_TEXT = {0: "stopped", 1: "at limit", 4: "moving"}
ALT_MAGIC, ALT_REPLY_MAGIC = 0x06022009, 0x0A6FE000
ALT_CMD_LED, ALT_CMD_TILT, ALT_CMD_STATE = 0x10, 0x803B, 0x8032


@dataclass(frozen=True)
class MotorState:
    accel_g: np.ndarray        # (3,) accelerometer in g (x, y, z of the sensor); gravity when still
    tilt_deg: float | None     # motor angle relative to the horizon, None if the device did not say
    status: str                # "stopped", "moving", "at limit" or "unknown"


def clamp_tilt(angle: float) -> float:
    if not np.isfinite(angle):
        raise ValueError(f"tilt angle must be a number, got {angle}")
    return float(min(TILT_LIMIT_DEG, max(-TILT_LIMIT_DEG, angle)))


def _usb_io(fn, *args, role: str = "motor"):
    try:
        return fn(*args)
    except usb.core.USBError as exc:
        if is_gone(exc):
            raise DeviceGone("the Kinect was unplugged") from exc
        if is_io_error(exc):
            raise KinectError(f"the Kinect {role} failed with {IO_ERROR_ADVICE}") from exc
        raise AccessDenied(f"cannot use the Kinect {role}: {access_advice(exc, role)}") from exc
    except NotImplementedError as exc:
        raise AccessDenied(f"cannot use the Kinect {role}: {access_advice(exc, role)}") from exc


def audio_command(device, tag: int, cmd: int, arg1: int = 0, arg2: int | None = None, data_len: int = 0) -> bytes:
    """One bulk command to the audio chip (models 1473 / Kinect for Windows): {magic, tag, arg1, cmd[, arg2]}
    on endpoint 0x01, an optional data reply, then the 12-byte status {0x0A6FE000, tag, 0} on 0x81."""
    fields = [ALT_MAGIC, tag, arg1, cmd] + ([] if arg2 is None else [arg2 & 0xFFFFFFFF])
    _usb_io(device.write, 0x01, struct.pack(f"<{len(fields)}I", *fields), 250, role="audio")
    data = bytes(_usb_io(device.read, 0x81, 512, 250, role="audio")) if data_len else b""
    reply = bytes(_usb_io(device.read, 0x81, 512, 250, role="audio"))
    if len(reply) != 12:
        raise ProtocolError(f"audio chip reply has {len(reply)} bytes, expected 12")
    magic, _tag, status = struct.unpack("<3I", reply)
    if magic != ALT_REPLY_MAGIC or status != 0:
        raise ProtocolError(f"audio chip command {cmd:#x} failed (magic {magic:#x}, status {status})")
    return data


_keep_alive_tags = itertools.count()


def send_keep_alive(audio) -> str:
    """libfreenect's keep-alive for every Kinect that is not a 1414: reset the audio chip (a previous session
    may have left it mid-command), then set its LED green. Without it newer 1473s (and Xbox-updated 1414s,
    which no longer report themselves as 1414) re-enumerate every few seconds. It needs no audio firmware.
    Returns '' when sent, else what went wrong: a warning, since the depth stream may still work."""
    if audio is None:
        return "LED keep-alive not sent: the Kinect's audio device was not found"
    try:
        try:
            audio.reset()
        except (usb.core.USBError, NotImplementedError) as exc:
            if is_gone(exc):
                raise DeviceGone("the Kinect was unplugged") from exc
            log.info("audio chip reset before the keep-alive failed (%s); sending it anyway", exc)
        usb.util.dispose_resources(audio)
        _usb_io(usb.util.claim_interface, audio, 0, role="audio")
        try:
            audio_command(audio, next(_keep_alive_tags), ALT_CMD_LED, 0, _ALT_LED[LED_MODES["green"]])
        finally:
            try:
                usb.util.release_interface(audio, 0)
            except (usb.core.USBError, NotImplementedError):
                pass
        return ""
    except (AccessDenied, ProtocolError) as exc:
        return f"LED keep-alive not sent ({exc}); the Kinect may drop off the bus every few seconds"
    finally:
        usb.util.dispose_resources(audio)


class KinectMotor:
    """Motor functions of one Kinect (from discovery)."""

    def __init__(self, info: KinectInfo):
        if not info.motor_available or info.motor is None:
            raise MotorUnavailable(f"{info.model} {info.serial}: {info.motor_note or 'no motor device'}")
        self.info = info
        self.device = info.motor
        self.via_audio = info.motor.idProduct not in P.MOTOR_PIDS
        self._tag = 0

    def _io(self, fn, *args):
        return _usb_io(fn, *args)

    def _alt_command(self, cmd: int, arg1: int = 0, arg2: int | None = None, data_len: int = 0) -> bytes:
        self._tag += 1
        return audio_command(self.device, self._tag - 1, cmd, arg1, arg2, data_len)

    # --- public --------------------------------------------------------------------------------------------
    def set_tilt(self, angle: float) -> float:
        """Tilt to `angle` degrees (clamped to ±27) relative to the horizon; returns the angle sent."""
        angle = clamp_tilt(angle)
        if self.via_audio:
            self._alt_command(ALT_CMD_TILT, 0, round(angle))
        else:
            self._io(self.device.ctrl_transfer, 0x40, 0x31, round(2 * angle) & 0xFFFF, 0, b"")
        return angle

    def set_led(self, mode: str) -> None:
        if mode not in LED_MODES:
            raise ValueError(f"unknown LED mode {mode!r}: choose from {', '.join(LED_MODES)}")
        code = LED_MODES[mode]
        if self.via_audio:
            self._alt_command(ALT_CMD_LED, 0, _ALT_LED[code])
        else:
            self._io(self.device.ctrl_transfer, 0x40, 0x06, code, 0, b"")

    def state(self) -> MotorState:
        if self.via_audio:
            data = self._alt_command(ALT_CMD_STATE, 0x68, None, data_len=104)
            if len(data) < 32:
                raise ProtocolError(f"motor state reply has {len(data)} bytes, expected 104")
            x, y, z, tilt = struct.unpack_from("<4i", data, 16)
            return MotorState(np.array([x, y, z]) / COUNTS_PER_G, float(tilt), "unknown")
        buf = bytes(self._io(self.device.ctrl_transfer, 0xC0, 0x32, 0, 0, 10))
        if len(buf) != 10:
            raise ProtocolError(f"motor state reply has {len(buf)} bytes, expected 10")
        x, y, z, tilt, status = struct.unpack(">2xhhhbB", buf)
        tilt_deg = None if tilt == -128 else tilt / 2.0          # -128: the motor did not report an angle
        return MotorState(np.array([x, y, z]) / COUNTS_PER_G, tilt_deg, STATUS_TEXT.get(status, "unknown"))

    def close(self) -> None:
        usb.util.dispose_resources(self.device)


def open_motor(backend=None, serial: str | None = None) -> KinectMotor:
    """The motor of the (first) Kinect. On a 1473 / Kinect for Windows whose audio chip is still in its
    bootloader, audios.bin is uploaded first when it can be found (as libfreenect does)."""
    info = find_kinect(backend, serial)
    if info.needs_audio_firmware and find_firmware() is not None:
        try:
            info = boot_audio_chip(info, lambda s: find_kinect(backend, s))
        except BadInputFile:
            raise                         # the user's file: their input, named in the message
        except KinectError as exc:
            raise MotorUnavailable(f"{info.model} {info.serial}: {exc}") from exc
    return KinectMotor(info)


def set_tilt(angle: float, backend=None, serial: str | None = None) -> float:
    """Tilt the (first) Kinect; returns the angle actually sent after clamping."""
    motor = open_motor(backend, serial)
    try:
        return motor.set_tilt(angle)
    finally:
        motor.close()
