"""Where the OSC receiver listens: other machines reach it only when the user asked for that (Listen on All
Interfaces) and Blender's Allow Online Access permits network access; otherwise this computer only."""
from __future__ import annotations

import bpy

LOOPBACK, ALL_INTERFACES = "127.0.0.1", "0.0.0.0"
REFUSED = ("Listening on this computer only: Allow Online Access is off "
           "(Preferences > System > Network)")


def osc_host(prefs, online: bool | None = None) -> tuple[str, str | None]:
    """(address to bind, why all interfaces were refused or None). `online`: Blender's online access
    (bpy.app.online_access) unless given."""
    if prefs is None or not prefs.osc_listen_all:
        return LOOPBACK, None
    if not (bpy.app.online_access if online is None else online):
        return LOOPBACK, REFUSED
    return ALL_INTERFACES, None
