"""The emulated Kinect's isochronous depth stream: packets on a 125 µs microframe clock, with fault injection.

DepthPacketizer cuts packed frames into the device's 242 packets (headers, sequence numbers, 60 MHz
timestamps). EmulatedIsoPump is the emulated side of the usb_backend seam: it hands out the packets that
have "arrived" by the clock, and loses the ones that arrived while the host had no transfer in flight,
exactly like a real host that fell behind.
"""
from __future__ import annotations

import math
import threading
from dataclasses import dataclass, field

import numpy as np

from usb.core import USBError

from ..device.depth_unpack import pack_11bit
from ..device.errors import DeviceGone
from ..device.protocol import (DEPTH_LAST_PAYLOAD, DEPTH_PACKETS_PER_FRAME, DEPTH_PAYLOAD, PACKET_HEADER_SIZE,
                       TICKS_PER_FRAME, build_packet_header, depth_packet_flag)

MICROFRAME_S = 125e-6
FRAME_S = 1.0 / 30.0


@dataclass
class Faults:
    """What goes wrong on the emulated wire. Frame numbers count from the start of each stream."""
    loss_rate: float = 0.0                     # each packet independently reported failed
    bursts: list[tuple[int, int, int]] = field(default_factory=list)    # (frame, first packet, count) lost
    truncate: list[tuple[int, int, int]] = field(default_factory=list)  # (frame, packet, bytes kept)
    unplug_at: float | None = None             # seconds after the first depth start
    replug_at: float | None = None
    access_denied: bool = False                # open() fails as without a udev rule
    seed: int = 0


class DepthPacketizer:
    """Packets of one depth stream: frame f of the stream shows images[f % len(images)]."""

    def __init__(self, images: list[np.ndarray], first_seq: int = 0, first_timestamp: int = 0,
                 packed: list[bytes] | None = None):
        self._packed = packed if packed is not None else [pack_11bit(img) for img in images]
        self.first_seq = first_seq
        self.first_timestamp = first_timestamp

    def timestamp(self, frame: int) -> int:
        return (self.first_timestamp + frame * TICKS_PER_FRAME) & 0xFFFFFFFF

    def packet(self, index: int) -> bytes:
        """Packet number `index` of the stream (all frames back to back)."""
        frame, j = divmod(index, DEPTH_PACKETS_PER_FRAME)
        data = self._packed[frame % len(self._packed)]
        size = DEPTH_LAST_PAYLOAD if j == DEPTH_PACKETS_PER_FRAME - 1 else DEPTH_PAYLOAD
        start = j * DEPTH_PAYLOAD
        header = build_packet_header(depth_packet_flag(j), self.first_seq + index, size + PACKET_HEADER_SIZE,
                                     self.timestamp(frame))
        return header + data[start:start + size]


def packet_due_time(index: int) -> float:
    """Seconds after stream start at which packet `index` reaches the host."""
    frame, j = divmod(index, DEPTH_PACKETS_PER_FRAME)
    return frame * FRAME_S + (j + 1) * MICROFRAME_S


class VirtualClock:
    """A clock that jumps instead of sleeping, so emulated streams can run faster than real time."""

    def __init__(self, start: float = 0.0):
        self.now = start
        self._lock = threading.Lock()

    def __call__(self) -> float:
        return self.now

    def sleep(self, seconds: float) -> None:
        with self._lock:
            self.now += max(seconds, 0.0)


class EmulatedIsoPump:
    """Emulated implementation of the iso transfer seam (see usb_backend.IsoPump)."""

    def __init__(self, device, handle, endpoint: int, transfers: int, packets_per_transfer: int):
        self._device = device          # the EmulatedKinect
        self._handle = handle
        self.endpoint = endpoint
        self.window_s = transfers * packets_per_transfer * MICROFRAME_S   # what the host keeps armed
        self.transfer_s = packets_per_transfer * MICROFRAME_S              # packets reach the host per transfer
        self._armed_until: float | None = None
        self._next = 0                 # next packet index of the current stream
        self._stream_id = None
        self._rng = np.random.default_rng(device.faults.seed)
        self._lost_set = self._burst_set(device.faults)
        self._truncate = {(f, p): keep for f, p, keep in device.faults.truncate}
        self.running = False
        self.faulted: dict[tuple[int, int], int] = {}   # (stream id, frame) -> packets lost or truncated
        self.overrun_packets = 0                       # lost because the host had no transfer in flight

    @staticmethod
    def _burst_set(faults: Faults) -> set[int]:
        lost = set()
        for frame, first, count in faults.bursts:
            base = frame * DEPTH_PACKETS_PER_FRAME + first
            lost.update(range(base, base + count))
        return lost

    def start(self) -> None:
        self._device.check_handle(self._handle)
        self.running = True
        self._armed_until = self._device.clock() + self.window_s

    def stop(self) -> None:
        self.running = False

    def poll(self, timeout: float) -> list:
        """Packets that arrived since the last poll (None = a slot the host saw fail); [] on timeout."""
        dev = self._device
        deadline = dev.clock() + timeout
        while True:
            try:
                dev.check_handle(self._handle)
            except USBError as exc:
                raise DeviceGone("the Kinect was unplugged") from exc
            stream = dev.depth_stream
            now = dev.clock()
            if stream is not None:
                if stream.id != self._stream_id:
                    self._stream_id, self._next = stream.id, 0
                packets = self._collect(stream, now)
                self._armed_until = now + self.window_s
                if packets:
                    return packets
                due = packet_due_time(self._next)
                wake = stream.start_time + math.ceil(due / self.transfer_s) * self.transfer_s
            else:
                self._armed_until = now + self.window_s
                wake = deadline
            if now >= deadline:
                return []
            dev.sleep(max(min(wake, deadline) - now, 0.0) + 1e-4)

    def _collect(self, stream, now: float) -> list:
        out = []
        faults = self._device.faults
        # like libusb, hand packets over a whole transfer at a time, when the transfer completes
        elapsed = math.floor((now - stream.start_time) / self.transfer_s) * self.transfer_s
        armed = self._armed_until - stream.start_time
        while True:
            due = packet_due_time(self._next)
            if due > elapsed:
                break
            i = self._next
            self._next += 1
            if due > armed:
                self.overrun_packets += 1                   # no transfer was in flight: gone for good
                continue
            key = (stream.id, i // DEPTH_PACKETS_PER_FRAME)
            if i in self._lost_set or (faults.loss_rate and self._rng.random() < faults.loss_rate):
                self.faulted[key] = self.faulted.get(key, 0) + 1
                out.append(None)
                continue
            packet = stream.packetizer.packet(i)
            keep = self._truncate.get(divmod(i, DEPTH_PACKETS_PER_FRAME))
            if keep is not None:
                self.faulted[key] = self.faulted.get(key, 0) + 1
                packet = packet[:keep]
            out.append(packet)
        return out


def packets_for_frames(images: list[np.ndarray], n_frames: int, first_seq: int = 0,
                       first_timestamp: int = 0) -> list[bytes]:
    """All packets of the first n_frames of a stream (tests and dumps)."""
    packetizer = DepthPacketizer(images, first_seq, first_timestamp)
    return [packetizer.packet(i) for i in range(n_frames * DEPTH_PACKETS_PER_FRAME)]
