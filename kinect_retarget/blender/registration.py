"""One static class list, registered in order; unregister is its mirror. Property groups come before the
classes that point at them, and the main panel before its sub-panels. After the classes, the hooks
(scene properties, handlers, menus, the USB source) are added in order and removed in reverse."""
from __future__ import annotations

import bpy

from .live import live_runtime, record_countdown, usb_service
from .ui import (autorig_operator, bake_operator, clip_operators, live_operators, mapping_table, menus, panels,
                 performers, preferences, properties, source_overlay, takes_list, usb_panel)

CLASSES = (*bake_operator.CLASSES, *preferences.CLASSES, *performers.CLASSES, *properties.CLASSES,
           *live_operators.CLASSES, *mapping_table.CLASSES, *panels.CLASSES, *takes_list.CLASSES, *usb_panel.CLASSES,
           *autorig_operator.CLASSES, *clip_operators.CLASSES, *menus.CLASSES)
# modules with register_extra()/unregister_extra(), in order
HOOKS = (properties, live_runtime, usb_service, usb_panel, autorig_operator, clip_operators, menus,
         record_countdown, source_overlay)

_done = {"classes": 0, "hooks": 0}   # how far register() got, so unregister() undoes exactly that


def register() -> None:
    for cls in CLASSES:
        bpy.utils.register_class(cls)
        _done["classes"] += 1
    for mod in HOOKS:
        mod.register_extra()
        _done["hooks"] += 1


def unregister() -> None:
    while _done["hooks"]:
        _done["hooks"] -= 1
        HOOKS[_done["hooks"]].unregister_extra()
    while _done["classes"]:
        _done["classes"] -= 1
        bpy.utils.unregister_class(CLASSES[_done["classes"]])
