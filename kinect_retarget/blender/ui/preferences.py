"""Add-on preferences: the defaults a new scene's Kinect settings start from."""
from __future__ import annotations

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty

from ...core.filters import FILTERS

# The add-on's module name: "kinect_retarget", or "bl_ext.<repo>.kinect_retarget" as an extension.
ADDON_ID = __package__.rsplit(".", 2)[0]   # this module is <addon>.blender.ui.preferences

SOURCE_ITEMS = [
    ("TAKE", "Take Playback", "Play a recorded take in real time", "FILE_MOVIE", 0),
    ("OSC", "OSC (NI mate)", "Receive NI mate's skeleton stream over UDP/OSC", "URL", 1),
    ("USB", "USB Kinect", "A Kinect for Xbox 360 on USB", "OUTLINER_OB_CAMERA", 2),
]
FILTER_ITEMS = [(f, f.replace("_", " ").title(), f"Jitter filter: {f}") for f in FILTERS]


class KinectRetargetPreferences(bpy.types.AddonPreferences):
    bl_idname = ADDON_ID

    default_source: EnumProperty(name="Default Source", items=SOURCE_ITEMS, default="TAKE")
    osc_port: IntProperty(name="OSC Port", default=7000, min=1, max=65535,
                          description="UDP port NI mate (or another bridge) sends skeleton messages to")
    osc_listen_all: BoolProperty(
        name="Listen on All Interfaces", default=False,
        description="Accept OSC from other machines (binds 0.0.0.0), only while Blender's Allow Online Access is "
                    "on. Off: only this computer (127.0.0.1)")
    default_filter: EnumProperty(name="Default Filter", items=FILTER_ITEMS, default="default")
    recordings_dir: StringProperty(name="Recordings Folder", subtype="DIR_PATH", default="//kinect_takes/",
                                   description="Where live recordings (.krtake) are written; // is the .blend's folder")
    lost_tracking_timeout: FloatProperty(
        name="Lost Tracking Timeout", default=2.0, min=0.1, max=60.0, unit="TIME_ABSOLUTE",
        description="Stop live when no joint has been tracked for this long")

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        col = layout.column()
        col.prop(self, "default_source")
        col.prop(self, "osc_port")
        col.prop(self, "osc_listen_all")
        if self.osc_listen_all and not bpy.app.online_access:
            col.label(text="Allow Online Access is off (System > Network): OSC stays on this computer",
                      icon="INTERNET_OFFLINE")
        col.prop(self, "default_filter")
        col.prop(self, "recordings_dir")
        col.prop(self, "lost_tracking_timeout")


def get_preferences(context=None):
    """The preferences, or None when the add-on is not registered under ADDON_ID (some test setups)."""
    context = context or bpy.context
    addon = context.preferences.addons.get(ADDON_ID)
    return addon.preferences if addon else None


CLASSES = (KinectRetargetPreferences,)
