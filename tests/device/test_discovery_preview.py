import numpy as np
import pytest

from kinect_retarget.device.disparity_calibration import Calibration
from kinect_retarget.device.discovery import UDEV_RULES, find_kinect, list_devices
from kinect_retarget.sim.emulated_kinect import EmulatedKinect
from kinect_retarget.sim.emulated_stream import Faults
from kinect_retarget.device.errors import DeviceNotFound
from kinect_retarget.device.depth_preview import depth_preview


def test_list_devices_for_each_model(real_depth):
    found = {m: list_devices(EmulatedKinect(real_depth[:1], model=m, serial="B00362700781048B"))[0]
             for m in ("1414", "1473", "k4w")}
    assert found["1414"].model == "Xbox 360 Kinect (1414)" and found["1414"].motor_available
    assert found["1473"].model == "Xbox 360 Kinect (1473)" and not found["1473"].motor_available
    assert found["k4w"].model == "Kinect for Windows"
    # 1473/K4W cameras report sixteen zeros: the serial comes from the audio device
    assert {k.serial for k in found.values()} == {"B00362700781048B"}
    assert all(k.camera_available and not k.problem for k in found.values())


def test_access_problem_names_the_fix(real_depth):
    info = list_devices(EmulatedKinect(real_depth[:1], faults=Faults(access_denied=True)))[0]
    assert not info.camera_available
    assert "udev" in info.problem or "Zadig" in info.problem
    assert "problem:" in info.describe()


def test_find_kinect_by_serial(real_depth):
    emu = EmulatedKinect(real_depth[:1])
    assert find_kinect(emu, "A00366A08793039A").model.endswith("(1414)")
    with pytest.raises(DeviceNotFound, match="found A00366A08793039A"):
        find_kinect(emu, "nope")
    emu.unplug()
    with pytest.raises(DeviceNotFound, match="no Kinect found"):
        find_kinect(emu)


def test_udev_rule_covers_every_kinect_device():
    for pid in ("02ae", "02bf", "02b0", "02c2", "02ad", "02be", "02c3", "02bb"):
        assert f'ATTR{{idProduct}}=="{pid}"' in UDEV_RULES


def test_preview_of_a_real_frame(real_depth):
    mm = Calibration().to_mm(real_depth[0])
    img = depth_preview(mm)
    assert img.shape == (120, 160) and img.dtype == np.uint8
    small = mm[::4, ::4]
    assert (img[small == 0] == 0).all()
    near, far = np.unravel_index(np.argmin(np.where(small > 0, small, 1e9)), small.shape), \
        np.unravel_index(np.argmax(small), small.shape)
    assert img[near] > img[far] > 0


def test_missing_libusb_is_a_clear_error(monkeypatch):
    import builtins

    import usb.backend.libusb1

    from kinect_retarget.cli import main
    from kinect_retarget.device.errors import LibusbMissing
    from kinect_retarget.device.usb_backend import find_backend

    real_import = builtins.__import__

    def no_libusb_package(name, *args, **kwargs):
        if name == "libusb_package":
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(usb.backend.libusb1, "get_backend", lambda *a, **k: None)
    monkeypatch.setattr(builtins, "__import__", no_libusb_package)
    with pytest.raises(LibusbMissing, match="libusb-1.0 could not be loaded"):
        find_backend()
    assert main(["devices"]) == 1                  # a device-side failure, not bad input
