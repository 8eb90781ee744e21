"""The "USB Kinect" sub-panel: detected devices, stream status, tilt and LED, the simulated Kinect toggle and the
live depth preview. It only draws and calls the service (blender/live/usb_service.py), which owns the threads."""
from __future__ import annotations

import math
import textwrap

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty

from ...device import KinectError, MotorUnavailable
from ...device.motor import LED_MODES, TILT_LIMIT_DEG
from ...sources import SourceError
from ..live import usb_service
from .sidebar_panel import KinectSidebarPanel

LED_ITEMS = [(m, m.replace("-", " ").title(), f"Kinect LED: {m}") for m in
             ("green", "red", "yellow", "blink-green", "blink-red-yellow", "off")]
assert all(m[0] in LED_MODES for m in LED_ITEMS)


# -- properties -------------------------------------------------------------------------------------------------
def _simulate_changed(self, context) -> None:
    usb_service.simulate_changed(context)


class KinectRetargetUsbSettings(bpy.types.PropertyGroup):
    simulate: BoolProperty(
        name="Simulated Kinect", default=False, update=_simulate_changed,
        description="Use an emulated Kinect streaming rendered depth of a real motion, for trying the whole "
                    "chain (devices, tilt, preview, live) without the hardware")
    tilt: FloatProperty(name="Tilt", subtype="ANGLE", default=0.0, min=-math.radians(TILT_LIMIT_DEG),
                        max=math.radians(TILT_LIMIT_DEG),
                        description="Motor angle from the horizon (the Kinect's limit is ±27°)")
    led: EnumProperty(name="LED", items=LED_ITEMS, default="green", description="Colour of the Kinect's LED")
    show_preview: BoolProperty(name="Depth Preview", default=True, description="Show the depth preview image")


# -- operators --------------------------------------------------------------------------------------------------
class KINECT_RETARGET_OT_usb_refresh(bpy.types.Operator):
    """Look for Kinects on USB (in the background; the list updates when the search ends)"""
    bl_idname = "kinect_retarget.usb_refresh"
    bl_label = "Refresh Devices"
    bl_options = {"REGISTER"}

    def execute(self, context):
        if not usb_service.refresh_devices(context):
            self.report({"INFO"}, "Already looking for Kinects")
        return {"FINISHED"}


def _motor_call(op, context, action, describe):
    try:
        result = usb_service.with_motor(context, action)
    except MotorUnavailable as exc:
        op.report({"ERROR"}, f"The motor is not available: {exc}")
        return {"CANCELLED"}
    except (KinectError, SourceError, ValueError) as exc:
        op.report({"ERROR"}, str(exc))
        return {"CANCELLED"}
    op.report({"INFO"}, describe(result))
    return {"FINISHED"}


class KINECT_RETARGET_OT_usb_tilt(bpy.types.Operator):
    """Tilt the Kinect's motor (-27° to +27° from the horizon)"""
    bl_idname = "kinect_retarget.usb_tilt"
    bl_label = "Set Tilt"
    bl_options = {"REGISTER"}

    angle: FloatProperty(name="Angle", subtype="ANGLE", min=-math.radians(TILT_LIMIT_DEG),
                         max=math.radians(TILT_LIMIT_DEG), description="Tilt (default: the panel's value)")

    def execute(self, context):
        s = usb_service.settings(context)
        angle = self.angle if self.properties.is_property_set("angle") or s is None else s.tilt
        return _motor_call(self, context, lambda m: m.set_tilt(math.degrees(angle)),
                           lambda sent: f"Tilting the Kinect to {sent:+.1f}°")


class KINECT_RETARGET_OT_usb_led(bpy.types.Operator):
    """Set the Kinect's LED"""
    bl_idname = "kinect_retarget.usb_led"
    bl_label = "Set LED"
    bl_options = {"REGISTER"}

    mode: EnumProperty(name="Mode", items=LED_ITEMS, default="green")

    def execute(self, context):
        s = usb_service.settings(context)
        mode = self.mode if self.properties.is_property_set("mode") or s is None else s.led
        return _motor_call(self, context, lambda m: m.set_led(mode), lambda _: f"Kinect LED: {mode}")


class KINECT_RETARGET_OT_usb_preview(bpy.types.Operator):
    """Start or stop streaming depth for the preview image (live shows its own, with the skeleton)"""
    bl_idname = "kinect_retarget.usb_preview"
    bl_label = "Depth Preview"
    bl_options = {"REGISTER"}

    @classmethod
    def poll(cls, context):
        if usb_service.live_uses_usb():
            cls.poll_message_set("Live is using the Kinect; the preview shows its frames")
            return False
        return True

    def execute(self, context):
        if usb_service.stream_running():
            usb_service.stop_stream()
            return {"FINISHED"}
        try:
            usb_service.start_stream(context)
        except SourceError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        return {"FINISHED"}


# -- the panel --------------------------------------------------------------------------------------------------
_STATE_ICONS = {"streaming": "REC", "connecting": "TIME", "waiting for device": "TIME", "unplugged": "UNLINKED",
                "error": "ERROR", "stopped": "PAUSE"}


def _wrapped(layout, text: str, icon: str = "NONE", width_px: int = 280, alert: bool = False) -> None:
    """Labels do not wrap: split long sentences (device problems, fixes) to the sidebar's width."""
    col = layout.column(align=True)
    col.alert = alert
    chars = max(20, int(width_px / 6.5))
    for n, line in enumerate(textwrap.wrap(text, chars) or [""]):
        col.label(text=line, icon=icon if n == 0 else "BLANK1")


class KINECT_RETARGET_PT_usb(KinectSidebarPanel, bpy.types.Panel):
    bl_label = "USB Kinect"
    bl_parent_id = "KINECT_RETARGET_PT_main"

    @classmethod
    def poll(cls, context):
        s = getattr(context.scene, "kinect_retarget", None)
        return s is not None and s.source == "USB" and usb_service.settings(context) is not None

    def draw(self, context):
        layout = self.layout
        u = usb_service.settings(context)
        region = getattr(context, "region", None)
        width = getattr(region, "width", 280) or 280
        self._draw_devices(layout, u, width)
        self._draw_stream(layout, u, width)
        self._draw_motor(layout, u, width)
        if u.show_preview:
            self._draw_preview(layout)

    @staticmethod
    def _draw_devices(layout, u, width):
        st = usb_service.stream_status()
        streaming = st.device if st is not None and st.state == "streaming" else ""
        box = layout.box()
        row = box.row(align=True)
        row.label(text="Devices", icon="OUTLINER_OB_CAMERA")
        row.prop(u, "simulate", text="Simulated", toggle=True)
        row.operator("kinect_retarget.usb_refresh", text="", icon="FILE_REFRESH")
        if usb_service.preparing_simulated():
            _wrapped(box, "Preparing the simulated Kinect (rendering depth of a real motion; the first time "
                          "takes about a minute)…", "TIME", width)
        elif usb_service.discovering():
            box.label(text="Looking for Kinects…", icon="TIME")
        if usb_service.runtime().sim_error and u.simulate:
            _wrapped(box, usb_service.runtime().sim_error, "ERROR", width, alert=True)
        if usb_service.runtime().discovery_error:
            _wrapped(box, usb_service.runtime().discovery_error, "ERROR", width, alert=True)
        elif usb_service.runtime().devices is None:
            if not usb_service.discovering():
                box.label(text="Press Refresh to look for Kinects", icon="INFO")
        elif not usb_service.runtime().devices:
            _wrapped(box, "No Kinect found: plug it in and connect its 12 V power adapter, then Refresh",
                     "INFO", width)
        for d in usb_service.runtime().devices or ():
            col = box.column(align=True)
            col.label(text=f"{d['model']}  {d['serial']}", icon="CHECKMARK" if d["camera_available"] else "ERROR")
            in_use = bool(streaming) and streaming.endswith(d["serial"])   # a busy camera may refuse a 2nd open
            camera = "streaming" if in_use else "ready" if d["camera_available"] else "cannot be opened"
            col.label(text=f"Camera: {camera}", icon="BLANK1")
            col.label(text="Motor: " + ("ready" if d["motor_available"] else "not available"), icon="BLANK1")
            if d["problem"] and not in_use:
                _wrapped(col, d["problem"], "ERROR", width, alert=True)
        if u.simulate and usb_service.runtime().sim_label:
            box.label(text=f"Simulated: {usb_service.runtime().sim_label}", icon="INFO")

    @staticmethod
    def _draw_stream(layout, u, width):
        box = layout.box()
        st = usb_service.stream_status()
        row = box.row(align=True)
        using_live = usb_service.live_uses_usb()
        row.label(text="Stream" + (" (live)" if using_live else ""), icon="PLAY" if st and st.fps else "PAUSE")
        running = usb_service.stream_running()
        row.prop(u, "show_preview", text="", icon="IMAGE_DATA")
        sub = row.row(align=True)
        sub.operator("kinect_retarget.usb_preview", text="Stop" if running else "Stream Depth",
                     icon="PAUSE" if running else "PLAY", depress=running)
        if st is None:
            box.label(text="Not streaming", icon="BLANK1")
            return
        message = st.message[:1].upper() + st.message[1:] if st.message else st.state.capitalize()
        _wrapped(box, message, _STATE_ICONS.get(st.state, "INFO"), width, alert=st.state in ("error", "unplugged"))
        col = box.column(align=True)
        col.label(text=f"{st.fps:.1f} frames/s · {st.frames} frames")
        col.label(text=f"dropped {st.frames_dropped} · reconnects {st.reconnects}"
                       + (f" · late {st.queue_overflows}" if st.queue_overflows else ""))

    @staticmethod
    def _draw_motor(layout, u, width):
        box = layout.box()
        motor = next((d for d in usb_service.runtime().devices or () if not d["motor_available"] and d["motor_note"]), None)
        row = box.row(align=True)
        row.prop(u, "tilt")
        row.operator("kinect_retarget.usb_tilt", text="", icon="CON_ROTLIKE")
        row = box.row(align=True)
        row.prop(u, "led", text="LED")
        row.operator("kinect_retarget.usb_led", text="", icon="LIGHT")
        if motor is not None:
            _wrapped(box, f"Motor: {motor['motor_note']}", "INFO", width)

    @staticmethod
    def _draw_preview(layout):
        icon = usb_service.runtime().previews.get("depth") if usb_service.runtime().previews is not None else None
        if icon is None or usb_service.preview_image() is None:
            layout.label(text="Depth preview appears while streaming or live", icon="IMAGE_DATA")
            return
        caption = "Person and fitted skeleton" if usb_service.runtime().preview_kind == "skeleton" else "Depth (near = bright)"
        layout.label(text=caption, icon="IMAGE_DATA")
        layout.template_icon(icon_value=icon.icon_id, scale=9.0)


def register_extra() -> None:
    bpy.types.Scene.kinect_retarget_usb = bpy.props.PointerProperty(type=KinectRetargetUsbSettings)


def unregister_extra() -> None:
    del bpy.types.Scene.kinect_retarget_usb


CLASSES = (KinectRetargetUsbSettings, KINECT_RETARGET_OT_usb_refresh, KINECT_RETARGET_OT_usb_tilt,
           KINECT_RETARGET_OT_usb_led, KINECT_RETARGET_OT_usb_preview, KINECT_RETARGET_PT_usb)
