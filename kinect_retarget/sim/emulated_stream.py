"""The emulated Kinect's isochronous depth stream: packets on a 125 µs microframe clock, with fault injection.

DepthPacketizer cuts packed frames into the device's 242 packets (headers, sequence numbers, 60 MHz
timestamps). FaultyWire applies the injected faults to each packet; emulated_libusb.py delivers the packets
to the driver's transfers on the microframe clock.
"""
from __future__ import annotations

import threading
from dataclasses import dataclass, field

import numpy as np

from ..device.depth_unpack import pack_11bit
from ..device.protocol import (DEPTH_LAST_PAYLOAD, DEPTH_PACKETS_PER_FRAME, DEPTH_PAYLOAD, PACKET_HEADER_SIZE,
                               TICKS_PER_FRAME, advance_ticks, build_packet_header, depth_packet_flag)

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
    denied: tuple[str, ...] = ()               # only these devices ("camera", "motor", "audio") refuse to open
    no_power: bool = False                     # no 12 V adapter: motor and audio enumerate, the camera does not
    seed: int = 0
    # --- what real hosts and devices do (libfreenect issues in docs/usb_driver.md) ---
    unplug_cancels: bool = False               # on unplug transfers come back CANCELLED (libusb on macOS)
    submit_io_error: bool = False              # every iso submit fails with LIBUSB_ERROR_IO (bandwidth)
    submit_io_error_at: tuple[int, ...] = ()   # these iso submits (1 = the first) fail with LIBUSB_ERROR_IO
    cancel_delay_s: float = 0.0                # real seconds before a cancelled transfer comes back (inf: never)
    write_ack_bytes: int = 2                   # register writes answered with 2 bytes (0000) or 4 (00000000)
    reply_padding: bool = False                # every control IN returns 0x200 bytes (Windows, issue #494)
    command_eio: bool = False                  # camera control transfers fail with EIO (device still there)
    no_data: bool = False                      # the depth stream starts but no packet ever arrives


class DepthPacketizer:
    """Packets of one depth stream: frame f of the stream shows images[f % len(images)]."""

    def __init__(self, images: list[np.ndarray], first_seq: int = 0, first_timestamp: int = 0,
                 packed: list[bytes] | None = None):
        self._packed = packed if packed is not None else [pack_11bit(img) for img in images]
        self.first_seq = first_seq
        self.first_timestamp = first_timestamp

    def timestamp(self, frame: int) -> int:
        return advance_ticks(self.first_timestamp, frame * TICKS_PER_FRAME)

    @staticmethod
    def packet_length(index: int) -> int:
        """Bytes of packet `index` as the device sends it, header included."""
        last = index % DEPTH_PACKETS_PER_FRAME == DEPTH_PACKETS_PER_FRAME - 1
        return (DEPTH_LAST_PAYLOAD if last else DEPTH_PAYLOAD) + PACKET_HEADER_SIZE

    def packet(self, index: int) -> bytes:
        """Packet number `index` of the stream (all frames back to back)."""
        frame, j = divmod(index, DEPTH_PACKETS_PER_FRAME)
        data = self._packed[frame % len(self._packed)]
        size = DEPTH_LAST_PAYLOAD if j == DEPTH_PACKETS_PER_FRAME - 1 else DEPTH_PAYLOAD
        start = j * DEPTH_PAYLOAD
        header = build_packet_header(depth_packet_flag(j), self.first_seq + index, size + PACKET_HEADER_SIZE,
                                     self.timestamp(frame))
        return header + data[start:start + size]


@dataclass
class DepthStreamState:
    """The depth stream the device is sending: started by register 0x06 = 2, ended by 0x06 = 0."""
    id: int
    start_time: float
    packetizer: DepthPacketizer


def packet_due_time(index: int) -> float:
    """Seconds after stream start at which packet `index` reaches the host."""
    frame, j = divmod(index, DEPTH_PACKETS_PER_FRAME)
    return frame * FRAME_S + (j + 1) * MICROFRAME_S


def packet_microframe(index: int) -> int:
    """The microframe (counted from the stream's start) that carries packet `index`: one packet per
    microframe, 242 of the ~267 in each 1/30 s frame."""
    frame, j = divmod(index, DEPTH_PACKETS_PER_FRAME)
    return (frame * 8000) // 30 + j + 1


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


class FaultyWire:
    """What the wire does to each packet under the injected faults: loses it (None), cuts it short, or not."""

    def __init__(self, faults: Faults):
        self._rng = np.random.default_rng(faults.seed)
        self._loss_rate = faults.loss_rate
        self._lost = set()
        for frame, first, count in faults.bursts:
            base = frame * DEPTH_PACKETS_PER_FRAME + first
            self._lost.update(range(base, base + count))
        self._truncate = {(f, p): keep for f, p, keep in faults.truncate}

    def packet(self, packetizer: DepthPacketizer, index: int) -> bytes | None:
        if index in self._lost or (self._loss_rate and self._rng.random() < self._loss_rate):
            return None
        packet = packetizer.packet(index)
        keep = self._truncate.get(divmod(index, DEPTH_PACKETS_PER_FRAME))
        return packet if keep is None else packet[:keep]


def packets_for_frames(images: list[np.ndarray], n_frames: int, first_seq: int = 0,
                       first_timestamp: int = 0) -> list[bytes]:
    """All packets of the first n_frames of a stream (tests and dumps)."""
    packetizer = DepthPacketizer(images, first_seq, first_timestamp)
    return [packetizer.packet(i) for i in range(n_frames * DEPTH_PACKETS_PER_FRAME)]
