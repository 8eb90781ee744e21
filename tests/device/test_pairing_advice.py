"""Pairing a camera with its motor and audio devices as libfreenect does, and advice that fits the OS."""
import errno
from types import SimpleNamespace

import pytest
import usb.core

from kinect_retarget.device import protocol as P
from kinect_retarget.device.discovery import find_sibling, list_devices
from kinect_retarget.device.kinect_camera import access_advice
from kinect_retarget.device.motor import open_motor
from kinect_retarget.sim.emulated_kinect import DEFAULT_SERIAL, EmulatedKinect
from kinect_retarget.sim.emulated_stream import Faults


def _dev(pid, bus, ports):
    return SimpleNamespace(idProduct=pid, bus=bus, port_numbers=ports)


def test_sibling_behind_the_same_hub_wins_over_others_on_the_bus():
    cams = [_dev(P.PID_CAMERA, 1, (2, 1)), _dev(P.PID_CAMERA, 1, (3, 1))]
    motors = [_dev(P.PID_MOTOR, 1, (3, 2)), _dev(P.PID_MOTOR, 1, (2, 2))]
    assert find_sibling(cams[0], cams + motors, P.MOTOR_PIDS) == (motors[1], "same hub")
    assert find_sibling(cams[1], cams + motors, P.MOTOR_PIDS) == (motors[0], "same hub")


def test_sibling_fallbacks_only_one_on_the_bus_then_only_one_on_the_system():
    cam = _dev(P.PID_CAMERA, 1, None)                                   # the OS gives no port path
    other_bus = _dev(P.PID_MOTOR, 2, (1, 2))
    same_bus = _dev(P.PID_MOTOR, 1, None)
    assert find_sibling(cam, [cam, other_bus, same_bus], P.MOTOR_PIDS) == (same_bus, "only one on the bus")
    assert find_sibling(cam, [cam, other_bus], P.MOTOR_PIDS) == (other_bus, "only one on the system")
    two = [_dev(P.PID_MOTOR, 2, None), _dev(P.PID_MOTOR, 3, None)]
    device, how = find_sibling(cam, [cam, *two], P.MOTOR_PIDS)
    assert device is None and "2 candidates" in how                     # ambiguous: no guess


@pytest.mark.parametrize("topology", ["no-ports", "split-bus"])
def test_a_kinect_whose_devices_do_not_share_a_hub_is_still_one_kinect(real_depth, topology):
    emu_1414 = EmulatedKinect(real_depth[:1], model="1414", topology=topology)
    info = list_devices(emu_1414)[0]
    assert info.motor_available and info.motor.idProduct == P.PID_MOTOR
    open_motor(emu_1414).set_led("red")
    assert emu_1414.motor.led == 2
    info = list_devices(EmulatedKinect(real_depth[:1], model="1473", topology=topology))[0]
    assert info.serial == DEFAULT_SERIAL and info.audio is not None      # serial read from its audio device


def test_linux_names_the_udev_rule_only_for_permission_errors():
    denied = usb.core.USBError("Access denied", -3, errno.EACCES)
    busy = usb.core.USBError("Resource busy", -6, errno.EBUSY)
    other = usb.core.USBError("Input/Output Error", -1, errno.EIO)
    assert "udev" in access_advice(denied, platform="linux")
    assert "udev" not in access_advice(busy, platform="linux") and "another program" in access_advice(busy)
    assert "udev" not in access_advice(other, platform="linux")
    for system in ("linux", "win32", "darwin"):                          # EIO: not a setup problem anywhere
        text = access_advice(other, platform=system)
        assert "I/O error" in text and "12 V" in text and "Zadig" not in text


def test_windows_names_the_device_to_pick_in_zadig():
    exc = NotImplementedError("Operation not supported or unimplemented on this platform")
    camera, motor, audio = (access_advice(exc, role, platform="win32") for role in ("camera", "motor", "audio"))
    assert "Zadig" in camera and "Xbox NUI Camera" in camera and "045E 02AE" in camera
    assert "Xbox NUI Motor" in motor and "045E 02B0" in motor
    assert "Audio" in audio and "045E 02AD" in audio and "motor" in audio


def test_macos_says_no_setup_is_needed():
    text = access_advice(usb.core.USBError("Access denied", -3, errno.EACCES), platform="darwin")
    assert "needs no driver or permission setup" in text and "udev" not in text and "Zadig" not in text


def test_an_audio_device_that_cannot_be_opened_is_not_called_missing_firmware(real_depth):
    info = list_devices(EmulatedKinect(real_depth[:1], model="1473", faults=Faults(denied=("audio",))))[0]
    assert info.camera_available and not info.motor_available
    assert "cannot be read" in info.motor_note and "firmware" not in info.motor_note
    info = list_devices(EmulatedKinect(real_depth[:1], model="1473"))[0]
    assert "audios.bin" in info.motor_note and "fwfetcher" in info.motor_note


def test_a_kinect_without_its_12_v_adapter_is_named_as_such(real_depth):
    from kinect_retarget.device.discovery import find_kinect
    from kinect_retarget.device.errors import DeviceNotFound
    for model in ("1414", "1473"):
        with pytest.raises(DeviceNotFound, match="motor or audio device is on the bus but not its camera.*12 V"):
            find_kinect(EmulatedKinect(real_depth[:1], model=model, faults=Faults(no_power=True)))
    emu = EmulatedKinect(real_depth[:1])
    emu.unplug()
    with pytest.raises(DeviceNotFound, match="no Kinect found"):
        find_kinect(emu)
