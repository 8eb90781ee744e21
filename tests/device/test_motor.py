import numpy as np
import pytest

from kinect_retarget.device.discovery import list_devices
from kinect_retarget.sim.emulated_kinect import EmulatedKinect
from kinect_retarget.sim.emulated_stream import VirtualClock
from kinect_retarget.device.errors import MotorUnavailable
from kinect_retarget.device.motor import KinectMotor, clamp_tilt, open_motor, set_tilt


@pytest.fixture
def clock():
    return VirtualClock()


def test_1414_tilt_led_and_accelerometer(real_depth, clock):
    emu = EmulatedKinect(real_depth[:1], clock=clock)
    motor = open_motor(emu)
    assert motor.set_tilt(40) == 27.0                # clamped to the mechanical range
    state = motor.state()
    assert state.status == "moving"
    clock.sleep(5.0)
    state = motor.state()
    assert state.tilt_deg == 27.0 and state.status == "at limit"
    # gravity seen by a sensor pitched up by 27 degrees
    np.testing.assert_allclose(state.accel_g, [0, np.cos(np.radians(27)), np.sin(np.radians(27))], atol=2e-3)
    motor.set_led("red")
    assert emu.motor.led == 2
    with pytest.raises(ValueError, match="purple"):
        motor.set_led("purple")
    assert set_tilt(-10.4, emu) == -10.4
    clock.sleep(5.0)
    assert motor.state().tilt_deg == -10.5            # the device works in half degrees


@pytest.mark.parametrize("model", ["1473", "k4w"])
def test_newer_models_without_audio_firmware_say_why(real_depth, model):
    emu = EmulatedKinect(real_depth[:1], model=model)
    info = list_devices(emu)[0]
    assert info.camera_available and not info.motor_available
    assert "firmware" in info.motor_note and "Depth streaming works" in info.motor_note
    with pytest.raises(MotorUnavailable, match="proprietary firmware"):
        KinectMotor(info)


def test_1473_with_audio_firmware_uses_bulk_commands(real_depth, clock):
    emu = EmulatedKinect(real_depth[:1], model="1473", audio_firmware=True, clock=clock)
    motor = open_motor(emu)
    assert motor.via_audio
    motor.set_tilt(-15)
    clock.sleep(3.0)
    state = motor.state()
    assert state.tilt_deg == -15.0
    np.testing.assert_allclose(state.accel_g[1], np.cos(np.radians(15)), atol=2e-3)
    motor.set_led("green")
    assert emu.motor.led == 3                               # the audio chip's code for solid green


def test_clamp_rejects_nan():
    with pytest.raises(ValueError):
        clamp_tilt(float("nan"))
