"""The emulated Kinect's libusb: the asynchronous transfer functions LibusbIsoPump calls, over the emulated wire.

So the emulated Kinect streams through the same pump, callback, resubmission and cancellation code as a real
one. Transfers are real ctypes libusb_transfer structures (pyusb's definitions). Each submitted transfer
covers the next `num_iso_packets` 125 µs microframes after the ones already armed; when its last microframe
has passed on the device clock it completes with the depth packets that arrived in its window, and libusb's
event loop (handle_events) calls its callback. Packets that arrive while no transfer is armed are lost, as
on a real host that fell behind. Faults reproduce what real stacks do (Faults in emulated_stream.py):
transfers that come back CANCELLED instead of NO_DEVICE on an unplug (libusb on macOS), submits refused with
LIBUSB_ERROR_IO (bus bandwidth, some USB 3 controllers), cancellations that take a while to come back.
"""
from __future__ import annotations

import collections
import ctypes
import math
import time
from dataclasses import dataclass

import usb.backend.libusb1 as L

from .emulated_stream import MICROFRAME_S, packet_microframe
from ..device.protocol import DEPTH_PACKETS_PER_FRAME, MAX_ISO_PACKET_SIZE

# libusb's own constants (libusb.h): the emulated libusb states them itself rather than trusting the driver's
COMPLETED, TRANSFER_ERROR, CANCELLED, NO_DEVICE = 0, 1, 3, 5
LIBUSB_ERROR_IO, LIBUSB_ERROR_NO_DEVICE, LIBUSB_ERROR_NOT_FOUND = -1, -4, -5

_T, _D = L._libusb_transfer, L._libusb_iso_packet_descriptor


def microframe(t: float) -> int:
    """Index of the 125 µs microframe that time `t` (seconds) falls in."""
    return math.floor(t / MICROFRAME_S + 1e-6)


@dataclass
class _Armed:
    pointer: object           # POINTER(libusb_transfer)
    key: int
    first: int                # first microframe this transfer covers
    end: int                  # one past its last microframe
    cancelled_at: float | None = None    # real time of libusb_cancel_transfer


class EmulatedLibusb:
    """The part of libusb-1.0 that LibusbIsoPump uses, for one EmulatedKinect."""

    def __init__(self, device):
        self._dev = device
        self._memory: dict[int, object] = {}     # transfer address -> its ctypes storage
        self._armed: collections.deque[_Armed] = collections.deque()
        self._armed_end: int | None = None
        self._stream_id = None
        self._next = 0                           # next packet index of the current device stream
        self.submits = 0
        self.faulted: dict[tuple[int, int], int] = {}   # (stream id, frame) -> packets lost or truncated
        self.overrun_packets = 0                        # lost because the host had no transfer armed
        self.closed_in_flight = 0                       # transfers still armed when their handle was closed
        self.freed_in_flight = 0                        # transfers freed while libusb still owned them

    # --- what the pump sees ------------------------------------------------------------------------------
    @property
    def in_flight(self) -> int:
        return len(self._armed)

    def libusb_get_max_iso_packet_size(self, devid, endpoint: int) -> int:
        return MAX_ISO_PACKET_SIZE

    def libusb_alloc_transfer(self, n: int):
        raw = ctypes.create_string_buffer(ctypes.sizeof(_T) + max(n - 1, 0) * ctypes.sizeof(_D))
        pointer = ctypes.cast(raw, ctypes.POINTER(_T))
        self._memory[ctypes.addressof(pointer.contents)] = raw
        return pointer

    def libusb_free_transfer(self, pointer) -> None:
        key = ctypes.addressof(pointer.contents)
        if any(a.key == key for a in self._armed):
            self.freed_in_flight += 1            # a real libusb would now write into freed memory
        self._memory.pop(key, None)

    def libusb_submit_transfer(self, pointer) -> int:
        dev = self._dev
        with dev._lock:
            handle = dev.handle_by_id(pointer.contents.dev_handle)
            if handle is None or not dev.handle_alive(handle):
                return LIBUSB_ERROR_NO_DEVICE
            self.submits += 1
            f = dev.faults
            if f.submit_io_error or self.submits in f.submit_io_error_at:
                return LIBUSB_ERROR_IO
            now = microframe(dev.clock())
            first = now if self._armed_end is None or not self._armed else max(now, self._armed_end)
            end = first + pointer.contents.num_iso_packets
            self._armed.append(_Armed(ctypes.cast(pointer, ctypes.POINTER(_T)),
                                      ctypes.addressof(pointer.contents), first, end))
            self._armed_end = end
            return 0

    def libusb_cancel_transfer(self, pointer) -> int:
        key = ctypes.addressof(pointer.contents)
        for armed in self._armed:
            if armed.key == key:
                if armed.cancelled_at is None:
                    armed.cancelled_at = time.monotonic()
                return 0
        return LIBUSB_ERROR_NOT_FOUND

    def handle_closed(self, handle) -> None:
        """pyusb closed a device handle: count the transfers libusb still had armed on it."""
        self.closed_in_flight += sum(1 for a in self._armed if a.pointer.contents.dev_handle == handle.id)

    def libusb_handle_events_timeout_completed(self, ctx, timeval, completed) -> int:
        """Complete what is due (calling callbacks), waiting up to the timeout for something to be."""
        tv = timeval._obj
        timeout = tv.tv_sec + tv.tv_usec / 1e6
        dev = self._dev
        deadline = dev.clock() + timeout
        real_deadline = time.monotonic() + timeout
        while True:
            done = self._due()
            for armed in done:
                armed.pointer.contents.callback(armed.pointer)
            if done:
                return 0
            now = dev.clock()
            if now >= deadline or time.monotonic() >= real_deadline:
                return 0
            if self._armed and all(a.cancelled_at is not None for a in self._armed):
                time.sleep(min(0.005, max(real_deadline - time.monotonic(), 0.0)))   # cancellations: real time
                continue
            wake = self._armed[0].end * MICROFRAME_S if self._armed else deadline
            dev.sleep(max(min(wake, deadline) - now, 0.0) + 1e-7)

    # --- the wire -------------------------------------------------------------------------------------------
    def _due(self) -> list[_Armed]:
        """Transfers that come back now, their status and packets filled in."""
        dev = self._dev
        with dev._lock:
            dev.refresh_plug()
            done = []
            delay = dev.faults.cancel_delay_s
            for armed in list(self._armed):
                if armed.cancelled_at is not None and time.monotonic() - armed.cancelled_at >= delay:
                    self._armed.remove(armed)
                    armed.pointer.contents.status = CANCELLED
                    done.append(armed)
            gone = [a for a in self._armed if not dev.handle_alive(dev.handle_by_id(a.pointer.contents.dev_handle))]
            if gone:                   # unplugged or re-enumerated: its transfers come back at once
                status = CANCELLED if dev.faults.unplug_cancels else NO_DEVICE
                for armed in gone:
                    self._armed.remove(armed)
                    armed.pointer.contents.status = status
                done += gone
                return done
            now = microframe(dev.clock())
            while self._armed and self._armed[0].end <= now and self._armed[0].cancelled_at is None:
                armed = self._armed.popleft()
                self._fill(armed)
                done.append(armed)
            return done

    def _fill(self, armed: _Armed) -> None:
        t = armed.pointer.contents
        t.status = COMPLETED
        descs = L._get_iso_packet_list(t)
        for desc in descs:
            desc.status, desc.actual_length = COMPLETED, 0
        stream = self._dev.depth_stream
        if stream is None or self._dev.faults.no_data:
            return
        if stream.id != self._stream_id:
            self._stream_id, self._next = stream.id, 0
        start = microframe(stream.start_time)
        while True:
            i = self._next
            due = start + packet_microframe(i)
            if due >= armed.end:
                break
            self._next += 1
            if due < armed.first:
                self.overrun_packets += 1            # no transfer was armed for it: gone for good
                continue
            slot = descs[due - armed.first]
            key = (stream.id, i // DEPTH_PACKETS_PER_FRAME)
            packet = self._dev.wire_packet(stream, i)
            if packet is None:
                self.faulted[key] = self.faulted.get(key, 0) + 1
                slot.status = TRANSFER_ERROR
                continue
            if len(packet) < stream.packetizer.packet_length(i):
                self.faulted[key] = self.faulted.get(key, 0) + 1
            ctypes.memmove(t.buffer + (due - armed.first) * slot.length, packet, len(packet))
            slot.actual_length = len(packet)
