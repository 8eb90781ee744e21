"""What real Kinects, hosts and operating systems do that a well-behaved device does not (issue 17), each
taught to the emulated Kinect and met by the driver through the same code as with hardware: DepthStream ->
KinectCamera (pyusb control transfers) and LibusbIsoPump (libusb's async API, here the emulated libusb)."""
import math
import queue
import time

import numpy as np
import pytest
import usb.core

from kinect_retarget.device import protocol as P
from kinect_retarget.device.kinect_camera import KinectCamera
from kinect_retarget.device.discovery import find_kinect, list_devices
from kinect_retarget.sim.emulated_kinect import DEFAULT_SERIAL, REENUMERATE_S, EmulatedKinect
from kinect_retarget.sim.emulated_stream import Faults, VirtualClock
from kinect_retarget.device.errors import DeviceGone, ProtocolError
from kinect_retarget.device.motor import open_motor
from kinect_retarget.device.protocol import TICKS_PER_FRAME
from kinect_retarget.device.depth_stream import ERROR, UNPLUGGED, DepthStream


def _watch(stream, until, seconds=20.0):
    """Frames, states and messages seen until until(frames, status) or `seconds` pass."""
    frames, states, messages = [], [], []
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        status = stream.status
        if not states or states[-1] != status.state:
            states.append(status.state)
        if not messages or messages[-1] != status.message:
            messages.append(status.message)
        if until(frames, status):
            break
        try:
            frames.append(stream.frames.get(timeout=0.01))
        except queue.Empty:
            pass
    return frames, states, messages


def _consecutive(frames) -> bool:
    return all((b.timestamp - a.timestamp) & 0xFFFFFFFF == TICKS_PER_FRAME for a, b in zip(frames, frames[1:]))


# --- 1. the LED keep-alive a 1473 needs ------------------------------------------------------------------------
def test_emulated_1473_reenumerates_unless_the_keep_alive_is_sent(real_depth):
    from kinect_retarget.device.motor import send_keep_alive
    clock = VirtualClock()
    emu = EmulatedKinect(real_depth[:1], model="1473", clock=clock)
    camera = KinectCamera(find_kinect(emu).camera).open()
    clock.sleep(REENUMERATE_S + 0.1)
    with pytest.raises(DeviceGone):                 # it dropped off the bus and came back as a new device
        camera.read_register(6)
    assert emu.reenumerations == 1
    info = find_kinect(emu)                         # the same Kinect, enumerated again
    assert send_keep_alive(info.audio) == ""        # the bootloader takes the LED command: no firmware needed
    camera = KinectCamera(info.camera).open()
    clock.sleep(3 * REENUMERATE_S)
    assert camera.read_register(6) == 0 and emu.reenumerations == 1
    camera.close()


def test_stream_from_a_1473_stays_up_for_five_seconds(real_depth):
    emu = EmulatedKinect(real_depth[:3], model="1473", clock=VirtualClock())
    stream = DepthStream(emu, queue_size=400).start()
    frames, states, _ = _watch(stream, lambda f, s: len(f) >= 150 or s.reconnects > 0)
    stream.stop()
    assert emu.keep_alive_received and emu.reenumerations == 0
    assert stream.status.reconnects == 0 and UNPLUGGED not in states
    assert len(frames) >= 150 and _consecutive(frames)          # 5 s of the Kinect's time, no gap


def test_keep_alive_failure_is_a_warning_not_a_stop(real_depth):
    emu = EmulatedKinect(real_depth[:1], model="1473", needs_keep_alive=False, topology="hub")
    emu.functions = [fn for fn in emu.functions if fn.kind != "audio"]     # its audio device not found
    stream = DepthStream(emu).start()
    frames, _, messages = _watch(stream, lambda f, s: len(f) >= 2)
    stream.stop()
    assert len(frames) >= 2 and any("keep-alive not sent" in m for m in messages)


# --- 2. register writes answered with 4 bytes ------------------------------------------------------------------
def test_four_byte_write_acknowledgements_still_start_the_stream(real_depth):
    emu = EmulatedKinect(real_depth[:2], faults=Faults(write_ack_bytes=4), clock=VirtualClock())
    camera = KinectCamera(find_kinect(emu).camera).open()
    camera.write_register(P.REG_DEPTH_FORMAT, 3)
    assert camera.odd_write_acks == [(P.REG_DEPTH_FORMAT, "00000000")]
    camera.close()
    stream = DepthStream(emu).start()
    frames, states, _ = _watch(stream, lambda f, s: len(f) >= 5 or s.state == ERROR, seconds=10)
    stream.stop()
    assert len(frames) >= 5 and ERROR not in states


# --- 3. an unplug that libusb reports as CANCELLED (macOS) -------------------------------------------------------
@pytest.mark.parametrize("cancels", [False, True], ids=["no-device", "cancelled-macos"])
def test_unplug_is_seen_however_libusb_reports_it(real_depth, cancels):
    clock = VirtualClock()
    emu = EmulatedKinect(real_depth[:3], faults=Faults(unplug_at=0.51, replug_at=0.9, unplug_cancels=cancels),
                         clock=clock)
    stream = DepthStream(emu, queue_size=200, reconnect_interval=0.05).start()
    before, states, _ = _watch(stream, lambda f, s: s.state == UNPLUGGED, seconds=10)
    assert UNPLUGGED in states
    clock.sleep(0.5)                                # past replug_at
    after, _, _ = _watch(stream, lambda f, s: len(f) >= 5)
    stream.stop()
    assert len(after) >= 5 and stream.status.reconnects == 1 and len(emu.streams) == 2


# --- 4. a resubmit that fails inside the callback ---------------------------------------------------------------
def test_failed_resubmit_is_reported_and_the_stream_restarts(real_depth):
    emu = EmulatedKinect(real_depth[:2], faults=Faults(submit_io_error_at=(40,)), clock=VirtualClock())
    stream = DepthStream(emu, queue_size=400, reconnect_interval=0.02).start()
    frames, states, messages = _watch(stream, lambda f, s: len(emu.streams) >= 2 and len(f) >= 30)
    stream.stop()
    assert ERROR in states
    assert any("resubmit" in m and "LIBUSB_ERROR_IO" in m for m in messages)
    assert len(emu.streams) >= 2 and len(frames) >= 30          # it restarted with all transfers armed


# --- 5. stop waits for every transfer ---------------------------------------------------------------------------
def test_stop_waits_until_libusb_hands_every_transfer_back(real_depth):
    emu = EmulatedKinect(real_depth[:2], faults=Faults(cancel_delay_s=0.3))
    stream = DepthStream(emu).start()
    _watch(stream, lambda f, s: len(f) >= 2)
    assert stream.stop(timeout=5.0)
    assert emu.lib.in_flight == 0
    assert (emu.lib.closed_in_flight, emu.lib.freed_in_flight) == (0, 0)   # nothing closed or freed under libusb
    assert stream.status.message == "stopped"


def test_stop_says_so_when_a_transfer_never_comes_back(real_depth):
    emu = EmulatedKinect(real_depth[:2], faults=Faults(cancel_delay_s=math.inf))
    stream = DepthStream(emu).start()
    _watch(stream, lambda f, s: len(f) >= 2)
    assert stream.stop(timeout=5.0)
    assert "not handed back" in stream.status.message and "replug" in stream.status.message
    assert emu.lib.in_flight == 16
    assert (emu.lib.closed_in_flight, emu.lib.freed_in_flight) == (0, 0)   # the handle was left open


# --- 6. control replies in full 0x200-byte buffers (Windows) ----------------------------------------------------
def test_replies_padded_to_0x200_bytes_are_understood(real_depth):
    emu = EmulatedKinect(real_depth[:2], faults=Faults(reply_padding=True), clock=VirtualClock())
    with KinectCamera(find_kinect(emu).camera) as camera:
        assert camera.calibration.source == "device" and camera.calibration.const_shift == 200
        assert camera.padded_replies == 2
    stream = DepthStream(emu).start()
    frames, states, _ = _watch(stream, lambda f, s: len(f) >= 3 or s.state == ERROR, seconds=10)
    stream.stop()
    assert len(frames) >= 3


def test_only_full_buffers_and_no_reply_says_what_to_try(real_depth, monkeypatch):
    emu = EmulatedKinect(real_depth[:1], faults=Faults(reply_padding=True))
    camera = KinectCamera(find_kinect(emu).camera).open()
    monkeypatch.setattr(emu, "_camera_command", lambda message: None)    # the answer never comes
    with pytest.raises(ProtocolError) as info:
        camera.read_register(6)
    text = str(info.value)
    assert "0x200" in text and "another USB port" in text and "libusbK" in text
    camera.close()


# --- 7. every iso submit refused with LIBUSB_ERROR_IO -----------------------------------------------------------
def test_refused_iso_submits_name_the_cause_and_the_fix(real_depth):
    emu = EmulatedKinect(real_depth[:1], faults=Faults(submit_io_error=True))
    stream = DepthStream(emu).start()
    _, states, messages = _watch(stream, lambda f, s: s.state == ERROR, seconds=10)
    stream.stop()
    text = next(m for m in messages if "LIBUSB_ERROR_IO" in m)
    assert "bandwidth" in text and "another port" in text and "USB 2" in text
    assert emu.lib.in_flight == 0 and emu.lib.freed_in_flight == 0


# --- 8. EIO is not an unplug -------------------------------------------------------------------------------------
def test_eio_is_reported_as_an_io_error_not_an_unplug(real_depth):
    emu = EmulatedKinect(real_depth[:1], faults=Faults(command_eio=True))
    stream = DepthStream(emu, reconnect_interval=0.01).start()
    _, states, messages = _watch(stream, lambda f, s: s.state == ERROR, seconds=10)
    stream.stop()
    assert UNPLUGGED not in states and stream.status.reconnects == 0
    assert any("I/O error" in m and "12 V" in m for m in messages)


# --- 9. Kinect for Windows audio ids once its firmware runs --------------------------------------------------
def test_kinect_for_windows_with_sdk_firmware_has_its_serial_and_motor(real_depth):
    emu = EmulatedKinect(real_depth[:1], model="k4w", audio_firmware=True)
    assert usb.core.find(idVendor=P.VENDOR_MICROSOFT, idProduct=0x02C3, backend=emu) is not None
    info = list_devices(emu)[0]
    assert info.serial == DEFAULT_SERIAL and info.motor_available, info.motor_note
    motor = open_motor(emu)
    motor.set_led("green")
    assert emu.motor.led == 3
    np.testing.assert_allclose(motor.state().accel_g, [0, 1, 0], atol=0.01)


# --- no frames within 2 s -----------------------------------------------------------------------------------------
def test_a_stream_without_data_says_why_within_the_timeout(real_depth):
    assert DepthStream().no_frame_timeout == 2.0
    emu = EmulatedKinect(real_depth[:1], faults=Faults(no_data=True))
    stream = DepthStream(emu, no_frame_timeout=0.3).start()
    t0 = time.monotonic()
    _, _, messages = _watch(stream, lambda f, s: "no depth data" in s.message, seconds=10)
    waited = time.monotonic() - t0
    stream.stop()
    assert "no depth data" in messages[-1] and "12 V" in messages[-1] and "USB 2" in messages[-1]
    assert stream.status.state != ERROR and waited < 5


def test_a_stream_losing_too_much_says_packets_arrive_but_no_frame(real_depth):
    emu = EmulatedKinect(real_depth[:1], faults=Faults(loss_rate=0.5), clock=VirtualClock())
    stream = DepthStream(emu, no_frame_timeout=0.3).start()
    _, _, messages = _watch(stream, lambda f, s: "no complete depth frame" in s.message, seconds=10)
    stream.stop()
    assert "no complete depth frame" in messages[-1] and "bandwidth" in messages[-1]
    assert stream.status.frames == 0
