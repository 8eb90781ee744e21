"""The in-flight transfer manager (LibusbIsoPump) against a fake libusb that behaves like the real async API.

The fake owns real ctypes libusb_transfer structures (pyusb's definitions), completes them in submission
order from handle_events, and calls the pump's ctypes callback, so the pump's pointer handling, per-packet
status/length parsing, resubmission, cancellation and freeing are exercised as with libusb.
"""
import collections
import ctypes

import numpy as np
import pytest
import usb.backend.libusb1 as L

from kinect_retarget.device.depth_unpack import unpack_11bit
from kinect_retarget.sim.emulated_stream import DepthPacketizer
from kinect_retarget.device.errors import DeviceGone, KinectError
from kinect_retarget.device.reassembly import FrameAssembler
from kinect_retarget.device.usb_backend import CANCELLED, COMPLETED, NO_DEVICE, LibusbIsoPump, open_iso_pump

T, D = L._libusb_transfer, L._libusb_iso_packet_descriptor


class FakeLibusb:
    def __init__(self, slots):
        self.slots = iter(slots)           # per microframe: bytes, b"" (empty) or None (failed)
        self.pending = collections.deque()
        self.memory = {}
        self.freed = set()
        self.cancelled = set()
        self.unplugged = False
        self.ignore_cancel = False
        self.submits = 0

    def libusb_alloc_transfer(self, n):
        raw = ctypes.create_string_buffer(ctypes.sizeof(T) + (n - 1) * ctypes.sizeof(D))
        p = ctypes.cast(raw, ctypes.POINTER(T))
        self.memory[ctypes.addressof(p.contents)] = raw
        return p

    def libusb_free_transfer(self, p):
        self.freed.add(ctypes.addressof(p.contents))

    def libusb_submit_transfer(self, p):
        if self.unplugged:
            return -4
        self.submits += 1
        self.pending.append(ctypes.cast(p, ctypes.POINTER(T)))
        return 0

    def libusb_cancel_transfer(self, p):
        self.cancelled.add(ctypes.addressof(p.contents))
        return 0

    def libusb_handle_events_timeout_completed(self, ctx, tv, completed, per_call=2):
        for _ in range(min(per_call, len(self.pending)) if not self.unplugged else len(self.pending)):
            p = self.pending.popleft()
            t = p.contents
            key = ctypes.addressof(t)
            if key in self.cancelled and not self.ignore_cancel:
                t.status = CANCELLED
            elif self.unplugged:
                t.status = NO_DEVICE
            else:
                t.status = COMPLETED
                descs = L._get_iso_packet_list(t)
                for i, desc in enumerate(descs):
                    data = next(self.slots, b"")
                    desc.status, desc.actual_length = (1, 0) if data is None else (0, len(data))
                    if data:
                        ctypes.memmove(t.buffer + i * desc.length, data, len(data))
            if key in self.cancelled and self.ignore_cancel:
                self.pending.append(p)     # libusb has not given it back yet
                continue
            t.callback(p)
        return 0


def _pump(lib, transfers=4, ppt=8):
    return LibusbIsoPump(lib, None, None, 0x82, transfers, ppt, 1920, transfer_module=L)


def _frames_slots(images, n_frames):
    packetizer = DepthPacketizer(images, first_seq=250)
    slots = []
    for i in range(n_frames * 242):
        slots.append(packetizer.packet(i))
        if i % 9 == 0:
            slots.append(b"")               # empty microframes, as the device leaves ~1 in 10
    return slots


def test_keeps_all_transfers_in_flight_and_delivers_bit_exact_frames(real_depth):
    lib = FakeLibusb(_frames_slots(real_depth[:3], 3))
    pump = _pump(lib)
    pump.start()
    assert len(lib.pending) == 4
    asm, frames = FrameAssembler(), []
    for _ in range(200):
        frames += asm.feed(pump.poll(0.01))
        assert len(lib.pending) == 4        # every completed transfer was resubmitted at once
    assert len(frames) == 3 and asm.stats.packets_lost == 0
    for img, f in zip(real_depth[:3], frames):
        np.testing.assert_array_equal(unpack_11bit(f.packed), img)
    pump.stop()
    assert len(lib.freed) == 4 and not pump._in_flight


def test_failed_slots_become_none_and_empty_slots_are_skipped():
    lib = FakeLibusb([b"RB" + bytes(10), None, b"", b"RB" + bytes(20)] + [b""] * 28)
    pump = _pump(lib, transfers=2, ppt=16)
    pump.start()
    out = pump.poll(0.01)
    assert out == [b"RB" + bytes(10), None, b"RB" + bytes(20)]


def test_unplug_raises_device_gone():
    lib = FakeLibusb([b"RB" + bytes(10)] * 1000)
    pump = _pump(lib)
    pump.start()
    pump.poll(0.01)
    lib.unplugged = True
    with pytest.raises(DeviceGone):
        for _ in range(3):
            pump.poll(0.01)
    pump.stop()                               # waits for libusb to hand every transfer back, then frees
    assert not lib.pending and len(lib.freed) == 4


def test_stop_keeps_transfers_that_libusb_has_not_returned():
    lib = FakeLibusb([b""] * 100000)
    lib.ignore_cancel = True
    pump = _pump(lib)
    pump.start()
    pump.stop(timeout=0.02)
    assert lib.cancelled and not lib.freed   # freeing them would hand libusb dangling memory
    assert len(pump._transfers) == 4


def test_open_iso_pump_refuses_a_backend_without_libusb(real_depth):
    class NotLibusb:
        pass

    class Resources:
        backend = NotLibusb()

        def managed_open(self):
            return object()

    class Device:
        _ctx = Resources()

    with pytest.raises(KinectError, match="libusb1 backend"):
        open_iso_pump(Device(), 0x82)
