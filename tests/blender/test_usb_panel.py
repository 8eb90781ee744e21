"""The "USB Kinect" sidebar sub-panel, headless against the emulated Kinect (real bpy 5.0.1 wheel).

Timers do not fire while a script blocks, so the tests call the timer function (`update_preview`) themselves.
"""
from __future__ import annotations

import math
import threading
import time
from types import SimpleNamespace

import bpy
import numpy as np
import pytest

import kinect_retarget
from kinect_retarget.core.kinect_rig_layout import typical_segment_lengths
from kinect_retarget.blender.live import live_runtime as live, usb_service as usb_panel
from kinect_retarget.blender.ui import usb_panel as usb_ui
from kinect_retarget.blender.io.kinect_rig import build_kinect_rig
from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.device import LibusbMissing, list_devices, open_motor
from kinect_retarget.sim.emulated_kinect import EmulatedKinect
from kinect_retarget.device.disparity_calibration import Calibration
from kinect_retarget.sim.depth_sequences import load_fakenect_dir
from kinect_retarget.sim.emulated_kinect import DEFAULT_SERIAL
from kinect_retarget.sources import SourceError

FAKENECT = ("depth_real", "fakenect_openiss", "fakenect-record")
PREVIEW_W, PREVIEW_H = 320, 240


@pytest.fixture(scope="module")
def fakenect_frames(data_dir):
    """Six real Kinect v1 depth frames (libfreenect recording of a person)."""
    return load_fakenect_dir(data_dir.joinpath(*FAKENECT), limit=6)


@pytest.fixture
def registered(monkeypatch, fakenect_frames):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    kinect_retarget.register()
    # the simulated Kinect streams real recorded depth here (rendering mocap is for the live-chain test)
    monkeypatch.setattr(usb_panel, "simulated_images", lambda: (list(fakenect_frames), "fakenect test frames"))
    usb_panel._rt.sim_backend = None
    bpy.context.scene.kinect_retarget.source = "USB"
    yield bpy.context.scene
    live.stop_live(bake=False)
    kinect_retarget.unregister()
    usb_panel._rt.sim_backend = usb_panel._rt.devices = None
    usb_panel._rt.discovery_error = ""


def _simulate(scene) -> EmulatedKinect:
    scene.kinect_retarget_usb.simulate = True          # starts preparing the emulated Kinect and a search
    assert usb_panel.wait_for_discovery(10.0)
    backend = usb_panel.simulated_backend(wait=10.0)
    assert backend is not None
    return backend


def _pump_until(predicate, seconds=10.0) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if predicate():
            return
        time.sleep(0.02)
    raise AssertionError("timed out")


def _our_threads() -> list[str]:
    return [t.name for t in threading.enumerate() if t.name.startswith(("kinect-depth", "kinect_retarget-"))]


# -- devices ----------------------------------------------------------------------------------------------------
def test_refresh_lists_the_simulated_kinect_without_blocking(registered):
    _simulate(registered)
    (d,) = usb_panel.devices()
    assert "1414" in d["model"] and d["serial"] == DEFAULT_SERIAL
    assert d["camera_available"] and d["motor_available"] and not d["problem"]
    # the operator returns at once and the answer arrives through the timer function
    assert bpy.ops.kinect_retarget.usb_refresh() == {"FINISHED"}
    assert bpy.app.timers.is_registered(usb_panel.update_preview)
    _pump_until(lambda: not usb_panel.discovering())
    usb_panel.update_preview()
    assert usb_panel.devices()[0]["serial"] == DEFAULT_SERIAL


def test_refresh_reports_why_a_device_cannot_be_used(registered, monkeypatch, fakenect_frames):
    emu = EmulatedKinect(fakenect_frames[:1], model="1473")
    monkeypatch.setattr(usb_panel, "list_devices", lambda backend=None: list_devices(backend or emu))
    usb_panel.refresh_devices()
    assert usb_panel.wait_for_discovery(10.0)
    (d,) = usb_panel.devices()
    assert d["camera_available"] and not d["motor_available"]
    assert "firmware" in d["motor_note"]

    def missing(backend=None):
        raise LibusbMissing("no libusb found: install libusb-package")
    monkeypatch.setattr(usb_panel, "list_devices", missing)
    usb_panel.refresh_devices()
    assert usb_panel.wait_for_discovery(10.0)
    assert usb_panel.devices() == [] and "libusb" in usb_panel._rt.discovery_error


# -- motor ------------------------------------------------------------------------------------------------------
def test_tilt_drives_the_emulated_motor_and_clamps(registered):
    backend = _simulate(registered)
    assert bpy.ops.kinect_retarget.usb_tilt(angle=math.radians(12.0)) == {"FINISHED"}
    assert backend.motor.target_deg == pytest.approx(12.0)
    u = registered.kinect_retarget_usb
    u.tilt = math.radians(40.0)                         # the property stops at the Kinect's limit
    assert math.degrees(u.tilt) == pytest.approx(27.0)
    assert bpy.ops.kinect_retarget.usb_tilt() == {"FINISHED"}   # no angle given: the panel's value
    assert backend.motor.target_deg == pytest.approx(27.0)
    assert bpy.ops.kinect_retarget.usb_led(mode="red") == {"FINISHED"}
    assert backend.motor.led == 2


def test_tilt_says_plainly_when_the_motor_needs_firmware(registered, monkeypatch, fakenect_frames):
    emu = EmulatedKinect(fakenect_frames[:1], model="1473")
    monkeypatch.setattr(usb_panel, "open_motor", lambda backend=None: open_motor(emu))
    reports = []
    op = SimpleNamespace(angle=0.1, properties=SimpleNamespace(is_property_set=lambda name: True),
                         report=lambda level, msg: reports.append((level, msg)))
    assert usb_ui.KINECT_RETARGET_OT_usb_tilt.execute(op, bpy.context) == {"CANCELLED"}
    (level, msg), = reports
    assert level == {"ERROR"} and "motor is not available" in msg and "firmware" in msg


def test_tilt_without_a_kinect_is_an_error_not_a_crash(registered, monkeypatch, fakenect_frames):
    emu = EmulatedKinect(fakenect_frames[:1])
    emu.unplug()
    monkeypatch.setattr(usb_panel, "open_motor", lambda backend=None: open_motor(emu))
    with pytest.raises(RuntimeError, match="no Kinect found"):   # how bpy.ops surfaces an ERROR report
        bpy.ops.kinect_retarget.usb_tilt(angle=0.0)


# -- preview ----------------------------------------------------------------------------------------------------
def _expected_greys(frames) -> list[np.ndarray]:
    cal = Calibration()
    return [usb_panel._grey_rgba(cal.to_mm(f)) for f in frames]


def test_depth_stream_preview_updates_the_image(registered, fakenect_frames):
    _simulate(registered)
    assert bpy.ops.kinect_retarget.usb_preview() == {"FINISHED"}
    assert usb_panel.stream_running() and bpy.app.timers.is_registered(usb_panel.update_preview)
    _pump_until(lambda: usb_panel.stream_status().frames >= 3)
    assert usb_panel.update_preview() == usb_panel.PREVIEW_INTERVAL
    img = bpy.data.images[usb_panel.IMAGE_NAME]
    assert tuple(img.size) == (PREVIEW_W, PREVIEW_H) and usb_panel._rt.preview_kind == "depth"
    shown = np.empty(PREVIEW_W * PREVIEW_H * 4, np.float32)
    img.pixels.foreach_get(shown)
    shown = shown.reshape(PREVIEW_H, PREVIEW_W, 4)
    # the image is one of the streamed frames, bottom-up, to 8-bit precision
    errors = [np.abs(shown - g).max() for g in _expected_greys(fakenect_frames)]
    assert min(errors) < 1 / 255 + 1e-6
    assert shown[..., 0].std() > 0.05                   # a real scene, not a blank image
    icon = usb_panel._rt.previews["depth"]
    assert tuple(icon.image_size) == (PREVIEW_W, PREVIEW_H)
    st = usb_panel.stream_status()
    assert st.state == "streaming" and st.frames >= 3 and st.reconnects == 0

    # a file load keeps the stream, so the (persistent) timer goes on and recreates the image in the new file
    bpy.ops.wm.read_factory_settings(use_empty=True)
    assert bpy.app.timers.is_registered(usb_panel.update_preview) and usb_panel.stream_running()
    frames = st.frames
    _pump_until(lambda: usb_panel.stream_status().frames > frames)
    usb_panel.update_preview()
    assert usb_panel.IMAGE_NAME in bpy.data.images

    assert bpy.ops.kinect_retarget.usb_preview() == {"FINISHED"}   # the same button stops it
    assert not usb_panel.stream_running()
    assert usb_panel.update_preview() is None            # nothing runs: the timer ends itself
    assert not [n for n in _our_threads() if n == "kinect-depth"]


@pytest.fixture
def rendered_frames(tmp_path_factory, monkeypatch):
    """Six frames of CMU mocap rendered as Kinect depth (the simulated Kinect's own content), cached."""
    from kinect_retarget.sources.simulated_kinect import simulated_frames
    monkeypatch.setenv("KR_DEPTH_CACHE", str(tmp_path_factory.getbasetemp() / "depth_cache"))
    return simulated_frames(6)   # from the package's own assets


def test_live_on_the_simulated_kinect_previews_person_and_skeleton(registered, monkeypatch, rendered_frames):
    monkeypatch.setattr(usb_panel, "simulated_images", lambda: (list(rendered_frames), "rendered test frames"))
    scene = registered
    _simulate(scene)
    bpy.ops.kinect_retarget.usb_preview()              # a preview stream runs: live must take the device over
    obj = build_kinect_rig(scene, KINECT_V1, typical_segment_lengths(KINECT_V1), "KinectRig")
    bpy.context.view_layer.objects.active = obj
    s = scene.kinect_retarget
    s.initialised, s.armature, s.preset, s.play_on_record = True, obj, "kinect", False
    c = live.start_live(bpy.context, use_timer=False)
    assert c.source_label == "simulated USB Kinect" and not usb_panel.stream_running()
    assert usb_panel.live_uses_usb()
    _pump_until(lambda: live.pump_live() and c.session.statistics()["applied"] >= 2, seconds=30)
    assert usb_panel.update_preview() == usb_panel.PREVIEW_INTERVAL
    assert usb_panel._rt.preview_kind == "skeleton"
    shown = np.empty(PREVIEW_W * PREVIEW_H * 4, np.float32)
    bpy.data.images[usb_panel.IMAGE_NAME].pixels.foreach_get(shown)
    rgb = shown.reshape(-1, 4)[:, :3]
    yellow = np.all(np.abs(rgb - [1.0, 0.85, 0.1]) < 0.01, axis=1)      # tracked joints and bones
    green = (rgb[:, 1] > 0.2) & np.isclose(rgb[:, 0], rgb[:, 1] * 0.5, atol=0.01)   # the person, tinted
    assert yellow.sum() > 20 and green.sum() > 500
    st = usb_panel.stream_status()                       # live's own stream, on show in the panel
    assert st.state == "streaming" and st.frames >= 2
    live.stop_live(bake=False)
    assert usb_panel.update_preview() is None


def test_live_while_the_simulated_kinect_is_prepared_says_so(registered, monkeypatch, fakenect_frames):
    gate = threading.Event()

    def slow_images():
        gate.wait(10.0)                                  # stands in for the first render (about a minute)
        return list(fakenect_frames), "fakenect test frames"
    monkeypatch.setattr(usb_panel, "simulated_images", slow_images)
    scene = registered
    scene.kinect_retarget_usb.simulate = True
    obj = build_kinect_rig(scene, KINECT_V1, typical_segment_lengths(KINECT_V1), "KinectRig")
    bpy.context.view_layer.objects.active = obj
    scene.kinect_retarget.initialised = True
    try:
        with pytest.raises(SourceError, match="being prepared"):
            live.start_live(bpy.context, use_timer=False)
        assert live.controller() is None
        text = " ".join(t for kind, t in _draw(bpy.context) if kind == "label")
        assert "Preparing the simulated Kinect" in text
    finally:
        gate.set()
    assert usb_panel.wait_for_discovery(10.0) and usb_panel.devices()[0]["serial"] == DEFAULT_SERIAL
    c = live.start_live(bpy.context, use_timer=False)    # ready now
    assert c.source_label == "simulated USB Kinect"


# -- panel and unregister ---------------------------------------------------------------------------------------
_UI = bpy.types.UILayout.bl_rna.functions
_ICONS = {i.identifier for i in _UI["label"].parameters["icon"].enum_items}


class _FakeLayout:
    """Records what draw() puts on screen; checks every call against the real UILayout's parameters."""

    def __init__(self, log):
        self.log, self.alert, self.enabled, self.scale_y = log, False, True, 1.0

    @staticmethod
    def _check(fn, kwargs):
        params = _UI[fn].parameters
        unknown = set(kwargs) - set(params.keys())
        assert not unknown, f"UILayout.{fn} has no parameter {unknown}"
        assert kwargs.get("icon", "NONE") in _ICONS, kwargs["icon"]

    def _child(self, **k):
        return _FakeLayout(self.log)

    def row(self, **k):
        self._check("row", k)
        return self._child()

    def column(self, **k):
        self._check("column", k)
        return self._child()

    def box(self):
        return self._child()

    def label(self, **k):
        self._check("label", k)
        self.log.append(("label", k.get("text", "")))

    def prop(self, data, prop, **k):
        self._check("prop", k)
        assert prop in data.bl_rna.properties, prop
        self.log.append(("prop", prop))

    def operator(self, idname, **k):
        self._check("operator", k)
        assert hasattr(getattr(bpy.ops, idname.split(".")[0]), idname.split(".")[1]), idname
        self.log.append(("operator", idname))

    def template_icon(self, **k):
        self._check("template_icon", k)
        self.log.append(("icon", k["icon_value"]))


def _draw(context) -> list:
    log = []
    panel = SimpleNamespace(layout=_FakeLayout(log))
    cls = usb_ui.KINECT_RETARGET_PT_usb
    for name in ("_draw_devices", "_draw_stream", "_draw_motor", "_draw_preview"):
        setattr(panel, name, getattr(cls, name))
    cls.draw(panel, context)
    return log


def test_panel_shows_devices_status_tilt_and_preview(registered, monkeypatch, fakenect_frames):
    assert usb_ui.KINECT_RETARGET_PT_usb.poll(bpy.context)
    text = " | ".join(t for kind, t in _draw(bpy.context) if kind == "label")
    assert "Press Refresh" in text and "Not streaming" in text
    _simulate(registered)
    bpy.ops.kinect_retarget.usb_preview()
    _pump_until(lambda: usb_panel.stream_status().frames >= 2)
    usb_panel.update_preview()
    log = _draw(bpy.context)
    text = " | ".join(t for kind, t in log if kind == "label")
    assert DEFAULT_SERIAL in text and "Camera: streaming" in text and "Motor: ready" in text
    assert "frames/s" in text and "dropped 0" in text and "reconnects 0" in text
    assert ("prop", "tilt") in log and ("operator", "kinect_retarget.usb_tilt") in log
    assert ("prop", "simulate") in log and ("operator", "kinect_retarget.usb_refresh") in log
    assert any(kind == "icon" for kind, _ in log)
    registered.kinect_retarget_usb.show_preview = False
    assert not any(kind == "icon" for kind, _ in _draw(bpy.context))
    usb_panel.stop_stream()
    # a 1473 without its audio firmware: the panel says why tilt cannot work
    emu = EmulatedKinect(fakenect_frames[:1], model="1473")
    monkeypatch.setattr(usb_panel, "list_devices", lambda backend=None: list_devices(emu))
    usb_panel.refresh_devices()
    usb_panel.wait_for_discovery(10.0)
    text = " ".join(t for kind, t in _draw(bpy.context) if kind == "label")
    assert "Motor: not available" in text and "firmware" in text
    registered.kinect_retarget.source = "TAKE"
    assert not usb_ui.KINECT_RETARGET_PT_usb.poll(bpy.context)


def test_unregister_leaves_no_timer_stream_or_thread(registered):
    _simulate(registered)
    bpy.ops.kinect_retarget.usb_preview()
    _pump_until(lambda: usb_panel.stream_status().frames >= 1)
    usb_panel.update_preview()
    assert bpy.app.timers.is_registered(usb_panel.update_preview) and _our_threads()
    stream = usb_panel._rt.stream
    kinect_retarget.unregister()
    try:
        assert not bpy.app.timers.is_registered(usb_panel.update_preview)
        assert not stream.running and not _our_threads()
        assert usb_panel.IMAGE_NAME not in bpy.data.images and usb_panel._rt.previews is None
        assert not hasattr(bpy.types.Scene, "kinect_retarget_usb")
    finally:
        kinect_retarget.register()   # the fixture unregisters
