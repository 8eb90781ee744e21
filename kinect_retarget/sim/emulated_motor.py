"""The emulated Kinect's tilt motor, LED and accelerometer, reachable two ways: the 1414's motor device
(vendor control transfers) and the audio chip's bulk commands on models 1473 / Kinect for Windows.

The accelerometer shows gravity for the current pitch as (0, cos θ, sin θ) · 819 counts: the axes are this
emulator's choice, not a measured fact.
"""
from __future__ import annotations

import math
import struct

from ..device.motor import (ALT_CMD_LED, ALT_CMD_STATE, ALT_CMD_TILT, ALT_MAGIC, ALT_REPLY_MAGIC, COUNTS_PER_G,
                    TILT_LIMIT_DEG)

MOTOR_DEG_PER_S = 15.0
LED_CODES = range(7)


class Rejected(Exception):
    """The request is not one the device accepts (the caller stalls the pipe)."""


class EmulatedMotor:
    def __init__(self, clock):
        self.clock = clock
        self.led = 1
        self.tilt_deg = 0.0
        self.target_deg = 0.0
        self._since = clock()

    def _advance(self) -> None:
        now = self.clock()
        step = MOTOR_DEG_PER_S * (now - self._since)
        self._since = now
        d = self.target_deg - self.tilt_deg
        self.tilt_deg = self.target_deg if abs(d) <= step else self.tilt_deg + math.copysign(step, d)

    def _gravity(self) -> tuple[int, int, int]:
        theta = math.radians(self.tilt_deg)
        return 0, round(COUNTS_PER_G * math.cos(theta)), round(COUNTS_PER_G * math.sin(theta))

    def _aim(self, degrees: float) -> None:
        self.target_deg = max(-TILT_LIMIT_DEG, min(TILT_LIMIT_DEG, degrees))

    def control(self, rtype: int, request: int, value: int) -> bytes | None:
        """A control request to the 1414 motor device: reply bytes for IN requests, None for OUT."""
        self._advance()
        if rtype == 0x40 and request == 0x31:
            self._aim(struct.unpack("<h", struct.pack("<H", value & 0xFFFF))[0] / 2.0)
            return None
        if rtype == 0x40 and request == 0x06 and value in LED_CODES:
            self.led = value
            return None
        if rtype == 0xC0 and request == 0x32:
            moving = self.tilt_deg != self.target_deg
            status = 4 if moving else (1 if abs(self.tilt_deg) >= TILT_LIMIT_DEG else 0)
            return struct.pack(">2xhhhbB", *self._gravity(), round(self.tilt_deg * 2), status)
        if rtype == 0xC0 and request == 0x10:
            return b"\x22"
        raise Rejected

    def audio_command(self, data: bytes, firmware: bool = True) -> list[bytes]:
        """A bulk command to the audio chip: the replies it queues on endpoint 0x81. Without its firmware
        (bootloader) it only takes the LED command."""
        if len(data) < 16:
            raise Rejected
        magic, tag, _arg1, cmd = struct.unpack_from("<4I", data)
        if not firmware and cmd != ALT_CMD_LED:
            raise Rejected
        arg2 = struct.unpack_from("<i", data, 16)[0] if len(data) >= 20 else 0
        self._advance()
        replies, status = [], 0
        if magic != ALT_MAGIC:
            status = 1
        elif cmd == ALT_CMD_TILT:
            self._aim(float(arg2))
        elif cmd == ALT_CMD_LED:
            self.led = arg2
        elif cmd == ALT_CMD_STATE:
            body = bytearray(104)
            struct.pack_into("<4i", body, 16, *self._gravity(), round(self.tilt_deg))
            replies.append(bytes(body))
        else:
            status = 2
        replies.append(struct.pack("<3I", ALT_REPLY_MAGIC, tag, status))
        return replies
