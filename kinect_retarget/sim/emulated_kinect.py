"""An emulated Kinect v1, as a pyusb backend (usb.backend.IBackend) with its own emulated libusb.

It enumerates the camera (and, for the 1414, the motor; for the 1473 and Kinect for Windows, the audio
chip) with real descriptors (emulated_usb.py), answers the GM/RB command protocol with register state, stalls on
malformed commands as the device's control pipe would, drives a tilt motor with an accelerometer
(emulated_motor.py), takes the audio firmware (emulated_audio.py), and streams depth built from a sequence of
depth images through its libusb's asynchronous transfers (emulated_libusb.py, emulated_stream.py), with the
faults real devices and hosts show (Faults). The driver runs unchanged against it, down to its iso pump.
"""
from __future__ import annotations

import array
import errno
import itertools
import struct
import threading
import time

import numpy as np
import usb.backend
from usb.core import USBError

from ..device import protocol as P
from ..device.depth_unpack import pack_11bit
from .emulated_motor import EmulatedMotor, Rejected
from .emulated_audio import AudioBootloader
from .emulated_libusb import EmulatedLibusb
from .emulated_stream import DepthPacketizer, DepthStreamState, FaultyWire, Faults, VirtualClock
from .emulated_usb import EmulatedHandle, UsbFunction, build_functions, calibration_reply
from ..device.protocol import TICKS_PER_FRAME, ticks_between
from ..device.usb_backend import LIBUSB_ERROR_NO_DEVICE

LIBUSB_ERROR_PIPE = -9
LIBUSB_ERROR_ACCESS = -3
LIBUSB_ERROR_TIMEOUT = -7
LIBUSB_ERROR_IO = -1
DEFAULT_SERIAL = "A00366A08793039A"
REENUMERATE_S = 2.0     # a 1473 without the LED keep-alive drops off the bus this long after its camera opens


class EmulatedKinect(usb.backend.IBackend):
    """A pyusb backend holding one emulated Kinect.

    images: sequence of (480, 640) raw 11-bit depth images the depth stream cycles through.
    model: "1414", "1473" or "k4w". clock/sleep: time source (time.monotonic/time.sleep, or a
    VirtualClock to run faster than real time).
    """

    def __init__(self, images, model: str = "1414", serial: str = DEFAULT_SERIAL, faults: Faults | None = None,
                 clock=None, sleep=None, bus: int = 1, audio_firmware: bool = False,
                 needs_keep_alive: bool | None = None, topology: str = "hub"):
        super().__init__()
        self.images = [np.asarray(img, dtype=np.uint16) for img in images]
        if not self.images:
            raise ValueError("the emulated Kinect needs at least one depth image")
        self.model = model
        # newer 1473s (and Xbox-updated 1414s, which report themselves as such) re-enumerate every few
        # seconds unless the audio chip is sent an LED command after power-on (libfreenect issue #452)
        self.needs_keep_alive = model == "1473" if needs_keep_alive is None else needs_keep_alive
        self.reenumerations = 0
        self._packed = [pack_11bit(img) for img in self.images]   # once: the wire format of each image
        self.faults = faults or Faults()
        if isinstance(clock, VirtualClock) and sleep is None:
            sleep = clock.sleep
        self.clock = clock or time.monotonic
        self.sleep = sleep or time.sleep
        self.bus = bus
        self._lock = threading.RLock()
        self._generation = 0
        self._addresses = itertools.count(5)
        self._stream_ids = itertools.count(1)
        self._first_start: float | None = None
        self._manual_plugged = True
        self.serial, self.topology, self._audio_firmware = serial, topology, audio_firmware
        self.functions = build_functions(model, serial, audio_firmware, topology)
        self.firmware_uploads = 0
        self._bulk_replies: list[bytes] = []
        self._assign_addresses()
        self._power_on()
        self._handles: dict[int, EmulatedHandle] = {}
        self._wire = FaultyWire(self.faults)
        self.lib = EmulatedLibusb(self)         # its libusb: the driver's LibusbIsoPump streams through it
        self.ctx = None
        self.streams: list[DepthPacketizer] = []
        self.register_log: list[tuple[int, int, bool]] = []   # (reg, value, iso transfers were queued)

    def expected_frame(self, timestamp: int) -> tuple[int, int]:
        """(stream number, frame number in that stream) that a delivered frame's timestamp belongs to."""
        for n, packetizer in enumerate(self.streams):
            offset = ticks_between(packetizer.first_timestamp, timestamp)
            if offset % TICKS_PER_FRAME == 0:
                return n, offset // TICKS_PER_FRAME
        raise KeyError(f"timestamp {timestamp} belongs to no emulated stream")

    def expected_raw(self, timestamp: int) -> np.ndarray:
        """The depth image the emulated device sent with this timestamp."""
        _, frame = self.expected_frame(timestamp)
        return self.images[frame % len(self.images)]

    def _assign_addresses(self) -> None:
        for fn in self.functions:
            fn.address = next(self._addresses)

    def _power_on(self) -> None:
        self.registers: dict[int, int] = {}
        self.depth_stream: DepthStreamState | None = None
        self._pending_reply: bytes | None = None
        self._reply_delay = 0
        self.motor = EmulatedMotor(self.clock)
        self.bootloader = AudioBootloader()
        self.keep_alive_received = False
        self._camera_opened_at: float | None = None

    # --- plug state --------------------------------------------------------------------------------------
    def _scheduled_plugged(self) -> bool:
        f = self.faults
        if self._first_start is None or f.unplug_at is None:
            return True
        t = self.clock() - self._first_start
        return not (t >= f.unplug_at and (f.replug_at is None or t < f.replug_at))

    @property
    def plugged(self) -> bool:
        return self._manual_plugged and self._scheduled_plugged()

    def unplug(self) -> None:
        with self._lock:
            self._manual_plugged = False
            self._update_plug()

    def replug(self) -> None:
        with self._lock:
            self._manual_plugged = True
            self._update_plug()

    def _update_plug(self) -> None:
        """Apply a plug change: unplugging invalidates every handle and resets the device on power-up."""
        plugged = self.plugged
        opened = self._camera_opened_at
        if (plugged and self._generation >= 0 and self.needs_keep_alive and not self.keep_alive_received
                and opened is not None and self.clock() - opened >= REENUMERATE_S):
            self._generation += 1                            # gone and back at once, as a fresh device
            self.reenumerations += 1
            self._assign_addresses()
            self._power_on()
        if not plugged and self._generation >= 0:
            self._generation = -(self._generation + 1)       # negative: unplugged
        elif plugged and self._generation < 0:
            self._generation = -self._generation
            # power lost: an uploaded audio firmware is gone (one the constructor was given stands for a
            # host whose driver uploads it at every plug, as the Kinect SDK does)
            self.functions = build_functions(self.model, self.serial, self._audio_firmware, self.topology)
            self._assign_addresses()
            self._power_on()

    def refresh_plug(self) -> bool:
        """Apply scheduled plug changes; True while the Kinect is on the bus."""
        with self._lock:
            self._update_plug()
            return self._generation >= 0

    def handle_by_id(self, handle_id) -> EmulatedHandle | None:
        return self._handles.get(handle_id)

    def handle_alive(self, handle: EmulatedHandle | None) -> bool:
        return (handle is not None and self.refresh_plug() and handle.generation == self._generation
                and self._enumerated(handle.function))

    def _enumerated(self, function: UsbFunction) -> bool:
        return any(fn is function for fn in self.functions)     # a re-enumerated device is a new one

    def wire_packet(self, stream: "DepthStreamState", index: int) -> bytes | None:
        """Packet `index` of a depth stream as it reaches the host: None if the wire lost it."""
        return self._wire.packet(stream.packetizer, index)

    def check_handle(self, handle: EmulatedHandle) -> None:
        with self._lock:
            self._update_plug()
            if handle.generation != self._generation or not self._enumerated(handle.function):
                self._no_device()

    # --- IBackend: enumeration and descriptors -----------------------------------------------------------
    def enumerate_devices(self):
        with self._lock:
            self._update_plug()
            if self._generation < 0:
                return []
            return [fn for fn in self.functions if not (self.faults.no_power and fn.kind == "camera")]

    def get_device_descriptor(self, dev):
        return dev.device_descriptor(self.bus)

    def get_configuration_descriptor(self, dev, config):
        if config != 0:
            raise IndexError(config)
        return dev.configuration_descriptor()

    def get_interface_descriptor(self, dev, intf, alt, config):
        return dev.interfaces[intf][alt]          # IndexError past the last alt setting, as pyusb expects

    def get_endpoint_descriptor(self, dev, ep, intf, alt, config):
        return dev.interfaces[intf][alt].endpoints[ep]

    # --- IBackend: handles ----------------------------------------------------------------------------------
    def open_device(self, dev):
        with self._lock:
            self._update_plug()
            if self._generation < 0 or not self._enumerated(dev):
                self._no_device()
            if self.faults.access_denied or dev.kind in self.faults.denied:
                raise USBError("Access denied (insufficient permissions)", LIBUSB_ERROR_ACCESS, errno.EACCES)
            handle = EmulatedHandle(dev, self._generation)
            self._handles[handle.id] = handle
            return handle

    def close_device(self, dev_handle):
        self.lib.handle_closed(dev_handle)
        self._handles.pop(dev_handle.id, None)

    def reset_device(self, dev_handle):
        self.check_handle(dev_handle)

    def set_configuration(self, dev_handle, config_value):
        self.check_handle(dev_handle)

    def get_configuration(self, dev_handle):
        self.check_handle(dev_handle)
        return 1

    def set_interface_altsetting(self, dev_handle, intf, altsetting):
        self.check_handle(dev_handle)
        if altsetting >= len(dev_handle.function.interfaces[intf]):
            self._stall()
        dev_handle.alt[intf] = altsetting

    def claim_interface(self, dev_handle, intf):
        self.check_handle(dev_handle)
        dev_handle.claimed.add(intf)
        if dev_handle.function.kind == "camera" and self._camera_opened_at is None:
            self._camera_opened_at = self.clock()

    def release_interface(self, dev_handle, intf):
        dev_handle.claimed.discard(intf)

    def is_kernel_driver_active(self, dev_handle, intf):
        self.check_handle(dev_handle)
        return False

    def detach_kernel_driver(self, dev_handle, intf):
        self.check_handle(dev_handle)

    def attach_kernel_driver(self, dev_handle, intf):
        self.check_handle(dev_handle)

    # --- IBackend: control transfers ------------------------------------------------------------------------
    def ctrl_transfer(self, dev_handle, bmRequestType, bRequest, wValue, wIndex, data, timeout):
        with self._lock:
            self.check_handle(dev_handle)
            fn = dev_handle.function
            if bmRequestType == 0x80 and bRequest == 6 and (wValue >> 8) == 3:
                return self._string_descriptor(fn, wValue & 0xFF, data)
            if fn.kind == "camera":
                return self._camera_control(bmRequestType, bRequest, wValue, wIndex, data)
            if fn.kind == "motor":
                return self._motor_control(bmRequestType, bRequest, wValue, data)
            self._stall()

    @staticmethod
    def _fill(data, payload: bytes) -> int:
        n = min(len(payload), len(data))
        data[:n] = array.array("B", payload[:n])
        return n

    def _string_descriptor(self, fn: UsbFunction, index: int, data) -> int:
        if index == 0:
            return self._fill(data, bytes([4, 3, 0x09, 0x04]))
        text = fn.strings().get(index)
        if not text:
            self._stall()
        body = text.encode("utf-16-le")
        return self._fill(data, bytes([2 + len(body), 3]) + body)

    def _stall(self):
        raise USBError("Pipe error", LIBUSB_ERROR_PIPE, errno.EPIPE)

    def _no_device(self):
        raise USBError("No such device (it may have been disconnected)", LIBUSB_ERROR_NO_DEVICE, errno.ENODEV)

    def _camera_control(self, rtype, request, value, index, data) -> int:
        if self.faults.command_eio:        # a failing cable or hub: the device stays on the bus
            raise USBError("Input/Output Error", LIBUSB_ERROR_IO, errno.EIO)
        if rtype == P.CMD_REQUEST_OUT and request == 0 and value == 0 and index == 0:
            self._camera_command(bytes(data))
            return len(data)
        if rtype == P.CMD_REQUEST_IN and request == 0 and value == 0 and index == 0:
            pad = self.faults.reply_padding    # Windows hosts that always return the full 0x200
            if self._pending_reply is None or self._reply_delay > 0:
                self._reply_delay -= 1
                return self._fill(data, bytes(P.CMD_REPLY_LENGTH)) if pad else 0   # not ready: poll again
            reply, self._pending_reply = self._pending_reply, None
            return self._fill(data, reply.ljust(P.CMD_REPLY_LENGTH, b"\0") if pad else reply)
        self._stall()

    def _camera_command(self, message: bytes) -> None:
        """Execute one GM command; malformed commands stall the pipe and leave no reply."""
        if len(message) < P.HEADER_SIZE or len(message) % 2:
            self._stall()
        hdr = P.parse_header(message)
        payload = message[P.HEADER_SIZE:]
        if hdr.magic != P.MAGIC_COMMAND or hdr.words * 2 != len(payload):
            self._stall()
        args = struct.unpack(f"<{len(payload) // 2}H", payload)
        reply = self._execute(hdr.opcode, args)
        if reply is None:
            self._stall()
        self._pending_reply = P._HEADER.pack(P.MAGIC_REPLY, len(reply) // 2, hdr.opcode, hdr.tag) + reply
        self._reply_delay = 1

    def _execute(self, opcode: int, args: tuple) -> bytes | None:
        if opcode == P.OP_READ_REGISTER and len(args) == 1:
            return P.words(args[0], self.registers.get(args[0], 0))
        if opcode == P.OP_WRITE_REGISTER and len(args) == 2:
            self._write_register(*args)
            return bytes(self.faults.write_ack_bytes)      # 0000, or 00000000 as some devices answer
        return calibration_reply(opcode, args, self.model)

    def _write_register(self, reg: int, value: int) -> None:
        self.registers[reg] = value
        self.register_log.append((reg, value, self.lib.in_flight > 0))
        if reg != P.REG_DEPTH_STREAM:
            return
        if value == 0:
            self.depth_stream = None
            return
        ready = (self.registers.get(P.REG_DEPTH_FORMAT) == 3 and self.registers.get(P.REG_DEPTH_RESOLUTION) == 1
                 and self.registers.get(P.REG_DEPTH_FPS) == 30)
        if value == 2 and ready:
            now = self.clock()
            if self._first_start is None:
                self._first_start = now
            sid = next(self._stream_ids)
            seq0 = (sid * 97) & 0xFF                     # streams do not restart at sequence 0
            packetizer = DepthPacketizer(self.images, seq0, sid * 12_345_678, packed=self._packed)
            self.depth_stream = DepthStreamState(sid, now, packetizer)
            self.streams.append(packetizer)

    def _motor_control(self, rtype, request, value, data) -> int:
        try:
            reply = self.motor.control(rtype, request, value)
        except Rejected:
            self._stall()
        return 0 if reply is None else self._fill(data, reply)

    # --- audio-chip motor commands (bulk; only with the audio firmware running) ----------------------------
    def bulk_write(self, dev_handle, ep, intf, data, timeout):
        with self._lock:
            self.check_handle(dev_handle)
            fn = dev_handle.function
            if fn.kind != "audio" or ep != 0x01:
                self._stall()
            firmware = len(fn.interfaces) >= 2
            replies = None if firmware else self.bootloader.command(bytes(data))
            if replies is None:
                try:   # the bootloader takes the LED command only: libfreenect's keep-alive
                    replies = self.motor.audio_command(bytes(data), firmware=firmware)
                except Rejected:
                    self._stall()
                self.keep_alive_received = True
            self._bulk_replies += replies
            return len(data)

    def bulk_read(self, dev_handle, ep, intf, buff, timeout):
        with self._lock:
            self.check_handle(dev_handle)
            if ep != 0x81 or not self._bulk_replies:
                raise USBError("Operation timed out", LIBUSB_ERROR_TIMEOUT, errno.ETIMEDOUT)
            n = self._fill(buff, self._bulk_replies.pop(0))
            if self.bootloader.booted and not self._bulk_replies:
                self._audio_firmware_starts()
            return n

    def _audio_firmware_starts(self) -> None:
        """The uploaded firmware runs: the audio chip leaves the bus and comes back with it (and, on a Kinect
        for Windows, another product id); the camera and motor stay as they are."""
        self.bootloader = AudioBootloader()
        new = next(fn for fn in build_functions(self.model, self.serial, True, self.topology) if fn.kind == "audio")
        new.address = next(self._addresses)
        self.functions = [new if fn.kind == "audio" else fn for fn in self.functions]
        self.firmware_uploads += 1
